/**
 * @file parameter_reference.hpp
 * @brief The parameter reference read from the parameter structs themselves: name, type and default from a
 *        forEachParam() list, unit and meaning from its ParamDoc, the valid range by probing the struct's validate().
 *
 * A range is what validate() accepts for one parameter with every other parameter at its value in the base
 * configuration, found by bisection over the ordered doubles (or ints) between an accepted value and the largest
 * magnitudes, so it is exact (to the last bit) and cannot drift from the code.
 */
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "map_aided_fusion/core/parameters.hpp"

namespace map_aided_fusion {
namespace core {

/// One row of the parameter reference.
struct ParamInfo
{
  std::string name;
  std::string type;           ///< double, int, bool, string, string list, string → double
  std::string default_value;  ///< as written in YAML
  std::string unit;
  std::string range;          ///< interval notation for numbers ("[0, 1]", "(0, ∞)"), "" when not probed
  std::string meaning;
};

/// The interval of accepted doubles from an accepted @p anchor: nullopt bound = unbounded on that side.
struct ProbedRange
{
  std::optional<double> lowest;   ///< smallest accepted value
  std::optional<double> highest;  ///< largest accepted value
};

/**
 * @brief Bisection for the accepted interval around @p anchor (which @p accepts must accept) over the finite
 *        doubles; a side on which the largest magnitude is accepted is unbounded.
 */
ProbedRange probeDoubleRange(double anchor, const std::function<bool(double)>& accepts);

/// The same over int (64-bit bisection between INT_MIN, @p anchor and INT_MAX).
ProbedRange probeIntRange(int anchor, const std::function<bool(int)>& accepts);

/**
 * @brief Interval notation of @p r: a bound that is the successor of a short decimal (0, 0.5, 1e-06) is written
 *        open on that decimal ("(0, 1]"), a short decimal is written closed, an absent bound as ∞.
 */
std::string formatRange(const ProbedRange& r, bool integer);

/// Shortest YAML spelling of a double (%.15g trimmed; NaN as .nan).
std::string formatDouble(double v);

/// A GitHub-flavoured Markdown table of @p rows (name, type, default, unit, valid range, meaning).
std::string markdownTable(const std::vector<ParamInfo>& rows);

namespace detail {

template <class T>
struct ParamTraits;
template <>
struct ParamTraits<double>
{
  static constexpr const char* name = "double";
  static std::string text(double v) { return formatDouble(v); }
};
template <>
struct ParamTraits<int>
{
  static constexpr const char* name = "int";
  static std::string text(int v) { return std::to_string(v); }
};
template <>
struct ParamTraits<bool>
{
  static constexpr const char* name = "bool";
  static std::string text(bool v) { return v ? "true" : "false"; }
};
template <>
struct ParamTraits<std::string>
{
  static constexpr const char* name = "string";
  static std::string text(const std::string& v) { return "\"" + v + "\""; }
};
template <>
struct ParamTraits<std::vector<std::string>>
{
  static constexpr const char* name = "string list";
  static std::string text(const std::vector<std::string>& v)
  {
    std::string s = "[";
    for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + v[i];
    return s + "]";
  }
};
template <>
struct ParamTraits<std::map<std::string, double>>
{
  static constexpr const char* name = "string → double";
  static std::string text(const std::map<std::string, double>& v)
  {
    std::string s = "{";
    bool first = true;
    for (const auto& [k, x] : v)
    {
      s += (first ? "" : ", ") + k + ": " + formatDouble(x);
      first = false;
    }
    return s + "}";
  }
};

/// value = x when @p now and both have the same type (a function: GCC 12 drops an `if constexpr` on the type of an
/// enclosing generic lambda's parameter inside a nested generic lambda).
template <class T, class U>
void assignIf(T& value, const U& x, bool now)
{
  if constexpr (std::is_same_v<T, U>)
  {
    if (now) value = x;
  }
}

/// The values tried, in order, when the base value of a number is rejected (a NaN "unset" default).
constexpr double kAnchors[] = { 0.0, 1.0, -1.0, 0.5, 10.0, 1000.0 };

}  // namespace detail

/**
 * @brief The reference rows of a parameter struct.
 * @param defaults  the values the reference states as defaults
 * @param base      a configuration validate() accepts, in which each parameter's range is probed (the defaults,
 *                  plus whatever the struct needs set: a map file, an origin)
 * @param for_each  calls get(name, field, ParamDoc) for every parameter (a forEachParam overload)
 * @param validate  throws (ParameterError) for a configuration out of range
 */
template <class Params, class ForEach, class Validate>
std::vector<ParamInfo> describeParams(const Params& defaults, const Params& base, ForEach&& for_each,
                                      Validate&& validate)
{
  std::vector<ParamInfo> rows;
  Params listed = defaults;
  for_each(listed, [&](const std::string& name, auto& value, const ParamDoc& doc) {
    using T = std::decay_t<decltype(value)>;
    rows.push_back(ParamInfo{ name, detail::ParamTraits<T>::name, detail::ParamTraits<T>::text(value), doc.unit, "",
                              doc.meaning });
  });
  for (std::size_t k = 0; k < rows.size(); ++k)
  {
    auto acceptsWith = [&](auto x) {
      Params p = base;
      std::size_t i = 0;
      for_each(p, [&](const std::string&, auto& value, const ParamDoc&) { detail::assignIf(value, x, i++ == k); });
      try
      {
        validate(p);
        return true;
      }
      catch (const std::exception&)
      {
        return false;
      }
    };
    Params copy = base;
    std::size_t i = 0;
    for_each(copy, [&](const std::string&, auto& value, const ParamDoc&) {
      using T = std::decay_t<decltype(value)>;
      if (i++ != k) return;
      if constexpr (std::is_same_v<T, double>)
      {
        std::optional<double> anchor;
        if (std::isfinite(value) && acceptsWith(value)) anchor = value;
        for (double a : detail::kAnchors)
          if (!anchor && acceptsWith(a)) anchor = a;
        if (anchor)
          rows[k].range = formatRange(probeDoubleRange(*anchor, [&](double x) { return acceptsWith(x); }), false);
      }
      else if constexpr (std::is_same_v<T, int>)
      {
        if (acceptsWith(value))
          rows[k].range = formatRange(probeIntRange(value, [&](int x) { return acceptsWith(x); }), true);
      }
    });
  }
  return rows;
}

}  // namespace core
}  // namespace map_aided_fusion

#include "map_aided_fusion/core/parameter_reference.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>

namespace map_aided_fusion {
namespace core {

namespace {

constexpr std::uint64_t kSignBit = std::uint64_t{ 1 } << 63;
/// Significant digits a "short decimal" (a bound typed in the code) has at most.
constexpr int kShortDigits = 6;
constexpr int kMaxDigits = 17;              ///< enough for any double to read back exactly
constexpr double kFullDigitsBelow = 1e15;

/// Monotone map of the doubles (without NaN) to the unsigned integers.
std::uint64_t orderedKey(double x)
{
  std::uint64_t u;
  std::memcpy(&u, &x, sizeof u);
  return (u & kSignBit) ? ~u : (u | kSignBit);
}

double fromKey(std::uint64_t k)
{
  const std::uint64_t u = (k & kSignBit) ? (k & ~kSignBit) : ~k;
  double x;
  std::memcpy(&x, &u, sizeof x);
  return x;
}

/// The boundary between @p good (accepted) and @p bad (rejected): the accepted value nearest to @p bad.
double bisect(double good, double bad, const std::function<bool(double)>& accepts)
{
  std::uint64_t g = orderedKey(good);
  std::uint64_t b = orderedKey(bad);
  while ((g > b ? g - b : b - g) > 1)
  {
    const std::uint64_t mid = g > b ? b + (g - b) / 2 : g + (b - g) / 2;
    if (accepts(fromKey(mid)))
      g = mid;
    else
      b = mid;
  }
  return fromKey(g);
}

/// @p v written with at most kShortDigits significant digits, if that reads back exactly.
std::optional<std::string> shortDecimal(double v)
{
  if (v == 0.0) return std::string("0");
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", kShortDigits, v);
  if (std::strtod(buf, nullptr) != v) return std::nullopt;
  return formatDouble(v);
}

std::string formatBound(double v, bool lower, bool integer)
{
  const char* open = lower ? "(" : "";
  const char* close = lower ? "" : ")";
  const char* open_closed = lower ? "[" : "";
  const char* close_closed = lower ? "" : "]";
  if (integer) return std::string(open_closed) + std::to_string(static_cast<long long>(v)) + close_closed;
  // A `> 0` test: the least positive double (or numeric_limits::min() where the code says so) is accepted.
  if (v != 0.0 && std::fabs(v) <= std::numeric_limits<double>::min()) return std::string(open) + "0" + close;
  if (auto s = shortDecimal(v)) return std::string(open_closed) + *s + close_closed;
  // The successor of a short decimal: the bound is that decimal, excluded.
  const double outside = std::nextafter(v, lower ? -std::numeric_limits<double>::infinity()
                                                 : std::numeric_limits<double>::infinity());
  if (auto s = shortDecimal(outside)) return std::string(open) + *s + close;
  return std::string(open_closed) + formatDouble(v) + close_closed;
}

}  // namespace

std::string formatDouble(double v)
{
  if (std::isnan(v)) return ".nan";
  if (std::isinf(v)) return v > 0 ? ".inf" : "-.inf";
  if (v == 0.0) return "0";
  char buf[64];
  int digits = 1;
  for (; digits < kMaxDigits; ++digits)
  {
    std::snprintf(buf, sizeof buf, "%.*g", digits, v);
    if (std::strtod(buf, nullptr) == v) break;
  }
  // Whole numbers below 10^15 in full (100, not 1e+02).
  const double magnitude = std::fabs(v);
  if (magnitude >= 1.0 && magnitude < kFullDigitsBelow)
    digits = std::max(digits, static_cast<int>(std::floor(std::log10(magnitude))) + 1);
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

ProbedRange probeDoubleRange(double anchor, const std::function<bool(double)>& accepts)
{
  constexpr double kMax = std::numeric_limits<double>::max();
  ProbedRange r;
  if (!accepts(-kMax)) r.lowest = bisect(anchor, -kMax, accepts);
  if (!accepts(kMax)) r.highest = bisect(anchor, kMax, accepts);
  return r;
}

ProbedRange probeIntRange(int anchor, const std::function<bool(int)>& accepts)
{
  ProbedRange r;
  auto edge = [&](std::int64_t good, std::int64_t bad) {
    while (std::llabs(good - bad) > 1)
    {
      const std::int64_t mid = good + (bad - good) / 2;
      if (accepts(static_cast<int>(mid)))
        good = mid;
      else
        bad = mid;
    }
    return static_cast<double>(good);
  };
  constexpr int kMin = std::numeric_limits<int>::min();
  constexpr int kMax = std::numeric_limits<int>::max();
  if (!accepts(kMin)) r.lowest = edge(anchor, kMin);
  if (!accepts(kMax)) r.highest = edge(anchor, kMax);
  return r;
}

std::string formatRange(const ProbedRange& r, bool integer)
{
  const std::string lo = r.lowest ? formatBound(*r.lowest, true, integer) : "(−∞";
  const std::string hi = r.highest ? formatBound(*r.highest, false, integer) : "∞)";
  return lo + ", " + hi;
}

std::string markdownTable(const std::vector<ParamInfo>& rows)
{
  auto cell = [](const std::string& s) {
    std::string out;
    for (char c : s) out += c == '|' ? std::string("\\|") : std::string(1, c);
    return out;
  };
  std::string t = "| name | type | default | unit | valid range | meaning |\n| --- | --- | --- | --- | --- | --- |\n";
  for (const ParamInfo& p : rows)
    t += "| `" + p.name + "` | " + p.type + " | `" + cell(p.default_value) + "` | " + cell(p.unit) + " | " +
         cell(p.range) + " | " + cell(p.meaning) + " |\n";
  return t;
}

}  // namespace core
}  // namespace map_aided_fusion

/**
 * @file parameters.hpp
 * @brief Validation helpers shared by every parameter struct: an out-of-range value is an error
 *        that names the parameter.
 */
#pragma once

#include <cmath>
#include <stdexcept>
#include <string>

namespace map_aided_fusion {
namespace core {

/**
 * @brief What the parameter reference (doc/parameters.md, tool `parameter_reference`) says of a parameter besides
 *        its name, type, default and valid range, which it reads from the struct and its validate().
 *
 * Every forEachParam() list calls `get(name, field, ParamDoc{unit, meaning})`; a getter takes the three arguments.
 */
struct ParamDoc
{
  const char* unit;     ///< "m", "s", "m/s", …; "" for a ratio, a flag or a name
  const char* meaning;  ///< one line
};

/// Thrown by the validate() of a parameter struct; the message starts with the parameter's name.
class ParameterError : public std::invalid_argument
{
public:
  ParameterError(const std::string& name, const std::string& what)
    : std::invalid_argument(name + ": " + what), name_(name)
  {
  }
  /// The offending parameter's name, as spelled in config/*.yaml.
  const std::string& parameter() const { return name_; }

private:
  std::string name_;
};

/// Throws ParameterError unless lo ≤ value ≤ hi (and value is finite).
inline void requireInRange(const std::string& name, double value, double lo, double hi)
{
  if (!std::isfinite(value) || value < lo || value > hi)
    throw ParameterError(name, "value " + std::to_string(value) + " is outside [" + std::to_string(lo) + ", " +
                                   std::to_string(hi) + "]");
}

/// Throws ParameterError unless value is in [0, 1].
inline void requireUnit(const std::string& name, double value) { requireInRange(name, value, 0.0, 1.0); }

/// Throws ParameterError unless value is finite and > 0.
inline void requirePositive(const std::string& name, double value)
{
  if (!std::isfinite(value) || value <= 0.0)
    throw ParameterError(name, "value " + std::to_string(value) + " must be finite and > 0");
}

}  // namespace core
}  // namespace map_aided_fusion

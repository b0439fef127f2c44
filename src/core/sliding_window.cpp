#include "map_aided_fusion/core/sliding_window.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "map_aided_fusion/core/parameters.hpp"

namespace map_aided_fusion {
namespace core {

namespace {

constexpr double kMinPeriod = 0.05;
constexpr double kMaxPeriod = 60.0;
constexpr double kMinWindow = 0.1;
constexpr double kMaxWindow = 600.0;
constexpr double kMaxStale = 3600.0;

std::string format(const char* fmt, double a, double b = 0.0)
{
  char buf[160];
  std::snprintf(buf, sizeof buf, fmt, a, b);
  return buf;
}

}  // namespace

double SlidingSamples::quantile(double now, double q)
{
  prune(now);
  if (samples_.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::vector<double> v;
  v.reserve(samples_.size());
  for (const Sample& s : samples_) v.push_back(s.value);
  const double clamped = std::min(1.0, std::max(0.0, q));
  const auto rank = static_cast<std::size_t>(std::ceil(clamped * static_cast<double>(v.size())));
  const std::size_t k = rank == 0 ? 0 : rank - 1;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

void StreamHealthParams::validate() const
{
  requireInRange("diagnostic_period", diagnostic_period, kMinPeriod, kMaxPeriod);
  requireInRange("diagnostic_window", diagnostic_window, kMinWindow, kMaxWindow);
  requireInRange("stale_error", stale_error, kMinPeriod, kMaxStale);
  requireInRange("stale_warn", stale_warn, kMinPeriod, stale_error);
}

HealthSummary streamHealth(const StreamHealthParams& p, bool ever, double since_last, std::size_t produced,
                           std::size_t lost, const std::string& what)
{
  HealthSummary h;
  const std::string lost_text = lost > 0 ? format(", %.0f inputs dropped or rejected in the last %.0f s",
                                                  static_cast<double>(lost), p.diagnostic_window) :
                                           std::string();
  if (!ever)
  {
    h.level = HealthLevel::kWarn;
    h.message = "no " + what + " yet" + lost_text;
  }
  else if (since_last >= p.stale_error)
  {
    h.level = HealthLevel::kError;
    h.message = "no " + what + format(" for %.1f s", since_last) + lost_text;
  }
  else if (since_last >= p.stale_warn)
  {
    h.level = HealthLevel::kWarn;
    h.message = "no " + what + format(" for %.1f s", since_last) + lost_text;
  }
  else if (lost > 0)
  {
    h.level = HealthLevel::kWarn;
    h.message = format("%.0f ", static_cast<double>(produced)) + what + lost_text;
  }
  else
  {
    h.level = HealthLevel::kOk;
    h.message = format("%.0f ", static_cast<double>(produced)) + what + format(" in the last %.0f s", p.diagnostic_window);
  }
  return h;
}

}  // namespace core
}  // namespace map_aided_fusion

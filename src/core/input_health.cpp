#include "map_aided_fusion/core/input_health.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "map_aided_fusion/core/parameters.hpp"

namespace map_aided_fusion {
namespace core {

namespace {

constexpr double kMaxValidReturns = 1e7;
constexpr double kMaxInputPeriod = 10.0;

}  // namespace

void InputHealthParams::validate() const
{
  requireInRange("min_valid_returns", min_valid_returns, 0.0, kMaxValidReturns);
  requireInRange("input_period", input_period, 0.0, kMaxInputPeriod);
}

const char* toString(BlindReason r)
{
  switch (r)
  {
    case BlindReason::kNone:
      return "sighted";
    case BlindReason::kEmpty:
      return "blind_empty";
    case BlindReason::kNonFinite:
      return "blind_non_finite";
    case BlindReason::kTooFewValid:
      return "blind_too_few_valid";
  }
  return "unknown";
}

BlindReason judgeReturns(std::size_t points, std::size_t valid, const InputHealthParams& params)
{
  if (params.min_valid_returns <= 0) return BlindReason::kNone;
  if (points == 0) return BlindReason::kEmpty;
  if (valid == 0) return BlindReason::kNonFinite;
  return valid < static_cast<std::size_t>(params.min_valid_returns) ? BlindReason::kTooFewValid : BlindReason::kNone;
}

double InputGapCounter::period() const
{
  if (configured_ > 0.0) return configured_;
  if (gaps_.empty()) return 0.0;
  return *std::min_element(gaps_.begin(), gaps_.end());
}

std::size_t InputGapCounter::observe(double stamp)
{
  if (!std::isfinite(stamp)) return 0;
  if (!last_)
  {
    last_ = stamp;
    return 0;
  }
  if (stamp <= *last_)
  {
    // A duplicate or a stamp out of order leaves the reference (the stream goes on from the newest); a stamp far
    // back (a looping bag, a restarted source) starts the count again.
    const double t = period();
    if (!(t > 0.0) || *last_ - stamp > kOutageFactor * t) last_ = stamp;
    return 0;
  }
  const double gap = stamp - *last_;
  last_ = stamp;
  const double t = period();
  std::size_t lost = 0;
  if (t > 0.0 && gap > kLostGapFactor * t && gap <= kOutageFactor * t)
    lost = static_cast<std::size_t>(std::lround(gap / t)) - 1;
  if (gap <= kOutageFactor * (t > 0.0 ? t : gap))
  {
    gaps_.push_back(gap);
    if (gaps_.size() > kLearnedGaps) gaps_.pop_front();
  }
  lost_ += lost;
  return lost;
}

HealthSummary inputHealth(HealthSummary base, const StreamHealthParams& params, const InputFindings& found)
{
  char buf[256];
  if (found.blind)
  {
    const HealthLevel level = found.blind_for >= params.stale_error ? HealthLevel::kError : HealthLevel::kWarn;
    std::snprintf(buf, sizeof buf, "lidar blind for %.1f s: %zu clouds without enough valid returns (%s), not fused",
                  found.blind_for, found.blind_clouds, found.blind_reason.c_str());
    base.level = std::max(base.level, level);
    base.message = buf;
  }
  if (found.lost > 0 || found.overruns > 0)
  {
    base.level = std::max(base.level, HealthLevel::kWarn);
    std::snprintf(buf, sizeof buf, "; overload in the last %.0f s: %zu inputs lost in the input queue, %zu processed "
                  "slower than they come", params.diagnostic_window, found.lost, found.overruns);
    base.message += buf;
  }
  return base;
}

}  // namespace core
}  // namespace map_aided_fusion

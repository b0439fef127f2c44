#include "map_aided_fusion/core/stamp_guard.hpp"

#include <cmath>
#include <limits>

#include "map_aided_fusion/core/parameters.hpp"

namespace map_aided_fusion {
namespace core {

namespace {

constexpr double kMinJumpThreshold = 0.001;
constexpr double kMaxJumpThreshold = 3600.0;
constexpr double kMaxSpeed = 1000.0;

}  // namespace

void TimeGuardParams::validate() const
{
  requireInRange("time_jump_threshold", time_jump_threshold, kMinJumpThreshold, kMaxJumpThreshold);
  requireInRange("max_plausible_speed", max_plausible_speed, std::numeric_limits<double>::min(), kMaxSpeed);
}

const char* toString(StampVerdict v)
{
  switch (v)
  {
    case StampVerdict::kFuse:
      return "fuse";
    case StampVerdict::kZeroStamp:
      return "zero stamp";
    case StampVerdict::kDuplicate:
      return "duplicate stamp";
    case StampVerdict::kOutOfOrder:
      return "out of order";
    case StampVerdict::kTimeJump:
      return "time jump";
    case StampVerdict::kLate:
      return "released late";
  }
  return "unknown";
}

StampVerdict StampGuard::check(double stamp, bool clock_watched) const
{
  if (!std::isfinite(stamp) || stamp <= 0.0) return StampVerdict::kZeroStamp;
  if (!last_) return StampVerdict::kFuse;
  if (stamp > *last_) return StampVerdict::kFuse;
  if (stamp == *last_) return StampVerdict::kDuplicate;
  if (*last_ - stamp <= params_.time_jump_threshold) return StampVerdict::kOutOfOrder;
  return clock_watched ? StampVerdict::kLate : StampVerdict::kTimeJump;
}

bool ClockJumpDetector::observe(double now)
{
  if (!std::isfinite(now)) return false;
  if (latest_ && *latest_ - now > threshold_)
  {
    latest_ = now;
    ++jumps_;
    return true;
  }
  if (!latest_ || now > *latest_) latest_ = now;
  return false;
}

PoseJump checkPoseJump(double x0, double y0, double t0, double x1, double y1, double t1, double max_speed)
{
  PoseJump j;
  j.distance = std::hypot(x1 - x0, y1 - y0);
  const double dt = t1 - t0;
  j.speed = dt > 0.0 ? j.distance / dt : (j.distance > 0.0 ? std::numeric_limits<double>::infinity() : 0.0);
  j.jumped = j.speed > max_speed;
  return j;
}

const char* toString(StartedVerdict v)
{
  switch (v)
  {
    case StartedVerdict::kShift:
      return "shift";
    case StartedVerdict::kNoScanYet:
      return "no scan yet";
    case StartedVerdict::kOtherFrame:
      return "other frame";
    case StartedVerdict::kBadStamp:
      return "bad stamp";
    case StartedVerdict::kNotNewer:
      return "not newer";
    case StartedVerdict::kImplausible:
      return "implausible pose";
    case StartedVerdict::kNoTransform:
      return "no transform";
  }
  return "?";
}

StartedVerdict checkStarted(const StartedReference& ref, const std::string& frame, double stamp, bool stamp_ok,
                            double x, double y, const TimeGuardParams& params)
{
  if (!std::isfinite(stamp) || stamp <= 0.0 || !stamp_ok) return StartedVerdict::kBadStamp;
  if (ref.frame.empty()) return StartedVerdict::kNoScanYet;
  if (frame != ref.frame) return StartedVerdict::kOtherFrame;
  if (stamp <= ref.fused_stamp || (ref.shifted_stamp && stamp <= *ref.shifted_stamp)) return StartedVerdict::kNotNewer;
  if (!std::isfinite(x) || !std::isfinite(y)) return StartedVerdict::kNoTransform;
  if (checkPoseJump(ref.fused_x, ref.fused_y, ref.fused_stamp, x, y, stamp, params.max_plausible_speed).jumped)
    return StartedVerdict::kImplausible;
  return StartedVerdict::kShift;
}

}  // namespace core
}  // namespace map_aided_fusion

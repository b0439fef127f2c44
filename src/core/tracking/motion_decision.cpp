#include "map_aided_fusion/core/tracking/motion_decision.hpp"

namespace map_aided_fusion {
namespace core {

TrackMotion decideMotion(const MotionEvidence& e, double stamp, double& still_since, const MotionDecisionParams& p)
{
  if (e.tentative) return TrackMotion::kUnknown;
  if (e.speed + p.motion_sigmas * e.speed_sigma < p.stopped_speed)
  {
    if (still_since < 0.0) still_since = stamp;
  }
  else
    still_since = -1.0;
  const double sigmas = e.free_space_check ? p.free_space_motion_sigmas : p.motion_sigmas;
  if (clearsSpeed(e.speed, e.speed_sigma, sigmas, p.moving_speed) && (!e.free_space_check || e.motion_seen))
    return TrackMotion::kMoving;
  if (still_since >= 0.0 && stamp - still_since >= p.stopped_time - kStoppedTimeSlack) return TrackMotion::kStopped;
  return TrackMotion::kUnknown;
}

}  // namespace core
}  // namespace map_aided_fusion

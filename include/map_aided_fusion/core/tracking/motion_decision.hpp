/**
 * @file
 * @brief Tracking, part "motion decision": moving, stopped or not yet known, from a track's speed and its standard
 *        deviation — a one-sided test of the evidence that the object moves, and one that it stands still.
 *
 * Moving: the speed clears moving_speed by k standard deviations (k = motion_sigmas; with the free-space check,
 * free_space_motion_sigmas, and only once free space has shown the motion). Stopped: speed + motion_sigmas · σ has
 * stayed below stopped_speed for stopped_time. Anything else, and every tentative track, is not yet known.
 */
#pragma once

namespace map_aided_fusion {
namespace core {

/// Motion decision of a track.
enum class TrackMotion : unsigned char
{
  kUnknown,
  kMoving,   ///< speed − motion_sigmas · σ above moving_speed (and, with the free-space check, Track::motion_seen)
  kStopped,  ///< speed + motion_sigmas · σ below stopped_speed for stopped_time
};

/// While the free-space check runs, free space has shown the motion too, so the speed need clear moving_speed by
/// this many standard deviations only, instead of motion_sigmas (which still decides without a ScanGrid).
constexpr double kFreeSpaceMotionSigmas = 0.5;

/// What the decision reads (TrackerParams' fields of the same names).
struct MotionDecisionParams
{
  double moving_speed = 0.5;               ///< m/s
  double motion_sigmas = 1.5;              ///< standard deviations the speed must clear
  double free_space_motion_sigmas = kFreeSpaceMotionSigmas;  ///< … while the free-space check runs
  double stopped_speed = 0.8;              ///< m/s
  double stopped_time = 1.0;               ///< s
};

/// One scan's evidence of a track's motion.
struct MotionEvidence
{
  bool tentative = false;       ///< not yet confirmed: never decided
  double speed = 0.0;           ///< m/s, relative to the world (the common motion removed)
  double speed_sigma = 0.0;     ///< m/s, its standard deviation
  bool free_space_check = false;  ///< the free-space check ran this scan
  bool motion_seen = false;     ///< … and has shown that the object moved
};

/// s of slack on stopped_time (stamps rounded to microseconds).
constexpr double kStoppedTimeSlack = 1e-6;

/// True when @p speed − @p sigmas · @p speed_sigma is above @p moving_speed (m/s).
inline bool clearsSpeed(double speed, double speed_sigma, double sigmas, double moving_speed)
{
  return speed - sigmas * speed_sigma > moving_speed;
}

/**
 * @brief The decision at @p stamp (s) from @p e; @p still_since (s, −1: not) is the stamp since which the track has
 *        been confidently slow, updated here (left as it is for a tentative track).
 */
TrackMotion decideMotion(const MotionEvidence& e, double stamp, double& still_since, const MotionDecisionParams& p);

}  // namespace core
}  // namespace map_aided_fusion

/**
 * @file
 * @brief Tracking, part "common motion": the motion the whole static world seems to share in the map frame when the
 *        vehicle's pose drifts (a localisation's slow error), as one rigid motion about the sensor,
 *        v(p) = v₀ + ω × (p − sensor), fitted to the velocities of the tracks seen in a scan.
 *
 * Robust in two stages: the per-axis median of the velocities (ω = 0), then, with a sensor position, iteratively
 * reweighted least squares from it (weights 1/σ(speed)², Huber beyond `sigmas` σ) for v₀ and ω; the fit replaces
 * the median when more tracks agree with it (within `sigmas` σ of their velocity), ω is significant (more than
 * `sigmas` standard errors from 0) and at most max_turn_rate. A motion is common when it is no faster than max_speed
 * (a drift, not traffic) and more than `share` of at least min_tracks tracks agree with it (one motion, not a mix).
 */
#pragma once

#include <vector>

#include "map_aided_fusion/core/grid_geometry.hpp"

namespace map_aided_fusion {
namespace core {

/// The common motion's numbers (steps common motion and common turn; fixed, not parameters): at least 20 confirmed
/// tracks seen in the scan, more than half of them within 2 σ(speed) of the motion, which is no faster than 2 m/s and
/// turns no faster than 0.05 rad/s (KITTI 00's drifting poses: 1.0 to 1.6 m/s, a heading drift of about 0.03 rad/s).
constexpr int kCommonMotionMinTracks = 20;
constexpr double kCommonMotionShare = 0.5;
constexpr double kCommonMotionSigmas = 2.0;
constexpr double kCommonMotionMaxSpeed = 2.0;
constexpr double kCommonMotionMaxTurnRate = 0.05;

/// What the fit reads: the constants above and TrackerSteps::common_turn.
struct CommonMotionParams
{
  int min_tracks = kCommonMotionMinTracks;        ///< tracks seen in the scan, at least
  double share = kCommonMotionShare;              ///< in (0, 1]: more than this share must agree
  double sigmas = kCommonMotionSigmas;            ///< σ(speed) of a track from the motion that still agrees with it
  double max_speed = kCommonMotionMaxSpeed;       ///< m/s: a faster common motion is traffic, not a drift
  bool turn = true;                               ///< fit the turn rate too (with a sensor position)
  double max_turn_rate = kCommonMotionMaxTurnRate;  ///< rad/s: a faster turn is not a drift
};

/// A track seen in the scan.
struct SeenTrack
{
  Point2 position;           ///< m, map frame
  Point2 velocity;           ///< m/s
  double speed_sigma = 0.0;  ///< m/s, σ of its speed (Track::speedSigma())
};

/// A scan's common motion.
struct CommonMotion
{
  bool found = false;
  Point2 velocity;         ///< m/s at centre; (0, 0) when none was found
  double turn_rate = 0.0;  ///< rad/s counter-clockwise; 0 when none or not turning
  Point2 centre;           ///< the sensor position it turns about
  /// The common motion at @p p: velocity + ω × (p − centre).
  Point2 at(Point2 p) const
  {
    return Point2{ velocity.x - turn_rate * (p.y - centre.y), velocity.y + turn_rate * (p.x - centre.x) };
  }
};

/// Reweightings of the turning fit.
constexpr int kCommonTurnIterations = 10;
/// m/s: a track's σ(speed) in the turning fit is never below this.
constexpr double kMinCommonSigma = 0.01;
/// Relative residual of the turning fit's normal equations above which they are singular.
constexpr double kCommonTurnSolveTolerance = 1e-9;

/**
 * @brief The common motion of the tracks @p seen (in their order); @p sensor, when given, is the point the motion may
 *        turn about (with p.turn). Not found with fewer than p.min_tracks tracks, a motion faster than p.max_speed or
 *        not shared by more than p.share of them.
 */
CommonMotion fitCommonMotion(const std::vector<SeenTrack>& seen, const Point2* sensor, const CommonMotionParams& p);

}  // namespace core
}  // namespace map_aided_fusion

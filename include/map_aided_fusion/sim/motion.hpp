/**
 * @file motion.hpp
 * @brief Motion of an object (or of the ego vehicle) along a polyline path: trapezoidal speed profile
 *        (accelerate, cruise, brake) with stops of given durations, corners rounded by circular arcs.
 */
#pragma once

#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "map_aided_fusion/core/grid_geometry.hpp"

namespace map_aided_fusion {
namespace sim {

using core::Point2;

/// A stop on a path: the object brakes to rest at arc length @ref s and waits @ref duration seconds
/// (+∞: for ever).
struct Stop
{
  double s = 0.0;         ///< m, arc length along the (rounded) path
  double duration = 0.0;  ///< s
};

/// What happens when an object reaches the end of its path.
enum class PathEnd
{
  kStay,   ///< brake to rest at the end and stay there
  kVanish  ///< drive off the end at speed and disappear
};

/// Parameters of a motion; all distances in metres, times in seconds.
struct MotionParams
{
  double speed = 10.0;         ///< m/s, cruise speed (≥ 0; 0 = static)
  double acceleration = 1.5;   ///< m/s², used to speed up and to brake (> 0)
  double start_time = 0.0;     ///< s, the object appears (already at cruise speed unless a stop is at s = 0)
  double corner_radius = 6.0;  ///< m, radius of the arcs that round the path's corners (0: sharp corners)
  PathEnd end = PathEnd::kStay;
  std::vector<Stop> stops;  ///< any order; stops beyond the path's end are clamped to it
  /// @throws core::ParameterError naming the parameter (prefixed by @p prefix)
  void validate(const std::string& prefix) const;
};

/// The state of a moving object at one instant.
struct MotionState
{
  bool present = false;  ///< false before start_time and after vanishing
  double x = 0.0, y = 0.0;
  double yaw = 0.0;    ///< rad, heading along the path
  double speed = 0.0;  ///< m/s along the heading
  double s = 0.0;      ///< m, arc length travelled
  double vx() const;
  double vy() const;
};

/// Replaces each interior corner of @p points by a circular arc of radius ≤ @p radius (smaller when
/// the adjacent segments are short), sampled every @p max_step_rad radians at most.
std::vector<Point2> roundCorners(const std::vector<Point2>& points, double radius, double max_step_rad);

/// A path and its speed schedule, evaluated in closed form at any time.
class PathMotion
{
public:
  /// @throws core::ParameterError when the path has fewer than 1 point or the parameters are invalid.
  PathMotion(const std::vector<Point2>& path, const MotionParams& params);

  MotionState at(double t) const;

  double length() const { return cumulative_.empty() ? 0.0 : cumulative_.back(); }
  /// Arc length of the path point nearest to @p p.
  double project(Point2 p) const;
  /// Time at which the object has finished its path (reached the end and, if it stays, stopped), +∞ when a
  /// stop lasts for ever.
  double endTime() const { return end_time_; }
  const std::vector<Point2>& points() const { return points_; }

private:
  struct Leg
  {
    double s0 = 0.0, length = 0.0;
    double t0 = 0.0;                        // time the leg starts
    double v0 = 0.0, vp = 0.0, v1 = 0.0;    // start, peak and end speeds
    double t_acc = 0.0, t_cruise = 0.0, t_dec = 0.0;
    double dwell = 0.0;                     // wait at the end of the leg
  };
  void pose(double s, double& x, double& y, double& yaw) const;
  double distanceInLeg(std::size_t leg, double tau, double& speed) const;

  std::vector<Point2> points_;
  std::vector<double> cumulative_;
  std::vector<double> vertex_yaw_;
  std::vector<Leg> legs_;
  std::vector<double> acc_;  // acceleration of each leg
  MotionParams params_;
  double end_time_ = 0.0;
};

}  // namespace sim
}  // namespace map_aided_fusion

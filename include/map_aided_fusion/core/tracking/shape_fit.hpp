/**
 * @file
 * @brief Tracking, part "shape fit": the rectangle of a cluster's returns seen from above.
 *
 * The principal axis of the returns' scatter, or, for a cluster long enough to show a vehicle's sides, the
 * search-based rectangle fit with the closeness criterion (Zhang et al. 2017, "Efficient L-shape fitting for vehicle
 * detection using laser scanners"): every heading in steps of @ref BoxFitParams::step_deg over 90° is scored by
 * Σ 1 / max(distance of a return to the rectangle's nearest edge, closeness), and the best one is kept.
 */
#pragma once

#include <vector>

#include <Eigen/Core>

#include "map_aided_fusion/core/grid_geometry.hpp"

namespace map_aided_fusion {
namespace core {

/// The rectangle fit's numbers (step box fit; fixed, not parameters): rectangles every 3° in [0°, 90°), a return
/// within 5 cm of an edge (a lidar's range noise) scoring as if on it, and clusters shorter than 1.5 m (a
/// pedestrian's returns, which have no edges to fit) keeping their principal axes.
constexpr double kBoxFitStepDeg = 3.0;
constexpr double kBoxFitCloseness = 0.05;
constexpr double kBoxFitMinLength = 1.5;

/// What the rectangle fit reads: the constants above, TrackerSteps::box_fit and TrackerParams::max_object_length.
struct BoxFitParams
{
  bool enabled = true;      ///< off: the principal axis only
  double min_length = kBoxFitMinLength;  ///< m: a cluster shorter than this along its principal axis keeps that axis
  double max_length = 18.0;  ///< m: a cluster longer than √2 · this along its principal axis is no object: not fitted
  double step_deg = kBoxFitStepDeg;     ///< deg: the headings tried, in (0, 45]
  double closeness = kBoxFitCloseness;  ///< m: distances to an edge below this score as this
};

/// A cluster's rectangle: its axes and its extents along them, from the returns' mean.
struct ClusterBox
{
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();   ///< m, the returns' mean (map frame)
  Eigen::Vector2d major = Eigen::Vector2d::UnitX();  ///< unit: the rectangle's longer side
  double lo_u = 0.0, hi_u = 0.0;  ///< m: the returns' extent along major, from the mean
  double lo_v = 0.0, hi_v = 0.0;  ///< m: along the minor axis (major turned by +90°)
  /// The rectangle fit turned the axes more than one step from the principal axis.
  bool fitted = false;
  double length() const { return hi_u - lo_u; }
  double width() const { return hi_v - lo_v; }
};

/**
 * @brief The rectangle of the returns @p points[@p idx] (at least one): the principal axis of their scatter (the
 *        eigenvector of its largest eigenvalue), and with @p p.enabled, for a cluster between p.min_length and
 *        √2 · p.max_length long along it, the rectangle fit's axis (within 90° of the principal axis, along the
 *        longer side).
 */
ClusterBox fitClusterBox(const std::vector<Point2>& points, const std::vector<int>& idx, const BoxFitParams& p);

/**
 * @brief The rectangle fit alone: the axis, along the rectangle's longer side and within 90° of @p principal, of the
 *        best of the rectangles at headings 0, step, 2·step … below 90° around @p mean.
 */
Eigen::Vector2d fittedAxis(const std::vector<Point2>& points, const std::vector<int>& idx, const Eigen::Vector2d& mean,
                           const Eigen::Vector2d& principal, const BoxFitParams& p);

}  // namespace core
}  // namespace map_aided_fusion

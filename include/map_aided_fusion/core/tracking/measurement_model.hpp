/**
 * @file
 * @brief Tracking, part "measurement model": what one cluster says of a tracked object — its measurement (centroid,
 *        box, covariance), the point of the object it places (the anchor point) and how well it places it.
 *
 * A partly seen object's cluster is shorter than its box: the track follows the centre of its box placed on the
 * cluster's end nearest the sensor (the rest is hidden, out of range or not yet seen), or, when that end is cut by an
 * occluder and the other end has free space beyond it (step open ends), on the other end. The anchor's covariance is
 * the cluster's (σ growing with its extent) grown by half the change of the cluster's extent since the track's last
 * cluster, with the steps hidden ends, open anchor and far growth (TrackerParams).
 */
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "map_aided_fusion/core/grid_geometry.hpp"
#include "map_aided_fusion/core/tracking/shape_fit.hpp"

namespace map_aided_fusion {
namespace core {

/// One object seen in one scan: a cluster of obstacle returns (map frame).
struct Measurement
{
  Point2 centroid;
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Identity();  ///< of the centroid, m²
  double yaw = 0.0;     ///< rad, the cluster's major axis
  double length = 0.0;  ///< m, extent along the major axis
  double width = 0.0;   ///< m, extent along the minor axis
  /// The cluster's box relative to the centroid: [lo_u, hi_u] along the major axis, [lo_v, hi_v] along the minor.
  double lo_u = 0.0, hi_u = 0.0, lo_v = 0.0, hi_v = 0.0;
  int points = 0;
  bool has_sensor = false;  ///< the sensor position is known (the end of a partly seen object nearest it is real)
  Point2 sensor;            ///< map frame
  /// Step open ends, when ends_seen: the faces of the box (kLowU … kHighV) with free space beyond them, and those the
  /// sensor cannot see past because a nearer obstacle blocks its line of sight.
  std::uint8_t open = 0, occluded = 0;
  bool ends_seen = false;
  static constexpr std::uint8_t kLowU = 1, kHighU = 2, kLowV = 4, kHighV = 8;
  std::vector<int> returns;  ///< clusterReturns(): indices of its returns in the points clustered
  bool split = false;  ///< step background split: a piece of the returns off background of a cluster too large
  bool fitted = false;  ///< step box fit: its axes are more than BoxFitParams::step_deg off its principal axes
};

/// The box of a measurement seen along an axis: its interval relative to the centroid, and whether its low end is the
/// object's end, on which a longer box is anchored.
struct AxisView
{
  double lo = 0.0, hi = 0.0;
  bool anchor_lo = true;
};

/// rad: step open ends probes the cluster's own faces, so it decides along a box axis this near one of them only.
constexpr double kOpenEndsMaxAngle = 20.0 * 3.14159265358979323846 / 180.0;
/// m: a cluster this much shorter or longer than the track's box is partly seen.
constexpr double kAnchorTolerance = 0.3;
/// rad (about 6°): axes this near are the same (steps second axes, long box, far growth).
constexpr double kMinAxesTurn = 0.1;

/**
 * @brief The box of @p m (its four corners) seen along the unit vector @p axis (map frame). It is anchored on its end
 *        nearest the sensor, unless (Measurement::ends_seen, step open ends, along an axis within kOpenEndsMaxAngle of
 *        one of the cluster's) that end is occluded and the other open: then on the other.
 */
AxisView viewAlong(const Measurement& m, const Eigen::Vector2d& axis);

/// m: the standard deviation step hidden ends adds along the axis of a cluster seen through a gap (fixed: the
/// length of a car seen through the gap between two parked cars, so that its views tell a track nothing there).
constexpr double kHiddenEndsSigma = 5.0;

/// What the measurement model reads (TrackerParams' sigmas, TrackerSteps' switches of the same names).
struct MeasurementModelParams
{
  double measurement_sigma = 0.15;  ///< m, standard deviation of a compact cluster's centroid
  double extent_sigma = 0.1;        ///< m of standard deviation per metre of extent
  bool hidden_ends = true;          ///< step hidden ends
  double hidden_ends_sigma = kHiddenEndsSigma;  ///< m
  bool open_anchor = true;          ///< step open anchor
  bool far_growth = true;           ///< step far growth
};

/// What the measurement model reads of a track.
struct TrackView
{
  double box_yaw = 0.0, box_length = 0.0, box_width = 0.0;  ///< its box (Track::extent_yaw, extent_length, extent_width)
  double last_length = 0.0, last_width = 0.0;  ///< m, its last cluster's extents (Track::length, width)
  bool moving = false;                          ///< its motion decision is moving
};

/// Standard deviation (m) of a cluster's centroid along an axis on which it extends @p extent m.
inline double clusterSigma(const MeasurementModelParams& p, double extent)
{
  return p.measurement_sigma + p.extent_sigma * extent;
}

/// The measurement of a cluster of returns @p idx with the rectangle @p box: its centroid, box and the centroid's
/// covariance, clusterSigma() of its extent along each of the box's axes.
Measurement measurementOf(const ClusterBox& box, std::vector<int>&& idx, const MeasurementModelParams& p);

/// True when @p m can place @p t's box by an end: the sensor is known and both have a length.
bool anchored(const TrackView& t, const Measurement& m);

/**
 * @brief The point of @p m that the track @p t follows: the centre of the track's box placed on the cluster. Along
 *        each of the box's axes, when the cluster's extent differs from the box's by more than kAnchorTolerance, the
 *        box is placed on the cluster's anchoring end (viewAlong()); otherwise the middle of the cluster's extent.
 *        Without a sensor position, or a box, the centroid.
 */
Point2 anchorPoint(const TrackView& t, const Measurement& m);

/// Step hidden ends: @p m's two ends along its major axis are hidden and neither is open, and @p t is not yet moving.
bool hiddenEnds(const TrackView& t, const Measurement& m, const MeasurementModelParams& p);

/// Step open anchor: the end of @p m on which @p t's box is anchored along the cluster's major axis has free space
/// beyond it.
bool openAnchor(const TrackView& t, const Measurement& m, const MeasurementModelParams& p);

/// Step far growth: @p m is placed by its open anchoring end (@p open, openAnchor()) and its major axis is one of
/// @p t's box axes (within kMinAxesTurn).
bool farGrowth(const TrackView& t, const Measurement& m, const MeasurementModelParams& p, bool open);

/**
 * @brief The covariance (m²) of anchorPoint(): the measurement's, grown by half the change of the cluster's extent
 *        since the track's last cluster on each axis (a partly seen object's centroid is off by up to half the part
 *        not seen); with step hidden ends, by hidden_ends_sigma along the major axis of a cluster whose ends are
 *        hidden. With step open anchor, a cluster placed by its open end has measurement_sigma along its major axis
 *        instead of its own σ; with step far growth, that axis does not grow.
 */
Eigen::Matrix2d anchorCovariance(const TrackView& t, const Measurement& m, const MeasurementModelParams& p);

}  // namespace core
}  // namespace map_aided_fusion

/**
 * @file cluster_measurements.hpp
 * @brief A scan's measurements: its obstacle returns flagged on static background, clustered, each cluster fitted
 *        (shape_fit.hpp) and made a measurement (measurement_model.hpp); steps background split and box fit.
 */
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "map_aided_fusion/core/grid_geometry.hpp"
#include "map_aided_fusion/core/mass_grid.hpp"
#include "map_aided_fusion/core/tracking/measurement_model.hpp"
#include "map_aided_fusion/core/tracking/tracker_params.hpp"

namespace map_aided_fusion {
namespace core {

/// The measurement model's share of @p p: its sigmas and steps hidden ends, open anchor and far growth.
MeasurementModelParams measurementModelOf(const TrackerParams& p);

/**
 * @brief Per return of @p returns (vehicle frame, vehicle pose @p pose): 1 when it lies on static background, i.e.
 *        @p onBackground(its map point) is true (trackScan(): its map cell's counter ζ is above background_zeta or,
 *        with step building background, its BetP(C) above kBuildingBackgroundBetP).
 */
template <class OnBackground>
void backgroundFlags(const Pose2& pose, const ObstaclePoints& returns, OnBackground&& onBackground,
                     std::vector<std::uint8_t>& flags)
{
  flags.assign(returns.count, 0);
  const double c = std::cos(pose.yaw), s = std::sin(pose.yaw);
  for (std::size_t i = 0; i < returns.count; ++i)
  {
    const double x = returns.xy[2 * i], y = returns.xy[2 * i + 1];
    flags[i] = onBackground(Point2{ pose.x + c * x - s * y, pose.y + s * x + c * y }) ? 1 : 0;
  }
}


/**
 * @brief Clusters map-frame returns: cells of cluster_distance / 2 holding returns, 8-connected, are one cluster.
 *        Clusters with fewer than min_cluster_points returns, longer than max_object_length or wider than
 *        max_object_width, or (with @p background, one flag per point) with more than background_share of their
 *        returns on background are dropped; non-finite points are skipped. With @p background and step background
 *        split, the returns not on background of the clusters too long or wide are clustered again: the pieces at
 *        most pedestrian_size long and wide are measurements too, with Measurement::split set.
 */
std::vector<Measurement> clusterReturns(const std::vector<Point2>& points, const TrackerParams& params,
                                        const std::vector<std::uint8_t>* background = nullptr);

}  // namespace core
}  // namespace map_aided_fusion

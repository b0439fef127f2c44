/**
 * @file
 * @brief Tracking, part "association": which tracks and measurements may pair, and at what cost; the pairing itself
 *        is the global assignment of assignment.hpp (solveAssignment(const SparseCosts&, …)).
 *
 * Two gates, as in the multi-target trackers of the field (Autoware's multi_object_tracker, AB3DMOT): a coarse
 * spatial one that finds the candidate pairs through a grid without looking at every track × measurement, then the
 * statistical one, the squared Mahalanobis distance of the innovation under a χ² threshold, whose value is the
 * pair's cost.
 */
#pragma once

#include <optional>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "map_aided_fusion/core/grid_geometry.hpp"

namespace map_aided_fusion {
namespace core {

/// A disc of the spatial gate: everything a track or a measurement may pair with lies within it.
struct GateDisc
{
  Point2 centre;        ///< m, map frame
  double radius = 0.0;  ///< m
};

/// Cells one disc covers in the candidate search's grid, at most; a wider disc is paired with every disc of the
/// other side (and the exact distance test decides).
constexpr long long kMaxGateCells = 1024;

/**
 * @brief The candidate pairs (row, column) of the spatial gate: every @p rows[i] and @p cols[j] whose discs meet
 *        (distance of the centres ≤ the sum of the radii), found through a grid of square cells of side @p cell (m,
 *        > 0): the columns are indexed in the cells their discs cover, each row looks in the cells its disc covers.
 *        The cost grows with the discs near each other, not with rows × columns. Sorted by row; within a row, the
 *        columns wider than kMaxGateCells cells first, then in the order the grid finds them, each once. A pair whose
 *        distance or radii are not a number does not meet; an infinite radius meets every finite centre.
 */
std::vector<std::pair<int, int>> spatialGate(const std::vector<GateDisc>& rows, const std::vector<GateDisc>& cols,
                                             double cell);

/**
 * @brief The statistical gate: the squared Mahalanobis distance yᵀ S⁻¹ y of the innovation @p y (m) with covariance
 *        @p s (m²), when |y| ≤ @p max_distance (m) and the distance is finite, ≥ 0 and ≤ @p gate (a χ² quantile with
 *        two degrees of freedom); nothing otherwise (also when S has lost its definiteness).
 */
std::optional<double> mahalanobisGate(const Eigen::Vector2d& y, const Eigen::Matrix2d& s, double max_distance,
                                      double gate);

}  // namespace core
}  // namespace map_aided_fusion

/**
 * @file
 * @brief Tracking, part "clustering": the returns of one scan grouped into objects by connected cells.
 *
 * The first of the tracker's parts (issue 63: one unit per concern, each tested alone). A return lies in a cell of a
 * square lattice of side @p cell on the world's axes (the same cells from scan to scan); returns in cells that touch,
 * sides or corners (8-connectivity), are one cluster. This is the grid-based Euclidean clustering of lidar trackers
 * (Autoware's euclidean_cluster in its voxel-grid form): two returns closer than one cell always share a cluster, two
 * returns farther than 2√2 cells never do unless returns between them join them.
 */
#pragma once

#include <vector>

#include "map_aided_fusion/core/grid_geometry.hpp"

namespace map_aided_fusion {
namespace core {

/**
 * @brief The clusters of @p points: each a list of indices into @p points in increasing order, the clusters in the
 *        order of their first return. Non-finite returns, and returns so far out that their cell has no index (beyond
 *        10¹⁵ cells), belong to no cluster.
 * @param cell  m, the lattice's side, > 0
 *
 * Linear in the returns: a dense index over the returns' bounding box, or a hash map when that box is too large (far
 * outliers); a union-find over the occupied cells.
 */
std::vector<std::vector<int>> connectedClusters(const std::vector<Point2>& points, double cell);

}  // namespace core
}  // namespace map_aided_fusion

/**
 * @file scan_evidence.hpp
 * @brief What one scan gave each cell of the MapGrid's window (ROS-free): free or occupied mass in the fused scan,
 *        or why none. It explains the labelled-ground cells that are not decided F (PointLabelScorer).
 */
#pragma once

#include <array>
#include <cstdint>
#include <string_view>
#include <vector>

#include "map_aided_fusion/core/grid_geometry.hpp"
#include "map_aided_fusion/core/mass_grid.hpp"
#include "map_aided_fusion/core/return_class.hpp"

namespace map_aided_fusion {
namespace core {
class MapGrid;
}  // namespace core

namespace eval {

struct LabelledPoint;

/// What the last scan gave a window cell.
enum class ScanEvidence : std::uint8_t
{
  kFree = 0,       ///< free mass in the scan as fused (after the steps of the projection)
  kOccupied = 1,   ///< occupied mass in the scan as fused
  kCleared = 2,    ///< free in the ScanGrid, none as fused: taken by step obstacle clearance (or the resampling)
  kUnreached = 3,  ///< no mass in the ScanGrid: its sector's free space ended before it (a nearer obstacle return,
                   ///< or the sector's last ground return)
  kAmbiguous = 4,  ///< no mass in the ScanGrid, and it holds a return neither ground nor obstacle (a height between
                   ///< the bands, a low relief, or disputed by the two ground models): steps ambiguous unknown and
                   ///< ground consensus
};

/// Number of ScanEvidence values.
constexpr int kNumScanEvidence = 5;

/// Names in code order, for metrics keys: "free", "occupied", "cleared", "unreached", "ambiguous".
constexpr std::array<std::string_view, kNumScanEvidence> kScanEvidenceNames{ "free", "occupied", "cleared",
                                                                             "unreached", "ambiguous" };

/// ScanEvidence per cell of a window (row-major, as the decision grid of the same scan).
struct EvidenceGrid
{
  core::GridGeometry geometry;
  std::vector<ScanEvidence> cells;
};

/**
 * @brief The evidence one scan gave each cell of @p grid's window after its update with that scan: the scan as
 *        the update fused it (ScanProjection with @p grid's parameters: point occupancy, obstacle clearance), and
 *        the ScanGrid @p scan itself sampled at each cell's centre. Cells without mass are kUnreached here;
 *        refineAmbiguous() tells the ambiguous ones.
 * @param scan       the ScanGrid of the scan (vehicle frame)
 * @param pose       the vehicle's pose in the map frame at the scan
 * @param grid       the MapGrid after its update with the scan (its window and parameters)
 * @param obstacles  the scan's obstacle returns (vehicle frame), as given to the update; nullptr: none
 */
EvidenceGrid scanEvidence(const core::ScanMassGrid& scan, const core::Pose2& pose, const core::MapGrid& grid,
                          const core::ObstaclePoints* obstacles);

/**
 * @brief Marks kAmbiguous the kUnreached cells of @p evidence that hold a point of @p points (map frame) which the
 *        sensor model called neither ground nor obstacle (@p classes, same order: kHeightGap, kLowRelief or
 *        kDisputed). A size mismatch throws std::invalid_argument.
 */
void refineAmbiguous(EvidenceGrid& evidence, const std::vector<LabelledPoint>& points,
                     const std::vector<core::ReturnClass>& classes);

}  // namespace eval
}  // namespace map_aided_fusion

/**
 * @file cell_class.hpp
 * @brief Hard per-cell classes of Ω_MG, as coded in the `decision` layer of the fusion and in the
 *        simulator's ground truth (`/ground_truth/classes`), both nav_msgs/OccupancyGrid.
 */
#pragma once

#include <array>
#include <cstdint>
#include <string_view>

namespace map_aided_fusion {
namespace core {

/// A cell's class; the values are the OccupancyGrid codes.
enum class CellClass : std::int8_t
{
  kUnknown = -1,        ///< not observed / nothing dominates
  kFree = 0,            ///< F
  kBuilding = 1,        ///< C: mapped infrastructure
  kInfrastructure = 2,  ///< N: non-mapped infrastructure (poles, bins, trees, unmapped buildings)
  kStopped = 3,         ///< S: temporarily stopped object
  kMoving = 4,          ///< V: moving object
  /// Decision layer only: occupied, motion (or class) not yet known (the step "motion margin": S and V within
  /// motion_margin of each other, or occupied with no class decided). Never a ground-truth class.
  kOccupied = 5,
};

/// Number of known classes (F, C, N, S, V).
constexpr int kNumCellClasses = 5;

/// Short names in code order: "F", "C", "N", "S", "V".
constexpr std::array<std::string_view, kNumCellClasses> kCellClassNames{ "F", "C", "N", "S", "V" };

/// Long names in code order, for reports (metrics keys use these).
constexpr std::array<std::string_view, kNumCellClasses> kCellClassLongNames{ "free", "building", "infrastructure",
                                                                              "stopped", "moving" };

}  // namespace core
}  // namespace map_aided_fusion

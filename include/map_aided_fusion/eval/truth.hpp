/**
 * @file truth.hpp
 * @brief The evaluation's ground-truth and decision types (ROS-free): class grids and labelled objects.
 */
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "map_aided_fusion/core/cell_class.hpp"
#include "map_aided_fusion/core/grid_geometry.hpp"

namespace map_aided_fusion {
namespace eval {

using core::kNumCellClasses;

/// A class grid (ground truth or decision) in the map frame: core::CellClass codes per cell.
struct ClassGrid
{
  core::GridGeometry geometry;
  std::vector<std::int8_t> cells;
  /// The code at a world point, kUnknown outside.
  std::int8_t at(core::Point2 p) const;
};

/// One ground-truth object at one instant.
struct TruthObject
{
  std::uint32_t id = 0;
  core::CellClass cell_class = core::CellClass::kMoving;
  std::string kind;
  core::Point2 centre;
  double yaw = 0.0;
  double length = 0.0;
  double width = 0.0;
  double speed = 0.0;  ///< m/s
  double vx = 0.0, vy = 0.0;  ///< m/s, map frame
  double z = 0.0;       ///< m, height of the box centre (map frame)
  double height = 0.0;  ///< m, box height (0: unknown)
  /// True when p lies in the object's footprint grown by @p margin metres on every side.
  bool contains(core::Point2 p, double margin = 0.0) const;
};

}  // namespace eval
}  // namespace map_aided_fusion

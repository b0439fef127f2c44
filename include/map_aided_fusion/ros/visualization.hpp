/**
 * @file visualization.hpp
 * @brief Static converters from the MapGrid's decisions and objects to rviz markers, in the paper's colours
 *        (F white, C blue, N cyan, S green, V red). Pure functions, tested without a ROS master.
 */
#pragma once

#include <cstdint>
#include <vector>

#include <std_msgs/ColorRGBA.h>
#include <std_msgs/Header.h>
#include <visualization_msgs/MarkerArray.h>

#include "map_aided_fusion/core/cell_class.hpp"
#include "map_aided_fusion/core/grid_geometry.hpp"
#include "map_aided_fusion/core/map_grid.hpp"

namespace map_aided_fusion {

/// Marker builders.
class Visualization
{
public:
  /// The paper's colour of a class (F white, C blue, N cyan, S green, V red; unknown transparent grey).
  static std_msgs::ColorRGBA classColour(core::CellClass c);

  /**
   * @brief One CUBE_LIST per known class (namespace "cells/<class>"), a cube per decided cell at z = 0.
   * @param include_free also draw free cells (white); off, only occupied classes are drawn.
   */
  static void decisionToCells(const core::GridGeometry& geometry, const std::vector<std::int8_t>& decision,
                              const std_msgs::Header& header, bool include_free, visualization_msgs::MarkerArray& out);

  /**
   * @brief A DELETEALL, then per object an oriented CUBE (namespace "objects/box") and a TEXT_VIEW_FACING
   *        label (namespace "objects/label": "moving 0.82" or "stopped 0.64").
   */
  static void objectsToMarkers(const std::vector<core::GridObject>& objects, const std_msgs::Header& header,
                               double box_height, visualization_msgs::MarkerArray& out);
};

}  // namespace map_aided_fusion

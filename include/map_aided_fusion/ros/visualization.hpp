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
#include "map_aided_fusion/TrackedObjectArray.h"
#include "map_aided_fusion/core/map_grid.hpp"
#include "map_aided_fusion/core/track_evidence.hpp"
#include "map_aided_fusion/core/tracker.hpp"

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

  /**
   * @brief The reported tracks (confirmed and coasting) as messages: id, motion (cell_class 3 stopped, 4 moving,
   *        5 not yet known), box, velocity and its covariance, age, hits. Tentative tracks are left out, and so are
   *        the tracks not yet checked against static background (core::Track::published()).
   * @param now  s, the scan's stamp (for the age)
   * @param boxes  what each track reports as its object (core::reportedBoxes(), one per track, in order); empty: each
   *               track's own box (core::ownBox())
   */
  static void tracksToMessage(const std::vector<core::Track>& tracks, const std_msgs::Header& header, double now,
                              double box_height, TrackedObjectArray& out,
                              const std::vector<core::ObjectBox>& boxes = {});

  /**
   * @brief A DELETEALL, then per tracked object an oriented CUBE coloured by its motion (moving red, stopped green,
   *        not yet known orange; namespace "tracks/box"), an ARROW of its velocity over one second ("tracks/velocity")
   *        and a label "#12 moving 7.3 m/s" ("tracks/label").
   */
  static void tracksToMarkers(const TrackedObjectArray& tracks, visualization_msgs::MarkerArray& out);
};

}  // namespace map_aided_fusion

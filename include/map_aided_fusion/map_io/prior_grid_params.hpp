/**
 * @file prior_grid_params.hpp
 * @brief Parameters of the PriorGridNodelet and prior_grid_tool (config/prior_grid.yaml), ROS-free, and the
 *        choice of the published window.
 */
#pragma once

#include <cstddef>
#include <string>

#include "map_aided_fusion/core/grid_geometry.hpp"
#include "map_aided_fusion/core/prior.hpp"
#include "map_aided_fusion/core/prior_grid.hpp"
#include "map_aided_fusion/map_io/map_loader.hpp"

namespace map_aided_fusion {
namespace map_io {

/// Everything the PriorGrid component reads from its parameters. Units in the field comments.
struct PriorGridParams
{
  MapLoadParams map;                ///< the map file and how to read it (see map_loader.hpp)
  std::string frame_id = "map";     ///< frame of the published grids and markers
  double resolution = 0.5;          ///< cell side, metres (> 0)
  core::PriorConfidence beta;       ///< β_B, β_R, β_T of equation 1, each in [0, 1] (defaults 0.9, 0.9, 0.8)
  core::PriorGridOptions options;   ///< cell_test, building_accuracy, road_accuracy (m) (core/prior_grid.hpp)
  double margin = 0.0;              ///< metres added around the map's extent (>= 0)
  /// Side in metres of the square published around (publish_centre_x, publish_centre_y); 0: the map's extent.
  double publish_size = 0.0;
  double publish_centre_x = 0.0;    ///< map frame, metres (default: the origin)
  double publish_centre_y = 0.0;    ///< map frame, metres
  /// Upper bound on the published cells (an EvidentialGrid carries 16 bytes per cell): the default 4e6 cells is
  /// 1 km × 1 km at 0.5 m (64 MB). A larger window is cropped to the largest square around the publish centre
  /// that fits, with a warning.
  double max_published_cells = 4.0e6;
  bool publish_outlines = true;     ///< publish prior_grid/outlines (MarkerArray)
  /// The vehicle's frame: the node warns (once per excursion) and its diagnostics say so when the vehicle is
  /// farther than max_vehicle_distance from every building, road area and road line of the map.
  std::string vehicle_frame = "base_link";
  double max_vehicle_distance = 500.0;  ///< metres, [0, 1e7]; 0: not checked

  /// @throws core::ParameterError naming the offending parameter (also validates map and beta).
  void validate() const;
};

/**
 * @brief Calls `get(name, field)` for every parameter of @p p, by its name in config/prior_grid.yaml, so that
 *        the ROS parameter server (PriorGridNodelet) and a YAML file (prior_grid_tool --config) read the same
 *        keys. `get` leaves the field unchanged when the key is absent and throws core::ParameterError(name, …)
 *        when its type is wrong. Field types: std::string, double, bool, std::vector<std::string>,
 *        std::map<std::string, double> (road_class_widths: replaces the default table).
 * @throws core::ParameterError for an unknown `source`.
 */
template <class Get>
void forEachPriorGridParam(PriorGridParams& p, Get&& get)
{
  MapLoadParams& m = p.map;
  get("map_file", m.file);
  std::string source = toString(m.source);
  get("source", source);
  m.source = parseMapSourceKind(source);
  get("origin_latitude", m.origin_latitude);
  get("origin_longitude", m.origin_longitude);
  get("origin_altitude", m.origin_altitude);
  get("metric", m.metric);
  get("max_origin_distance", m.max_origin_distance);
  get("building_layer", m.building_layer);
  get("road_layer", m.road_layer);
  get("road_area_layer", m.road_area_layer);
  get("building_attribute", m.building_attribute);
  get("building_height_attribute", m.building_height_attribute);
  get("building_levels_attribute", m.building_levels_attribute);
  get("road_class_attribute", m.road_class_attribute);
  get("road_width_attribute", m.road_width_attribute);
  get("road_lanes_attribute", m.road_lanes_attribute);
  get("road_area_attribute", m.road_area_attribute);
  get("road_tunnel_attribute", m.road_tunnel_attribute);
  get("exclude_tunnels", m.exclude_tunnels);
  get("drivable_classes", m.drivable_classes);
  get("lane_width", m.lane_width);
  get("level_height", m.level_height);
  get("default_road_width", m.default_road_width);
  get("road_class_widths", m.road_class_widths);
  get("repair_invalid", m.repair_invalid);
  get("max_vertices_per_feature", m.max_vertices_per_feature);
  get("frame_id", p.frame_id);
  get("resolution", p.resolution);
  get("beta_building", p.beta.beta_building);
  get("beta_road", p.beta.beta_road);
  get("beta_other", p.beta.beta_other);
  std::string cell_test = core::toString(p.options.cell_test);
  get("cell_test", cell_test);
  p.options.cell_test = core::parsePriorCellTest(cell_test);
  get("building_accuracy", p.options.building_accuracy);
  get("road_accuracy", p.options.road_accuracy);
  get("margin", p.margin);
  get("publish_size", p.publish_size);
  get("publish_centre_x", p.publish_centre_x);
  get("publish_centre_y", p.publish_centre_y);
  get("max_published_cells", p.max_published_cells);
  get("publish_outlines", p.publish_outlines);
  get("vehicle_frame", p.vehicle_frame);
  get("max_vehicle_distance", p.max_vehicle_distance);
}

/**
 * @brief The window to publish: the map's @p extent, or the publish_size square around the publish centre,
 *        intersected with the extent and then capped at max_published_cells (a square around the publish
 *        centre, clipped to the extent). Aligned on @p extent's cells.
 * @param cropped set when the cap reduced the window
 * @throws core::ParameterError when the window does not overlap the map's extent.
 */
core::GridGeometry publishedWindow(const core::GridGeometry& extent, const PriorGridParams& params, bool& cropped);

}  // namespace map_io
}  // namespace map_aided_fusion

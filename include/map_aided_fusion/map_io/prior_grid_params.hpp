/**
 * @file prior_grid_params.hpp
 * @brief Parameters of the PriorGridNodelet and prior_grid_tool (config/prior_grid.yaml), ROS-free, and the
 *        choice of the published window.
 */
#pragma once

#include <cstddef>
#include <string>

#include "map_aided_fusion/core/parameters.hpp"
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
  get("map_file", m.file, { "", "map file: OSM (.osm, .osm.pbf), GeoJSON, Shapefile, GeoPackage; \"\": no prior" });
  std::string source = toString(m.source);
  get("source", source, { "", "file format: auto (from the file), osm or ign" });
  m.source = parseMapSourceKind(source);
  get("origin_latitude", m.origin_latitude, { "deg", "WGS84 origin of the map frame; NaN: the centre of the data" });
  get("origin_longitude", m.origin_longitude, { "deg", "see origin_latitude" });
  get("origin_altitude", m.origin_altitude, { "m", "altitude of the origin above the ellipsoid" });
  get("metric", m.metric, { "", "coordinates are already metric in the map frame (no projection)" });
  get("max_origin_distance", m.max_origin_distance, { "m", "data farther from the origin is an error; features entirely farther are dropped" });
  get("building_layer", m.building_layer, { "", "layer of buildings (\"\": every layer; IGN BD TOPO: BATIMENT)" });
  get("road_layer", m.road_layer, { "", "layer of road centre lines (IGN: TRONCON_DE_ROUTE)" });
  get("road_area_layer", m.road_area_layer, { "", "layer of road surfaces as polygons" });
  get("building_attribute", m.building_attribute, { "", "set and not \"no\": the feature is a building" });
  get("building_height_attribute", m.building_height_attribute, { "", "building height attribute, m (IGN: HAUTEUR)" });
  get("building_levels_attribute", m.building_levels_attribute, { "", "storeys attribute (IGN: NOMBRE_D_ETAGES)" });
  get("road_class_attribute", m.road_class_attribute, { "", "road class attribute (IGN: NATURE)" });
  get("road_width_attribute", m.road_width_attribute, { "", "road width attribute, m (IGN: LARGEUR)" });
  get("road_lanes_attribute", m.road_lanes_attribute, { "", "lanes attribute (IGN: NB_VOIES)" });
  get("road_area_attribute", m.road_area_attribute, { "", "drivable class on a polygon: the polygon is a road surface" });
  get("road_tunnel_attribute", m.road_tunnel_attribute, { "", "set and not \"no\" or \"building_passage\": a tunnel" });
  get("exclude_tunnels", m.exclude_tunnels, { "", "tunnels are underground: not road surface" });
  get("drivable_classes", m.drivable_classes, { "", "road classes that are road surface; [\"*\"]: every class" });
  get("lane_width", m.lane_width, { "m", "width per lane when a road gives its lanes" });
  get("level_height", m.level_height, { "m", "height per storey when a building gives its levels" });
  get("default_road_width", m.default_road_width, { "m", "width of a road whose class has no entry in road_class_widths" });
  get("road_class_widths", m.road_class_widths, { "m", "road width per class (replaces the default table)" });
  get("repair_invalid", m.repair_invalid, { "", "repair invalid polygons (self-intersections) with GEOS" });
  get("max_vertices_per_feature", m.max_vertices_per_feature, { "", "features with more vertices are skipped and counted" });
  get("frame_id", p.frame_id, { "", "frame of the published prior and markers" });
  get("resolution", p.resolution, { "m", "PriorGrid cell side" });
  get("beta_building", p.beta.beta_building, { "", "β_B: confidence in the map's buildings (equation 1)" });
  get("beta_road", p.beta.beta_road, { "", "β_R: confidence in its roads" });
  get("beta_other", p.beta.beta_other, { "", "β_T: confidence in the rest of the map" });
  std::string cell_test = core::toString(p.options.cell_test);
  get("cell_test", cell_test, { "", "coverage (share of each cell covered; outline cells {F, C}) or centre (the paper)" });
  p.options.cell_test = core::parsePriorCellTest(cell_test);
  get("building_accuracy", p.options.building_accuracy, { "m", "positional accuracy of the map's buildings, softens the prior; 0: exact" });
  get("road_accuracy", p.options.road_accuracy, { "m", "positional accuracy of its roads; 0: exact" });
  get("margin", p.margin, { "m", "added around the map's extent" });
  get("publish_size", p.publish_size, { "m", "side of the published square around the publish centre; 0: the map's extent" });
  get("publish_centre_x", p.publish_centre_x, { "m", "x of the published square's centre, map frame" });
  get("publish_centre_y", p.publish_centre_y, { "m", "y of the published square's centre, map frame" });
  get("max_published_cells", p.max_published_cells, { "cells", "a larger published window is cropped around the publish centre (16 bytes per cell)" });
  get("publish_outlines", p.publish_outlines, { "", "publish prior_grid/outlines (MarkerArray)" });
  get("vehicle_frame", p.vehicle_frame, { "", "the vehicle's frame, to warn when it is far from every map feature" });
  get("max_vehicle_distance", p.max_vehicle_distance, { "m", "farther from every feature of the map: WARN (a wrong map or origin); 0: not checked" });
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

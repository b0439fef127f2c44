/**
 * @file vector_map.hpp
 * @brief Map geometry in the metric `map` frame (ENU, metres), as loaded from a geographic map and used
 *        by the PriorGrid rasteriser and by the scenario simulator.
 */
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "map_aided_fusion/core/grid_geometry.hpp"

namespace map_aided_fusion {
namespace core {

/// A closed ring of vertices (the closing vertex is not repeated), in the map frame.
using Ring = std::vector<Point2>;

/// A polygon with holes (courtyards).
struct Polygon
{
  Ring outer;               ///< outer boundary
  std::vector<Ring> holes;  ///< inner boundaries
};

/// A building footprint and what the map says of its height.
struct Building
{
  Polygon footprint;
  double height = 0.0;  ///< metres; 0 when the map does not say (`height`, else `building:levels`)
  std::string id;       ///< source identifier (e.g. "way/123", "relation/45")
};

/// A road centre line (e.g. an OSM `highway=*` way) with the width of its surface.
struct RoadLine
{
  std::vector<Point2> points;
  double width = 0.0;      ///< metres, full width of the carriageway
  std::string road_class;  ///< e.g. "residential"
  std::string id;
};

/// Everything the PriorGrid needs from a map, in the metric `map` frame.
struct VectorMap
{
  std::vector<Building> buildings;
  std::vector<Polygon> road_areas;  ///< road surfaces given as areas (`area:highway`), or buffered centre lines
  std::vector<RoadLine> road_lines; ///< centre lines the road areas were (or can be) built from
  std::size_t skipped_geometries = 0;  ///< broken or incomplete geometries skipped while loading
};

/**
 * @brief Distance (m) from @p p to the nearest data of @p map: the edges of building footprints and road areas
 *        (outer rings and holes) and the segments of road centre lines. Infinity for an empty map.
 */
double distanceToMapData(const VectorMap& map, const Point2& p);

}  // namespace core
}  // namespace map_aided_fusion

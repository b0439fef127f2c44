/**
 * @file map_loader.hpp
 * @brief Reads a geographic map (OpenStreetMap XML/PBF, GeoJSON, Shapefile, GeoPackage) with GDAL/OGR and
 *        projects it with GeographicLib into the local metric `map` frame (ENU, REP-103/105) as a
 *        core::VectorMap: buildings, road areas and road centre lines with their widths.
 *
 * ROS-free: GDAL, GeographicLib and map_aided_fusion_core only (library `map_aided_fusion_map_io`).
 *
 * What is a building, a road area, a road centre line:
 *  - building: a polygon (closed OSM way or multipolygon relation) whose `building_attribute` is set and not
 *    "no"; or any polygon of `building_layer` when that parameter is set. Holes (courtyards) are kept.
 *  - road area: a polygon whose `road_area_attribute` (`area:highway`) is a drivable class (an
 *    `area:highway=footway` pavement is not road), or a polygon with a drivable `road_class_attribute` and
 *    `area=yes`; or any polygon of `road_area_layer`.
 *  - tunnels (`road_tunnel_attribute` set and not "no" or "building_passage") are not road surface when
 *    `exclude_tunnels` is set: they are counted in MapLoadReport::excluded_tunnels, not skipped.
 *  - road centre line: a line whose `road_class_attribute` (`highway`) is one of `drivable_classes`
 *    (or any line of `road_layer`, filtered by class when the class attribute exists and the list is not
 *    {"*"}). Its width: `road_width_attribute` when > 0, else `road_lanes_attribute` × lane_width, else
 *    `road_class_widths[class]`, else default_road_width.
 *  Road areas and centre lines are both kept: the road surface is their union (an `area:highway` polygon and
 *  the centre line inside it do not conflict). Where buildings and roads overlap, the PriorGrid lets the
 *  building win.
 *
 * Broken geometry (rings with fewer than 3 distinct vertices, non-finite coordinates, unclosed building ways,
 * ways whose nodes are missing from an extract, invalid polygons that cannot be repaired) is skipped and
 * counted in MapLoadReport (and VectorMap::skipped_geometries); invalid polygons are repaired with GEOS when
 * `repair_invalid` is set.
 *
 * OpenStreetMap specifics (GDAL's OSM driver): closed ways are read as lines and turned into polygons here, so
 * that ways shortened by missing nodes are recognised (the driver reports them only through CPLDebug, which
 * the loader captures) and skipped; relations the driver ignores because member ways are missing, and ways it
 * drops for having fewer than 2 nodes, are counted by id (whatever their kind: the driver does not say).
 * Known limits of the driver, not detectable here: a multipolygon relation whose rings do not close is
 * dropped without a message, and an untagged member way with a missing node is shortened without one.
 * Coordinates of OSM files have OSM's precision of 1e-7 degree (≤ 1.1 cm).
 */
#pragma once

#include <cstddef>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "map_aided_fusion/core/vector_map.hpp"

namespace map_aided_fusion {
namespace map_io {

/// File format of a map source.
enum class MapSourceKind
{
  kAuto,        ///< from the file name's extension (.osm, .pbf, .geojson/.json, .shp, .gpkg), else GDAL guesses
  kOsm,         ///< OpenStreetMap XML (.osm) or PBF (.osm.pbf)
  kGeoJson,     ///< GeoJSON
  kShapefile,   ///< ESRI Shapefile (a .shp file or a folder of them)
  kGeoPackage,  ///< OGC GeoPackage (e.g. IGN BD TOPO)
};

/// "auto", "osm", "geojson", "shapefile", "gpkg" → MapSourceKind. @throws core::ParameterError("source", …).
MapSourceKind parseMapSourceKind(const std::string& name);
/// MapSourceKind → its name as accepted by parseMapSourceKind().
std::string toString(MapSourceKind kind);

/// Default drivable OSM `highway` classes (motorway … residential, service, living_street and the links).
std::vector<std::string> defaultDrivableClasses();
/// Default full road width per OSM `highway` class, metres.
std::map<std::string, double> defaultRoadClassWidths();

/// Everything loadVectorMap() needs. Defaults suit OpenStreetMap; see config/prior_grid.yaml.
struct MapLoadParams
{
  std::string file;                             ///< path of the map file
  MapSourceKind source = MapSourceKind::kAuto;  ///< file format

  /// Origin of the `map` frame (WGS84). NaN latitude/longitude: the centre of the data's bounding box.
  double origin_latitude = std::numeric_limits<double>::quiet_NaN();   ///< degrees, [-90, 90]
  double origin_longitude = std::numeric_limits<double>::quiet_NaN();  ///< degrees, [-180, 180]
  double origin_altitude = 0.0;  ///< metres above the ellipsoid, [-1000, 10000]
  /// True: coordinates are already metric in the `map` frame (HD maps in local coordinates); no projection.
  bool metric = false;
  /// Data whose nearest vertex is farther than this from the origin is an error; features entirely farther
  /// are dropped and counted (metres, > 0).
  double max_origin_distance = 50000.0;

  // Layers (GeoJSON/Shapefile/GeoPackage). Empty: decide from the attributes below, on every layer.
  std::string building_layer;   ///< e.g. "BATIMENT" (IGN BD TOPO)
  std::string road_layer;       ///< e.g. "TRONCON_DE_ROUTE" (IGN BD TOPO)
  std::string road_area_layer;  ///< layer of road surfaces as polygons

  // Attributes (OSM keys for OSM sources).
  std::string building_attribute = "building";                ///< set and not "no": a building
  std::string building_height_attribute = "height";           ///< metres (IGN: "HAUTEUR")
  std::string building_levels_attribute = "building:levels";  ///< storeys (IGN: "NOMBRE_D_ETAGES")
  std::string road_class_attribute = "highway";               ///< road class (IGN: "NATURE")
  std::string road_width_attribute = "width";                 ///< metres (IGN: "LARGEUR")
  std::string road_lanes_attribute = "lanes";                 ///< lanes (IGN: "NB_VOIES")
  std::string road_area_attribute = "area:highway";           ///< drivable class: the polygon is a road surface
  std::string road_tunnel_attribute = "tunnel";               ///< set and not "no"/"building_passage": a tunnel
  bool exclude_tunnels = true;  ///< tunnels are underground: not road surface of the grid

  /// Road classes that are road surface; {"*"} accepts every class.
  std::vector<std::string> drivable_classes = defaultDrivableClasses();
  double lane_width = 3.5;          ///< metres per lane (> 0)
  double level_height = 3.0;        ///< metres per storey (> 0)
  double default_road_width = 6.0;  ///< metres, for a class missing from road_class_widths (> 0)
  std::map<std::string, double> road_class_widths = defaultRoadClassWidths();  ///< metres (> 0)
  /// Repair invalid polygons (self-intersections…) with GEOS (OGRGeometry::MakeValid); false: keep as read.
  bool repair_invalid = true;
  /// Features with more vertices are skipped and counted (a guard against pathological geometry), [3, 1e8].
  int max_vertices_per_feature = 100000;

  /// @throws core::ParameterError naming the offending parameter.
  void validate() const;
};

/// A map that cannot be loaded: the message names the file and the cause.
class MapLoadError : public std::runtime_error
{
public:
  explicit MapLoadError(const std::string& what) : std::runtime_error(what) {}
};

/// What loadVectorMap() read, kept and skipped.
struct MapLoadReport
{
  std::string file;                        ///< the file read
  std::string driver;                      ///< GDAL driver used
  double origin_latitude = 0.0;            ///< origin actually used (degrees)
  double origin_longitude = 0.0;           ///< origin actually used (degrees)
  double origin_altitude = 0.0;            ///< origin actually used (metres)
  std::size_t features_read = 0;           ///< features examined (all layers)
  std::size_t buildings = 0;               ///< building polygons kept (a multipolygon counts per part)
  std::size_t road_areas = 0;              ///< road area polygons kept
  std::size_t road_lines = 0;              ///< road centre lines kept
  std::size_t repaired_geometries = 0;     ///< invalid polygons repaired
  std::size_t dropped_holes = 0;           ///< holes outside their shell or enclosing it, dropped
  std::size_t excluded_tunnels = 0;        ///< drivable roads left out because they are tunnels
  std::size_t skipped_geometries = 0;      ///< total skipped (the sum of the counts below)
  std::size_t skipped_unclosed = 0;        ///< building/road-area ways that are not closed rings
  std::size_t skipped_missing_nodes = 0;   ///< ways with nodes missing from the extract (OSM: ways of any kind
                                           ///< the reader dropped with < 2 nodes are included)
  std::size_t skipped_incomplete_relations = 0;  ///< OSM relations (any kind) ignored: member ways missing
  std::size_t skipped_degenerate = 0;      ///< fewer than 3 distinct vertices (polygons) or 2 (lines), NaN
  std::size_t skipped_invalid = 0;         ///< invalid polygons not repaired
  std::size_t skipped_out_of_range = 0;    ///< farther than max_origin_distance (or on the far side of the globe)
  std::size_t skipped_too_many_vertices = 0;  ///< more than max_vertices_per_feature vertices
  std::size_t read_errors = 0;             ///< GDAL errors while reading features (truncated file…)
  std::vector<std::string> messages;       ///< the first few skip reasons, with feature ids
};

/**
 * @brief Reads, filters and projects a map into the local `map` frame.
 * @param params validated parameters (validate() is called again here)
 * @param report optional: counts of what was kept and skipped
 * @throws MapLoadError naming the file and the cause: missing/unreadable file, unknown format, no usable
 *         feature, origin farther than max_origin_distance from the data.
 * @throws core::ParameterError on invalid parameters.
 */
core::VectorMap loadVectorMap(const MapLoadParams& params, MapLoadReport* report = nullptr);

/// One feature as a reader hands it to the geometry path, in source coordinates (WGS84 longitude and latitude,
/// or metres in the `map` frame with MapLoadParams::metric).
struct SourceFeature
{
  enum class Kind
  {
    kBuilding,
    kRoadArea,
    kRoadLine,
  };
  Kind kind = Kind::kBuilding;
  std::string id;                                ///< named in the report's messages
  std::vector<std::vector<core::Point2>> parts;  ///< polygon: exterior ring then holes (closed or not); line: parts
  double height = 0.0;                           ///< building height, metres (0: unknown)
  double width = 0.0;                            ///< road width, metres
  std::string road_class;                        ///< road class (informational)
};

/**
 * @brief The geometry path of loadVectorMap() on features given in memory, without a file or a GDAL driver:
 *        coordinate checks, vertex limits, hole and validity repair, projection, origin and range checks.
 *
 * Used by the in-memory fuzz target (fuzz/fuzz_map_geometry.cpp) and by tests; the attribute and layer
 * parameters of @p params are not used (the features carry their kind, height and width).
 * @throws MapLoadError, core::ParameterError as loadVectorMap().
 */
core::VectorMap buildVectorMap(const std::vector<SourceFeature>& features, const MapLoadParams& params,
                               MapLoadReport* report = nullptr);

/// One-paragraph human-readable summary of a report (for logs and the command-line tool).
std::string summary(const MapLoadReport& report);

}  // namespace map_io
}  // namespace map_aided_fusion

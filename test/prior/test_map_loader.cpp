// Map loading (GDAL/OGR + GeographicLib) on hand-made fixtures (test/prior/fixtures), on maps/town.osm and,
// when present, on the real OpenStreetMap extracts in ../shared/data/osm.
#include <gtest/gtest.h>

#include <GeographicLib/LocalCartesian.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <string>

#include "map_aided_fusion/core/parameters.hpp"
#include "map_aided_fusion/core/prior_grid.hpp"
#include "map_aided_fusion/map_io/map_loader.hpp"
#include "map_aided_fusion/map_io/projection.hpp"

namespace {

using namespace map_aided_fusion;
using core::PriorClass;

const std::string kPackage = MAF_PACKAGE_DIR;
const std::string kFixtures = kPackage + "/test/prior/fixtures/";
const std::string kSharedData = MAF_SHARED_DATA_DIR;

constexpr double kFixtureLat = 49.0;
constexpr double kFixtureLon = 2.0;
constexpr double kMillimetre = 1e-3;

core::GridGeometry testGrid()
{
  core::GridGeometry g;
  g.resolution = 1.0;
  g.width = 40;
  g.height = 40;
  g.origin_x = -20.0;
  g.origin_y = -20.0;
  return g;
}

map_io::MapLoadParams fixtureParams(const std::string& file)
{
  map_io::MapLoadParams p;
  p.file = kFixtures + file;
  p.origin_latitude = kFixtureLat;
  p.origin_longitude = kFixtureLon;
  return p;
}

std::size_t count(const core::PriorGrid& g, PriorClass c) { return g.classCounts()[static_cast<std::size_t>(c)]; }

const core::Building* findBuilding(const core::VectorMap& m, const std::string& id)
{
  for (const auto& b : m.buildings)
    if (b.id == id) return &b;
  return nullptr;
}

std::string writeTemp(const std::string& name, const std::string& content)
{
  const std::string path = (std::filesystem::temp_directory_path() / ("maf_test_" + name)).string();
  std::ofstream(path) << content;
  return path;
}

template <class F>
std::string errorOf(F&& f)
{
  try
  {
    f();
  }
  catch (const map_io::MapLoadError& e)
  {
    return e.what();
  }
  return "(no MapLoadError)";
}

TEST(MapLoader, OsmBlocksGiveExactCellsOfEachLabel)
{
  map_io::MapLoadReport report;
  const core::VectorMap m = map_io::loadVectorMap(fixtureParams("blocks.osm"), &report);
  EXPECT_EQ(report.driver, "OSM");
  EXPECT_EQ(m.buildings.size(), 3u);
  ASSERT_EQ(m.road_lines.size(), 1u);  // the footway is not drivable
  EXPECT_DOUBLE_EQ(m.road_lines[0].width, 4.0);  // `width` wins over `lanes`
  EXPECT_EQ(m.road_lines[0].road_class, "residential");
  EXPECT_TRUE(m.road_areas.empty());

  core::PriorGrid grid;
  grid.build(m, testGrid());
  EXPECT_EQ(count(grid, PriorClass::kBuilding), 372u);
  EXPECT_EQ(count(grid, PriorClass::kRoad), 130u);
  EXPECT_EQ(count(grid, PriorClass::kOther), 1098u);
  EXPECT_EQ(grid.labelAt({ -10.5, 10.5 }), PriorClass::kOther);     // courtyard
  EXPECT_EQ(grid.labelAt({ -10.5, -9.5 }), PriorClass::kBuilding);  // building over road
}

TEST(MapLoader, HeightsFromHeightOrLevels)
{
  const core::VectorMap m = map_io::loadVectorMap(fixtureParams("blocks.osm"));
  const core::Building* square = findBuilding(m, "way/1");
  const core::Building* garage = findBuilding(m, "way/2");
  const core::Building* cloister = findBuilding(m, "relation/50");
  ASSERT_NE(square, nullptr);
  ASSERT_NE(garage, nullptr);
  ASSERT_NE(cloister, nullptr);
  EXPECT_DOUBLE_EQ(square->height, 12.5);
  EXPECT_DOUBLE_EQ(garage->height, 2 * 3.0);
  EXPECT_DOUBLE_EQ(cloister->height, 0.0);
  EXPECT_EQ(cloister->footprint.holes.size(), 1u);
}

TEST(MapLoader, WayWithMissingNodeIsSkippedAndCounted)
{
  map_io::MapLoadReport report;
  const core::VectorMap m = map_io::loadVectorMap(fixtureParams("blocks.osm"), &report);
  EXPECT_EQ(findBuilding(m, "way/7"), nullptr);
  EXPECT_EQ(report.skipped_missing_nodes, 1u);
  EXPECT_EQ(report.skipped_geometries, 1u);
  EXPECT_EQ(m.skipped_geometries, 1u);
  ASSERT_FALSE(report.messages.empty());
  EXPECT_NE(report.messages[0].find("way/7"), std::string::npos);
}

TEST(MapLoader, ProjectionMatchesGeographicLibToMillimetres)
{
  const core::VectorMap m = map_io::loadVectorMap(fixtureParams("blocks.osm"));
  const core::Building* square = findBuilding(m, "way/1");
  ASSERT_NE(square, nullptr);
  ASSERT_EQ(square->footprint.outer.size(), 4u);
  // Node 101 of blocks.osm (49.0000179840, 2.0000273329) as GDAL's OSM driver stores it, at OSM's precision of
  // 1e-7 degree, projected directly with GeographicLib.
  const GeographicLib::LocalCartesian lc(kFixtureLat, kFixtureLon, 0.0);
  double x = 0, y = 0, z = 0;
  lc.Forward(49.0000180, 2.0000273, 0.0, x, y, z);
  const core::Point2 p0 = square->footprint.outer[0];
  EXPECT_NEAR(p0.x, x, kMillimetre);
  EXPECT_NEAR(p0.y, y, kMillimetre);
  // And the designed map-frame corners (2, 2) … (12, 12), within OSM's 1e-7 degree (≤ 1.1 cm).
  constexpr double kOsmPrecision = 0.011;
  const double expected[4][2] = { { 2, 2 }, { 12, 2 }, { 12, 12 }, { 2, 12 } };
  for (int i = 0; i < 4; ++i)
  {
    EXPECT_NEAR(square->footprint.outer[i].x, expected[i][0], kOsmPrecision);
    EXPECT_NEAR(square->footprint.outer[i].y, expected[i][1], kOsmPrecision);
  }
  // LocalProjector round trip and a point 1 km north-east.
  const map_io::LocalProjector proj(kFixtureLat, kFixtureLon, 0.0);
  double lat = 0, lon = 0, h = 0;
  lc.Reverse(1000.0, 1000.0, 0.0, lat, lon, h);
  const core::Point2 q = proj.forward(lat, lon);
  EXPECT_NEAR(q.x, 1000.0, kMillimetre);
  EXPECT_NEAR(q.y, 1000.0, kMillimetre);
  double lat2 = 0, lon2 = 0;
  proj.reverse(q, lat2, lon2);
  const core::Point2 q2 = proj.forward(lat2, lon2);
  EXPECT_NEAR(q2.x, q.x, kMillimetre);
  EXPECT_NEAR(q2.y, q.y, kMillimetre);
}

TEST(MapLoader, OriginShiftMovesTheMap)
{
  map_io::MapLoadParams p = fixtureParams("blocks.osm");
  const GeographicLib::LocalCartesian lc(kFixtureLat, kFixtureLon, 0.0);
  double lat = 0, lon = 0, h = 0;
  lc.Reverse(100.0, -50.0, 0.0, lat, lon, h);
  p.origin_latitude = lat;
  p.origin_longitude = lon;
  const core::VectorMap m = map_io::loadVectorMap(p);
  const core::Building* square = findBuilding(m, "way/1");
  ASSERT_NE(square, nullptr);
  EXPECT_NEAR(square->footprint.outer[0].x, 2.0 - 100.0, 0.01);
  EXPECT_NEAR(square->footprint.outer[0].y, 2.0 + 50.0, 0.01);
}

TEST(MapLoader, AutoOriginIsTheCentreOfTheData)
{
  map_io::MapLoadParams p = fixtureParams("blocks.osm");
  p.origin_latitude = std::numeric_limits<double>::quiet_NaN();
  p.origin_longitude = std::numeric_limits<double>::quiet_NaN();
  map_io::MapLoadReport r;
  map_io::loadVectorMap(p, &r);
  // Data (buildings and kept road) spans x ∈ [−20, 20], y ∈ [−11, 18] around (49, 2).
  const GeographicLib::LocalCartesian lc(kFixtureLat, kFixtureLon, 0.0);
  double lat = 0, lon = 0, h = 0;
  lc.Reverse(0.0, 3.5, 0.0, lat, lon, h);
  EXPECT_NEAR(r.origin_latitude, lat, 1e-7);
  EXPECT_NEAR(r.origin_longitude, lon, 1e-7);
}

TEST(MapLoader, MetricGeoJsonWithRepairAndDegenerateRing)
{
  map_io::MapLoadParams p;
  p.file = kFixtures + "blocks_metric.geojson";
  p.metric = true;
  map_io::MapLoadReport report;
  const core::VectorMap m = map_io::loadVectorMap(p, &report);
  EXPECT_EQ(report.driver, "GeoJSON");
  EXPECT_EQ(report.repaired_geometries, 1u);  // the bow-tie
  EXPECT_EQ(report.skipped_geometries, 1u);   // the 2-vertex ring
  ASSERT_EQ(m.road_lines.size(), 1u);
  core::PriorGrid grid;
  grid.build(m, testGrid());
  // Bow-tie (14,2)(18,6)(18,2)(14,6): two triangles of 4 m², 2 + 6 centres by the half-open rule.
  EXPECT_EQ(count(grid, PriorClass::kBuilding), 372u + 8u);
  EXPECT_EQ(count(grid, PriorClass::kRoad), 130u);
  EXPECT_EQ(count(grid, PriorClass::kOther), 1098u - 8u);
}

TEST(MapLoader, LayerAndAttributeNamesAreParameters)
{
  // An IGN-like GeoJSON in WGS84: BATIMENT with HAUTEUR, TRONCON_DE_ROUTE with LARGEUR.
  const GeographicLib::LocalCartesian lc(kFixtureLat, kFixtureLon, 0.0);
  auto ll = [&](double x, double y) {
    double lat = 0, lon = 0, h = 0;
    lc.Reverse(x, y, 0.0, lat, lon, h);
    char buf[64];
    std::snprintf(buf, sizeof buf, "[%.10f, %.10f]", lon, lat);
    return std::string(buf);
  };
  const std::string json =
      R"({"type":"FeatureCollection","features":[)"
      R"({"type":"Feature","properties":{"NATURE":"Indifférenciée","HAUTEUR":7.5},"geometry":{"type":"Polygon","coordinates":[[)" +
      ll(2, 2) + "," + ll(12, 2) + "," + ll(12, 12) + "," + ll(2, 12) + "," + ll(2, 2) +
      R"(]]}},{"type":"Feature","properties":{"NATURE":"Route à 1 chaussée","LARGEUR":4},"geometry":{"type":"LineString","coordinates":[)" +
      ll(-20, -10) + "," + ll(20, -10) + "]}}]}";
  const std::string buildings_path = writeTemp("BATIMENT.geojson", json);
  map_io::MapLoadParams p;
  p.file = buildings_path;
  p.origin_latitude = kFixtureLat;
  p.origin_longitude = kFixtureLon;
  p.building_attribute = "HAUTEUR";
  p.building_height_attribute = "HAUTEUR";
  p.road_class_attribute = "NATURE";
  p.road_width_attribute = "LARGEUR";
  p.drivable_classes = { "Route à 1 chaussée" };
  map_io::MapLoadReport r;
  const core::VectorMap m = map_io::loadVectorMap(p, &r);
  ASSERT_EQ(m.buildings.size(), 1u);
  EXPECT_DOUBLE_EQ(m.buildings[0].height, 7.5);
  // Full double precision in GeoJSON: the corners come back to the millimetre.
  ASSERT_EQ(m.buildings[0].footprint.outer.size(), 4u);
  EXPECT_NEAR(m.buildings[0].footprint.outer[0].x, 2.0, kMillimetre);
  EXPECT_NEAR(m.buildings[0].footprint.outer[0].y, 2.0, kMillimetre);
  EXPECT_NEAR(m.buildings[0].footprint.outer[2].x, 12.0, kMillimetre);
  EXPECT_NEAR(m.buildings[0].footprint.outer[2].y, 12.0, kMillimetre);
  ASSERT_EQ(m.road_lines.size(), 1u);
  EXPECT_DOUBLE_EQ(m.road_lines[0].width, 4.0);
  core::PriorGrid grid;
  grid.build(m, testGrid());
  EXPECT_EQ(count(grid, PriorClass::kBuilding), 100u);
  EXPECT_EQ(count(grid, PriorClass::kRoad), 160u);
  std::filesystem::remove(buildings_path);
}

TEST(MapLoader, WidthFromLanesThenClassDefault)
{
  const std::string osm = R"(<?xml version="1.0"?><osm version="0.6">
  <node id="1" lat="49.0" lon="2.0"/><node id="2" lat="49.0" lon="2.001"/>
  <way id="10"><nd ref="1"/><nd ref="2"/><tag k="highway" v="primary"/><tag k="lanes" v="3"/></way>
  <way id="11"><nd ref="1"/><nd ref="2"/><tag k="highway" v="service"/></way>
  <way id="12"><nd ref="1"/><nd ref="2"/><tag k="highway" v="motorway"/><tag k="width" v="24 ft"/></way>
  <way id="13"><nd ref="1"/><nd ref="2"/><tag k="highway" v="cycleway"/></way>
  <way id="14"><nd ref="1"/><nd ref="2"/><tag k="highway" v="service"/><tag k="width" v="wide"/></way>
</osm>)";
  map_io::MapLoadParams p;
  p.file = writeTemp("widths.osm", osm);
  p.origin_latitude = kFixtureLat;
  p.origin_longitude = kFixtureLon;
  p.lane_width = 3.25;
  const core::VectorMap m = map_io::loadVectorMap(p);
  ASSERT_EQ(m.road_lines.size(), 4u);
  std::map<std::string, double> widths;
  for (const auto& l : m.road_lines) widths[l.id] = l.width;
  EXPECT_DOUBLE_EQ(widths["way/10"], 3 * 3.25);
  EXPECT_DOUBLE_EQ(widths["way/11"], 4.0);
  EXPECT_DOUBLE_EQ(widths["way/12"], 24 * 0.3048);
  EXPECT_DOUBLE_EQ(widths["way/14"], 4.0);  // unparsable width: class default
  std::filesystem::remove(p.file);
}

TEST(MapLoader, BadInputGivesClearErrors)
{
  map_io::MapLoadParams p = fixtureParams("does_not_exist.osm");
  std::string e = errorOf([&] { map_io::loadVectorMap(p); });
  EXPECT_NE(e.find("does_not_exist.osm"), std::string::npos) << e;
  EXPECT_NE(e.find("does not exist"), std::string::npos) << e;

  p.file = writeTemp("garbage.osm", "this is not a map\n\x01\x02");
  e = errorOf([&] { map_io::loadVectorMap(p); });
  EXPECT_NE(e.find(p.file), std::string::npos) << e;
  EXPECT_NE(e.find("cannot be read"), std::string::npos) << e;
  std::filesystem::remove(p.file);

  p.file = writeTemp("footway.osm", R"(<?xml version="1.0"?><osm version="0.6">
  <node id="1" lat="49.0" lon="2.0"/><node id="2" lat="49.0" lon="2.001"/>
  <way id="10"><nd ref="1"/><nd ref="2"/><tag k="highway" v="footway"/></way></osm>)");
  e = errorOf([&] { map_io::loadVectorMap(p); });
  EXPECT_NE(e.find("no usable"), std::string::npos) << e;
  std::filesystem::remove(p.file);

  p = fixtureParams("blocks.osm");
  p.origin_latitude = 50.0;  // ~111 km north
  e = errorOf([&] { map_io::loadVectorMap(p); });
  EXPECT_NE(e.find("blocks.osm"), std::string::npos) << e;
  EXPECT_NE(e.find("max_origin_distance"), std::string::npos) << e;
  EXPECT_NE(e.find("111."), std::string::npos) << e;
}

TEST(MapLoader, ParametersAreValidated)
{
  map_io::MapLoadParams p = fixtureParams("blocks.osm");
  p.lane_width = -1.0;
  try
  {
    p.validate();
    FAIL() << "no ParameterError";
  }
  catch (const core::ParameterError& e)
  {
    EXPECT_EQ(e.parameter(), "lane_width");
  }
  p = fixtureParams("blocks.osm");
  p.origin_latitude = 91.0;
  EXPECT_THROW(p.validate(), core::ParameterError);
  p.origin_latitude = std::numeric_limits<double>::quiet_NaN();  // only one of the two: error
  EXPECT_THROW(p.validate(), core::ParameterError);
  p = fixtureParams("blocks.osm");
  p.road_class_widths["primary"] = 0.0;
  EXPECT_THROW(p.validate(), core::ParameterError);
  p.file.clear();
  EXPECT_THROW(map_io::loadVectorMap(p), core::ParameterError);
  EXPECT_EQ(map_io::parseMapSourceKind("GPKG"), map_io::MapSourceKind::kGeoPackage);
  EXPECT_EQ(map_io::toString(map_io::parseMapSourceKind("shapefile")), "shapefile");
  EXPECT_THROW(map_io::parseMapSourceKind("dxf"), core::ParameterError);
}

TEST(MapLoader, TownMap)
{
  map_io::MapLoadParams p;
  p.file = kPackage + "/maps/town.osm";
  p.origin_latitude = 49.4150;
  p.origin_longitude = 2.8230;
  p.origin_altitude = 40.0;
  map_io::MapLoadReport r;
  const core::VectorMap m = map_io::loadVectorMap(p, &r);
  EXPECT_EQ(m.buildings.size(), 23u);
  EXPECT_EQ(m.road_areas.size(), 1u);
  EXPECT_EQ(m.road_lines.size(), 7u);
  EXPECT_EQ(r.skipped_geometries, 0u);
  const core::Building* cloister = findBuilding(m, "relation/1154");
  ASSERT_NE(cloister, nullptr);
  EXPECT_EQ(cloister->footprint.holes.size(), 1u);
  EXPECT_DOUBLE_EQ(cloister->height, 15.0);

  const core::PriorGrid grid = core::PriorGrid::fromVectorMap(m, 0.5);
  EXPECT_EQ(grid.labelAt({ 40, 40 }), PriorClass::kOther);     // courtyard
  EXPECT_EQ(grid.labelAt({ 40, 15 }), PriorClass::kBuilding);  // cloister
  EXPECT_EQ(grid.labelAt({ 8.5, 8.5 }), PriorClass::kRoad);    // Market Junction area, outside both roads
  EXPECT_EQ(grid.labelAt({ -80, 50 }), PriorClass::kRoad);     // West Avenue
  EXPECT_EQ(grid.labelAt({ -90, 120 }), PriorClass::kOther);   // footway: not a road
  EXPECT_EQ(grid.labelAt({ -74, 20 }), PriorClass::kOther);    // pavement between West Avenue and a building
  EXPECT_EQ(grid.labelAt({ 118, -118 }), PriorClass::kBuilding);  // rotated house
}

// ---- Real OpenStreetMap extracts (../shared/data/osm) -------------------------------------------

void checkRealExtract(const std::string& name, std::size_t min_buildings, double resolution)
{
  const std::string path = kSharedData + "/osm/" + name;
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "SKIPPED: real data " << path << " is absent";
  map_io::MapLoadParams p;
  p.file = path;  // origin: the centre of the data
  map_io::MapLoadReport r;
  const core::VectorMap m = map_io::loadVectorMap(p, &r);
  std::cout << "[ REAL     ] " << map_io::summary(r) << std::endl;
  EXPECT_GE(m.buildings.size(), min_buildings);
  EXPECT_GT(m.road_lines.size(), 500u);
  EXPECT_EQ(m.skipped_geometries, r.skipped_geometries);
  EXPECT_EQ(r.messages.empty(), r.skipped_geometries == 0);  // every skip is explained
  core::PriorBuildStats stats;
  const core::PriorGrid grid = core::PriorGrid::fromVectorMap(m, resolution, 0.0, &stats);
  std::cout << "[ REAL     ] " << grid.geometry().width << " x " << grid.geometry().height << " cells, "
            << stats.buildings_rasterised << " buildings rasterised, " << stats.buildings_empty
            << " smaller than a cell" << std::endl;
  // None dropped silently: every kept building is either rasterised or counted as covering no cell centre.
  EXPECT_EQ(stats.buildings_rasterised + stats.buildings_empty + stats.skipped_invalid, m.buildings.size());
  EXPECT_GE(static_cast<double>(stats.buildings_rasterised), 0.98 * static_cast<double>(m.buildings.size()));
  const auto n = grid.classCounts();
  EXPECT_GT(n[static_cast<int>(PriorClass::kBuilding)], 0u);
  EXPECT_GT(n[static_cast<int>(PriorClass::kRoad)], 0u);
  EXPECT_EQ(n[static_cast<int>(PriorClass::kUnknown)], 0u);
}

TEST(MapLoaderRealData, Monaco) { checkRealExtract("monaco.osm.pbf", 20000, 0.5); }
TEST(MapLoaderRealData, Liechtenstein) { checkRealExtract("liechtenstein-2013-08-03.osm.pbf", 3500, 1.0); }
// Liechtenstein spans 11 km × 23 km: 1 m cells keep the test at ~260 MB.

}  // namespace

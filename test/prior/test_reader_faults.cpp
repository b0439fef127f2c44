// Map readers under hostile input (what fuzzing found): pathological polygons, absurd coordinates, data on
// the far side of the globe, stray holes and out-of-range parameters. Each test failed before its fix.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

#include <cpl_vsi.h>

#include "map_aided_fusion/core/parameters.hpp"
#include "map_aided_fusion/core/prior_grid.hpp"
#include "map_aided_fusion/core/rasterizer.hpp"
#include "map_aided_fusion/map_io/map_loader.hpp"
#include "../run_command.hpp"

namespace {

using namespace map_aided_fusion;

std::string writeTemp(const std::string& name, const std::string& content)
{
  const std::string path = (std::filesystem::temp_directory_path() / ("maf_faults_" + name)).string();
  std::ofstream(path) << content;
  return path;
}

std::string featureCollection(const std::string& features, const std::string& crs = "")
{
  return "{\"type\":\"FeatureCollection\"," + crs + "\"features\":[" + features + "]}";
}

std::string building(const std::string& rings)
{
  return "{\"type\":\"Feature\",\"properties\":{\"building\":\"yes\"},\"geometry\":{\"type\":\"Polygon\","
         "\"coordinates\":[" +
         rings + "]}}";
}

long residentKb()
{
  std::ifstream statm("/proc/self/statm");
  long pages = 0, resident = 0;
  statm >> pages >> resident;
  return resident * 4;
}

std::size_t cellsOf(const std::vector<core::CellSpan>& spans)
{
  std::size_t n = 0;
  for (const auto& s : spans) n += static_cast<std::size_t>(s.col_end - s.col_begin);
  return n;
}

/// A comb: N teeth [0.6 k, 0.6 k + 0.3] × [0, H] on a base [0, 0.6 N] × [−1, 0] (4 vertices a tooth).
core::Ring comb(int teeth, double height)
{
  core::Ring r;
  r.push_back({ 0.0, -1.0 });
  r.push_back({ 0.6 * teeth, -1.0 });
  for (int k = teeth - 1; k >= 0; --k)
  {
    const double x0 = 0.6 * k, x1 = x0 + 0.3;
    r.push_back({ x1, 0.0 });
    r.push_back({ x1, height });
    r.push_back({ x0, height });
    r.push_back({ x0, 0.0 });
  }
  return r;
}

TEST(RasteriserFaults, ZigZagOfTenThousandsOfVerticesIsExactInBoundedMemory)
{
  constexpr int kTeeth = 12500;      // 50,002 vertices, as the fuzzer's building
  constexpr double kHeight = 2000.0; // every edge spans 2000 rows: one entry per edge per row was 1.6 GB
  const core::Ring ring = comb(kTeeth, kHeight);
  core::GridGeometry g;
  g.resolution = 1.0;
  g.width = static_cast<int>(0.6 * kTeeth) + 2;
  g.height = static_cast<int>(kHeight) + 2;
  g.origin_x = 0.0;
  g.origin_y = -2.0;
  core::ScanlineRasterizer r(g);
  std::vector<core::CellSpan> spans;
  const long before = residentKb();
  const auto t0 = std::chrono::steady_clock::now();
  r.fill(ring, spans);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const long growth = residentKb() - before;
  // Expected from the definition (cells whose centre is inside; centres at i + 0.5, half-open [a, b)):
  // the base row (centre y −0.5) has every column whose centre is in [0, 0.6 N); each of the rows with centres
  // in (0, H) has the columns whose centre is in a tooth [0.6 k, 0.6 k + 0.3).
  std::size_t tooth_columns = 0;
  for (int k = 0; k < kTeeth; ++k)
    tooth_columns += static_cast<std::size_t>(std::ceil(0.6 * k + 0.3 - 0.5) - std::ceil(0.6 * k - 0.5));
  const std::size_t base = static_cast<std::size_t>(std::ceil(0.6 * kTeeth - 0.5));
  EXPECT_EQ(cellsOf(spans), base + tooth_columns * static_cast<std::size_t>(kHeight));
  std::cout << "zig-zag of " << ring.size() << " vertices: " << spans.size() << " spans in " << seconds
            << " s, resident memory +" << growth << " kB\n";
#ifndef __SANITIZE_ADDRESS__  // AddressSanitizer's quarantine keeps freed memory resident
  EXPECT_LT(growth, 200 * 1024) << "the rasteriser's memory grows with edges x rows";
#endif
}

TEST(MapReaderFaults, HoleOutsideOrAroundItsShellIsDroppedNotMadeABuilding)
{
  const std::string shell = "[[0,0],[10,0],[10,10],[0,10],[0,0]]";
  const std::string outside = "[[20,20],[25,20],[25,25],[20,25],[20,20]]";
  const std::string around = "[[-5,-5],[15,-5],[15,15],[-5,15],[-5,-5]]";
  const std::string inside = "[[4,4],[6,4],[6,6],[4,6],[4,4]]";
  map_io::MapLoadParams p;
  p.metric = true;
  p.file = writeTemp("holes.geojson", featureCollection(building(shell + "," + outside) + "," +
                                                        building(shell + "," + around) + "," +
                                                        building(shell + "," + inside)));
  map_io::MapLoadReport report;
  const core::VectorMap m = map_io::loadVectorMap(p, &report);
  EXPECT_EQ(report.dropped_holes, 2u);
  EXPECT_EQ(report.repaired_geometries, 0u) << "a stray hole was repaired into a second polygon";
  ASSERT_EQ(m.buildings.size(), 3u);
  EXPECT_TRUE(m.buildings[0].footprint.holes.empty());
  EXPECT_TRUE(m.buildings[1].footprint.holes.empty());
  EXPECT_EQ(m.buildings[2].footprint.holes.size(), 1u);  // a genuine courtyard stays
  core::GridGeometry g;
  g.resolution = 1.0;
  g.width = g.height = 40;
  g.origin_x = g.origin_y = -10.0;
  core::PriorGrid grid;
  grid.build(m, g);
  // The shell's 100 cells, nothing outside it (a repaired hole painted 25 or 300 more).
  EXPECT_EQ(grid.classCounts()[static_cast<std::size_t>(core::PriorClass::kBuilding)], 100u);
}

TEST(MapReaderFaults, AbsurdProjectedCoordinatesAreSkippedQuickly)
{
  const std::string crs = "\"crs\":{\"type\":\"name\",\"properties\":{\"name\":\"urn:ogc:def:crs:EPSG::3857\"}},";
  // 2.0 deg E, 49.0 deg N in Web Mercator, and a building at 1e17 m.
  const std::string good = building("[[222639,6274861],[222649,6274861],[222649,6274871],[222639,6274871],"
                                    "[222639,6274861]]");
  const std::string absurd = building("[[1e17,1e17],[1.1e17,1e17],[1.1e17,1.1e17],[1e17,1.1e17],[1e17,1e17]]");
  map_io::MapLoadParams p;
  p.file = writeTemp("absurd.geojson", featureCollection(good + "," + absurd, crs));
  p.origin_latitude = 49.0;
  p.origin_longitude = 2.0;
  map_io::MapLoadReport report;
  const auto t0 = std::chrono::steady_clock::now();
  const core::VectorMap m = map_io::loadVectorMap(p, &report);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 10.0);
  EXPECT_EQ(m.buildings.size(), 1u);
  EXPECT_EQ(report.skipped_degenerate, 1u);
}

TEST(MapReaderFaults, DataOnTheFarSideOfTheGlobeIsNotPlacedNearTheOrigin)
{
  const std::string near = building("[[2.0,49.0],[2.0001,49.0],[2.0001,49.0001],[2.0,49.0001],[2.0,49.0]]");
  // The antipode of (49 N, 2 E) is (49 S, 178 W): on the tangent plane it projects onto the origin.
  const std::string antipode =
      building("[[-178.0,-49.0],[-177.9999,-49.0],[-177.9999,-48.9999],[-178.0,-48.9999],[-178.0,-49.0]]");
  // Across the antimeridian, far away.
  const std::string across = building("[[179.9999,-16.0],[-179.9999,-16.0],[-179.9999,-15.9999],[179.9999,-15.9999],"
                                      "[179.9999,-16.0]]");
  map_io::MapLoadParams p;
  p.file = writeTemp("far.geojson", featureCollection(near + "," + antipode + "," + across));
  p.origin_latitude = 49.0;
  p.origin_longitude = 2.0;
  map_io::MapLoadReport report;
  const core::VectorMap m = map_io::loadVectorMap(p, &report);
  ASSERT_EQ(m.buildings.size(), 1u);
  EXPECT_EQ(report.skipped_out_of_range, 2u);
  for (const auto& q : m.buildings[0].footprint.outer) EXPECT_LT(std::hypot(q.x, q.y), 20.0);

  // Only the antipode: an error that says where the data are, not a building at the origin nor 10^147 km.
  p.file = writeTemp("antipode.geojson", featureCollection(antipode));
  try
  {
    map_io::loadVectorMap(p);
    ADD_FAILURE() << "the antipode was loaded";
  }
  catch (const map_io::MapLoadError& e)
  {
    const std::string what = e.what();
    EXPECT_NE(what.find("other side of the globe"), std::string::npos) << what;
    EXPECT_EQ(what.find("e+"), std::string::npos) << what;
    EXPECT_LT(what.size(), 400u) << what;
  }

  // A map across the antimeridian with an automatic origin: the origin is on the data, not at longitude 0.
  p.file = writeTemp("across.geojson", featureCollection(across));
  p.origin_latitude = p.origin_longitude = std::numeric_limits<double>::quiet_NaN();
  const core::VectorMap a = map_io::loadVectorMap(p, &report);
  ASSERT_EQ(a.buildings.size(), 1u);
  EXPECT_NEAR(std::abs(report.origin_longitude), 180.0, 1e-3);
  for (const auto& q : a.buildings[0].footprint.outer) EXPECT_LT(std::hypot(q.x, q.y), 20.0);
}

TEST(MapReaderFaults, TheInMemoryGeometryPathGivesWhatTheFileGives)
{
  // The path fuzz/fuzz_map_geometry.cpp drives: the same features from memory and from a GeoJSON file give the
  // same projected map, with the same repairs and skips.
  const std::string square = "[[2.0,49.0],[2.0001,49.0],[2.0001,49.0001],[2.0,49.0001],[2.0,49.0]]";
  const std::string bowtie = "[[2.0002,49.0],[2.0003,49.0001],[2.0003,49.0],[2.0002,49.0001],[2.0002,49.0]]";
  const std::string stray_hole = "[[2.0010,49.0010],[2.0011,49.0010],[2.0011,49.0011],[2.0010,49.0011],"
                                 "[2.0010,49.0010]]";
  map_io::MapLoadParams p;
  p.origin_latitude = 49.0;
  p.origin_longitude = 2.0;
  p.file = writeTemp("memory.geojson", featureCollection(building(square + "," + stray_hole) + "," + building(bowtie)));
  map_io::MapLoadReport from_file, from_memory;
  const core::VectorMap a = map_io::loadVectorMap(p, &from_file);
  using map_io::SourceFeature;
  const auto ring = [](std::initializer_list<core::Point2> pts) { return std::vector<core::Point2>(pts); };
  std::vector<SourceFeature> features(2);
  features[0].parts = { ring({ { 2.0, 49.0 }, { 2.0001, 49.0 }, { 2.0001, 49.0001 }, { 2.0, 49.0001 } }),
                        ring({ { 2.0010, 49.0010 }, { 2.0011, 49.0010 }, { 2.0011, 49.0011 }, { 2.0010, 49.0011 } }) };
  features[1].parts = { ring({ { 2.0002, 49.0 }, { 2.0003, 49.0001 }, { 2.0003, 49.0 }, { 2.0002, 49.0001 } }) };
  p.file.clear();
  const core::VectorMap b = map_io::buildVectorMap(features, p, &from_memory);
  ASSERT_EQ(a.buildings.size(), b.buildings.size());
  EXPECT_EQ(from_file.repaired_geometries, 1u);
  EXPECT_EQ(from_memory.repaired_geometries, from_file.repaired_geometries);
  EXPECT_EQ(from_memory.dropped_holes, 1u);
  EXPECT_EQ(from_memory.driver, "memory");
  for (std::size_t i = 0; i < a.buildings.size(); ++i)
  {
    ASSERT_EQ(a.buildings[i].footprint.outer.size(), b.buildings[i].footprint.outer.size()) << i;
    for (std::size_t k = 0; k < a.buildings[i].footprint.outer.size(); ++k)
    {
      EXPECT_NEAR(a.buildings[i].footprint.outer[k].x, b.buildings[i].footprint.outer[k].x, 1e-9);
      EXPECT_NEAR(a.buildings[i].footprint.outer[k].y, b.buildings[i].footprint.outer[k].y, 1e-9);
    }
  }
  // A NaN vertex, a line with one point and nothing usable: counted skips, then the loader's own error.
  std::vector<SourceFeature> bad(2);
  bad[0].parts = { ring({ { 2.0, 49.0 }, { std::nan(""), 49.0 }, { 2.0001, 49.0001 } }) };
  bad[1].kind = SourceFeature::Kind::kRoadLine;
  bad[1].parts = { ring({ { 2.0, 49.0 } }) };
  map_io::MapLoadReport r;
  EXPECT_THROW(map_io::buildVectorMap(bad, p, &r), map_io::MapLoadError);
  EXPECT_EQ(r.skipped_degenerate, 2u) << "the NaN vertex must be caught before GEOS";
}

TEST(MapReaderFaults, FeatureWithTooManyVerticesIsSkippedAndCounted)
{
  std::ostringstream ring;
  ring << "[";
  for (int i = 0; i < 200; ++i)
  {
    const double a = 2.0 * M_PI * i / 200.0;
    ring << "[" << 10.0 * std::cos(a) << "," << 10.0 * std::sin(a) << "],";
  }
  ring << "[10,0]]";
  map_io::MapLoadParams p;
  p.metric = true;
  p.file = writeTemp("many.geojson", featureCollection(building(ring.str()) + "," +
                                                       building("[[20,20],[30,20],[30,30],[20,30],[20,20]]")));
  p.max_vertices_per_feature = 100;
  map_io::MapLoadReport report;
  const core::VectorMap m = map_io::loadVectorMap(p, &report);
  EXPECT_EQ(m.buildings.size(), 1u);
  EXPECT_EQ(report.skipped_too_many_vertices, 1u);
  EXPECT_EQ(report.skipped_geometries, 1u);
  p.max_vertices_per_feature = 1000;
  EXPECT_EQ(map_io::loadVectorMap(p).buildings.size(), 2u);
}

TEST(MapReaderFaults, OriginParametersAreCheckedWithClearNames)
{
  map_io::MapLoadParams p;
  p.file = "any.osm";
  p.origin_latitude = 49.0;
  p.origin_longitude = 2.0;
  p.origin_altitude = 1e7;  // accepted before, and it scaled the map
  try
  {
    p.validate();
    FAIL() << "origin_altitude 1e7 accepted";
  }
  catch (const core::ParameterError& e)
  {
    EXPECT_EQ(e.parameter(), "origin_altitude");
  }
  p.origin_altitude = 0.0;
  p.origin_longitude = std::nan("");
  try
  {
    p.validate();
    FAIL() << "NaN longitude with a latitude accepted";
  }
  catch (const core::ParameterError& e)
  {
    EXPECT_EQ(e.parameter(), "origin_longitude");
    EXPECT_NE(std::string(e.what()).find("is NaN"), std::string::npos) << e.what();
  }
  p.origin_longitude = std::numeric_limits<double>::infinity();
  EXPECT_THROW(p.validate(), core::ParameterError);
  p.origin_longitude = 2.0;
  p.max_vertices_per_feature = 2;
  EXPECT_THROW(p.validate(), core::ParameterError);
}

TEST(MapReaderFaults, GdalVirtualPathsAreReadable)
{
  std::string json = featureCollection(building("[[0,0],[10,0],[10,10],[0,10],[0,0]]"));
  VSIFCloseL(VSIFileFromMemBuffer("/vsimem/maf_test.geojson", reinterpret_cast<GByte*>(&json[0]),
                                  static_cast<vsi_l_offset>(json.size()), FALSE));
  map_io::MapLoadParams p;
  p.metric = true;
  p.file = "/vsimem/maf_test.geojson";
  EXPECT_EQ(map_io::loadVectorMap(p).buildings.size(), 1u);
  VSIUnlink("/vsimem/maf_test.geojson");
  EXPECT_THROW(map_io::loadVectorMap(p), map_io::MapLoadError);
}

TEST(PriorGridToolFaults, NonFiniteNumbersAreBadOptionsNotDisabledLimits)
{
  for (const std::string option : { "--max-cells nan", "--max-cells inf", "--resolution nan", "--size -1" })
  {
    int status = 0;
    const std::string out = maf_test::runCommand(
        std::string(MAF_PRIOR_GRID_TOOL) + " --map " + MAF_PACKAGE_DIR + "/maps/town.osm " + option, &status);
    EXPECT_NE(status, 0) << option << " was accepted:\n" << out;
    EXPECT_NE(out.find("bad or incomplete option '" + option.substr(0, option.find(' ')) + "'"), std::string::npos)
        << option << ":\n"
        << out;
  }
}

}  // namespace

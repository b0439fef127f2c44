// The simulator on maps read by the map loader: the town fixture used by the other simulator tests is the
// town of maps/town.osm; the shipped scenarios run on the loaded town; on the real Monaco extract
// (../shared/data, SKIPPED when absent) the grid-accelerated ray casting equals a brute-force cast over
// every building, and a full 32-beam scan runs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <random>

#include "map_aided_fusion/map_io/map_loader.hpp"
#include "map_aided_fusion/sim/simulator.hpp"
#include "town_fixture.hpp"

using namespace map_aided_fusion;
using namespace map_aided_fusion::sim;

namespace {

const std::string kPackage = MAF_SOURCE_DIR;
const std::string kSharedData = MAF_SHARED_DATA_DIR;

struct Box2
{
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
};

Box2 bounds(const core::Polygon& p)
{
  Box2 b;
  for (const auto& v : p.outer)
  {
    b.x0 = std::min(b.x0, v.x);
    b.y0 = std::min(b.y0, v.y);
    b.x1 = std::max(b.x1, v.x);
    b.y1 = std::max(b.y1, v.y);
  }
  return b;
}

core::VectorMap loadTown()
{
  map_io::MapLoadParams p;
  p.file = kPackage + "/maps/town.osm";
  const Scenario sc = loadScenario(kPackage + "/scenarios/default.yaml");
  p.origin_latitude = sc.map_origin_latitude;
  p.origin_longitude = sc.map_origin_longitude;
  p.origin_altitude = sc.map_origin_altitude;
  return map_io::loadVectorMap(p);
}

}  // namespace

TEST(SimMaps, TownFixtureIsTheTownMap)
{
  const core::VectorMap town = loadTown();
  const core::VectorMap fixture = maf_test::townLikeMap();
  ASSERT_EQ(town.buildings.size(), fixture.buildings.size() + 1);  // + the rotated house
  constexpr double kTol = 0.01;  // m: the OSM file stores 8 decimals of a degree
  std::size_t matched = 0;
  for (const auto& f : fixture.buildings)
  {
    const Box2 a = bounds(f.footprint);
    for (const auto& b : town.buildings)
    {
      const Box2 c = bounds(b.footprint);
      if (std::abs(a.x0 - c.x0) < kTol && std::abs(a.y0 - c.y0) < kTol && std::abs(a.x1 - c.x1) < kTol &&
          std::abs(a.y1 - c.y1) < kTol && b.footprint.outer.size() == f.footprint.outer.size() &&
          b.footprint.holes.size() == f.footprint.holes.size())
      {
        EXPECT_NEAR(b.height, f.height, 1e-9) << b.id;
        ++matched;
        break;
      }
    }
  }
  EXPECT_EQ(matched, fixture.buildings.size());
}

TEST(SimMaps, ScenariosRunOnTheLoadedTown)
{
  const core::VectorMap town = loadTown();
  for (const char* name : { "default.yaml", "dense_traffic.yaml" })
  {
    Simulator sim(loadScenario(kPackage + "/scenarios/" + name), town);
    EXPECT_EQ(sim.summary().mapped_buildings, 22u) << name;
    EXPECT_EQ(sim.summary().absent_buildings, 1u) << name;
    EXPECT_EQ(sim.summary().unmapped_buildings, 1u) << name;
    ScanFrame f;
    sim.scan(150, f);
    EXPECT_GT(f.points.size(), 30000u) << name;
  }
}

TEST(SimMaps, MonacoGridCastEqualsBruteForce)
{
  const std::string path = kSharedData + "/osm/monaco.osm.pbf";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "SKIPPED: real data " << path << " is absent";
  map_io::MapLoadParams p;
  p.file = path;
  const core::VectorMap monaco = map_io::loadVectorMap(p);
  ASSERT_GT(monaco.buildings.size(), 20000u);
  ASSERT_FALSE(monaco.road_lines.empty());
  constexpr double kDefaultHeight = 10.0;
  std::vector<WorldBuilding> world;
  for (const auto& b : monaco.buildings)
  {
    WorldBuilding w;
    w.footprint = b.footprint;
    w.height = b.height > 0.0 ? b.height : kDefaultHeight;
    world.push_back(std::move(w));
  }
  const Scene scene(world);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> az(-3.14159, 3.14159), el(-0.25, 0.25);
  std::uniform_int_distribution<std::size_t> road(0, monaco.road_lines.size() - 1);
  std::size_t compared = 0, building_hits = 0;
  std::vector<Span> spans;
  for (int k = 0; k < 400; ++k)
  {
    const auto& line = monaco.road_lines[road(rng)];
    if (line.points.empty()) continue;
    const Point2 o = line.points[line.points.size() / 2];
    const double oz = 1.9, a = az(rng), e = el(rng), max_range = 100.0;
    const Ray2 ray{ o, std::cos(a), std::sin(a) };
    const double slope = std::tan(e), max_s = max_range * std::cos(e);
    double best = groundHitDistance(oz, slope);
    bool inside = false;
    for (const auto& b : world)
    {
      spans.clear();
      appendSpans(b.footprint, 0.0, b.height, ray, spans);
      for (const Span& sp : spans)
      {
        if (sp.s_in < 0.0 && sp.s_out > 0.0) inside = true;
        if (sp.s_out >= 0.0) best = std::min(best, hitDistance(sp, oz, slope));
      }
    }
    if (inside) continue;  // a road point inside a building footprint (bridges, arcades): not comparable
    const BeamHit h = scene.castRay(o.x, o.y, oz, a, e, max_range);
    ++compared;
    if (best > max_s)
    {
      EXPECT_EQ(h.solid, BeamHit::kNone) << k;
    }
    else
    {
      EXPECT_NEAR(h.s, best, 1e-6) << k;
      if (h.solid >= 0) ++building_hits;
    }
  }
  std::cout << "[ real data ] Monaco: " << world.size() << " buildings, " << compared << " rays compared, "
            << building_hits << " hit a building" << std::endl;
  EXPECT_GT(compared, 300u);
  EXPECT_GT(building_hits, 50u);
}

// The simulator on a small hand-made world: ground-truth codes and unknown cells, lidar points, objects,
// determinism, scenario YAML parsing and its errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "map_aided_fusion/core/parameters.hpp"
#include "map_aided_fusion/sim/simulator.hpp"

using namespace map_aided_fusion;
using namespace map_aided_fusion::sim;

namespace {

core::Building mapBuilding(double x0, double y0, double x1, double y1, double h, const std::string& id)
{
  core::Building b;
  b.footprint.outer = { { x0, y0 }, { x1, y0 }, { x1, y1 }, { x0, y1 } };
  b.height = h;
  b.id = id;
  return b;
}

/// A: mapped (C) east; B: mapped but absent west; D: mapped backstop far west; U: unmapped north (N).
core::VectorMap smallMap()
{
  core::VectorMap m;
  m.buildings.push_back(mapBuilding(10, -5, 15, 5, 10, "way/A"));
  m.buildings.push_back(mapBuilding(-15, -5, -10, 5, 10, "way/B"));
  m.buildings.push_back(mapBuilding(-40, -30, -35, 30, 0, "way/D"));  // no height: default
  return m;
}

ObjectSpec object(std::uint32_t id, const std::string& kind, std::vector<Point2> path, double speed = 0.0)
{
  ObjectSpec o;
  EXPECT_TRUE(objectKindDefaults(kind, o));
  o.id = id;
  o.path = std::move(path);
  o.motion.speed = path.size() > 1 ? speed : speed;
  o.motion.corner_radius = 0.0;
  return o;
}

Scenario smallScenario()
{
  Scenario sc;
  sc.duration = 2.0;
  sc.lidar = LidarParams::fromPreset("vlp32");
  sc.lidar.elevations_deg = { 0.0 };
  sc.lidar.azimuth_resolution_deg = 0.5;
  sc.lidar.fov_deg = 360.0;
  sc.lidar.range_noise_stddev = 0.0;
  sc.lidar.dropout_probability = 0.0;
  sc.lidar.mount_x = 0.0;
  sc.lidar.mount_z = 1.0;
  sc.lidar.max_range = 60.0;
  sc.ego.route = { { 0.0, 0.0 } };
  sc.ego.motion.speed = 0.0;
  WorldBuilding u;
  u.footprint.outer = { { -5, 10 }, { 5, 10 }, { 5, 15 }, { -5, 15 } };
  u.height = 8.0;
  sc.map_errors.unmapped.push_back(u);
  sc.map_errors.absent_at.push_back(Point2{ -12.0, 0.0 });
  sc.objects.push_back(object(1, "car", { { 0.0, -8.0 } }));                     // parked: S
  sc.objects.push_back(object(2, "car", { { -20.0, -20.0 }, { 100.0, -20.0 } }, 10.0));  // driving: V
  sc.objects.push_back(object(3, "pole", { { 8.0, 8.0 } }));                     // N
  return sc;
}

std::int8_t classAt(const ScanFrame& f, double x, double y)
{
  core::CellIndex c;
  if (!f.truth_geometry.worldToCell(core::Point2{ x, y }, c)) return -100;
  return f.truth_classes[f.truth_geometry.index(c)];
}

}  // namespace

TEST(SimSimulator, GroundTruthCodesAndUnknownCells)
{
  Simulator sim(smallScenario(), smallMap());
  EXPECT_EQ(sim.summary().mapped_buildings, 2u);
  EXPECT_EQ(sim.summary().absent_buildings, 1u);
  EXPECT_EQ(sim.summary().unmapped_buildings, 1u);
  ScanFrame f;
  sim.scan(0, f);
  EXPECT_EQ(f.truth_geometry.width, 200);
  EXPECT_EQ(f.truth_geometry.height, 200);
  EXPECT_DOUBLE_EQ(f.truth_geometry.origin_x, -50.0);
  EXPECT_EQ(classAt(f, 10.25, 0.25), 1);   // wall of A, hit cell: C
  EXPECT_EQ(classAt(f, 9.75, 0.25), 0);    // in front of it: F
  EXPECT_EQ(classAt(f, 12.25, 0.25), -1);  // inside A: never reached
  EXPECT_EQ(classAt(f, 20.25, 0.25), -1);  // behind A
  EXPECT_EQ(classAt(f, -12.25, 0.25), 0);  // the absent mapped building B: free ground, seen through
  EXPECT_EQ(classAt(f, -35.25, 0.25), 1);  // backstop D
  EXPECT_EQ(classAt(f, 0.25, 10.25), 2);   // unmapped building: N
  EXPECT_EQ(classAt(f, 0.25, 12.25), -1);
  EXPECT_EQ(classAt(f, 0.25, -7.25), 3);   // parked car: S
  EXPECT_EQ(classAt(f, 7.9, 7.9), 2);      // pole: N
  EXPECT_EQ(classAt(f, -49.75, 49.75), -1);  // no return that way
  // The driving car is V where seen, and only on its footprint.
  int moving = 0;
  for (std::size_t i = 0; i < f.truth_classes.size(); ++i)
    if (f.truth_classes[i] == 4)
    {
      ++moving;
      const auto c = f.truth_geometry.cellCentre(f.truth_geometry.cellOf(i));
      EXPECT_LE(std::abs(c.x + 20.0), 2.25 + 0.5);
      EXPECT_LE(std::abs(c.y + 20.0), 0.9 + 0.5);
    }
  EXPECT_GT(moving, 0);
  // Objects: the three, with their classes, sizes and velocities.
  ASSERT_EQ(f.objects.size(), 3u);
  EXPECT_EQ(f.objects[0].cell_class, core::CellClass::kStopped);
  EXPECT_EQ(f.objects[1].cell_class, core::CellClass::kMoving);
  EXPECT_NEAR(f.objects[1].vx, 10.0, 1e-9);
  EXPECT_NEAR(f.objects[1].z, 0.75, 1e-9);
  EXPECT_EQ(f.objects[2].cell_class, core::CellClass::kInfrastructure);
  EXPECT_NEAR(f.objects[2].length, 0.3, 1e-12);
}

TEST(SimSimulator, RaysWithoutReturnCanCountAsObserved)
{
  Scenario sc = smallScenario();
  sc.ground_truth.include_no_return_rays = true;
  Simulator sim(sc, smallMap());
  ScanFrame f;
  sim.scan(0, f);
  EXPECT_EQ(classAt(f, -35.25, 35.25), 0);   // 49.8 m along a ray without return: within max range (60 m)
  EXPECT_EQ(classAt(f, -49.75, 49.75), -1);  // 70.4 m: beyond
  EXPECT_EQ(classAt(f, 20.25, 0.25), -1);   // still hidden behind A
  EXPECT_EQ(classAt(f, 10.25, 0.25), 1);
}

TEST(SimSimulator, AnObjectNoRayHitIsNotObserved)
{
  // A walker 0.5 m tall at (-25, 0): the level beam (1 m high) passes over it to the backstop D at x = -35.
  Scenario sc = smallScenario();
  ObjectSpec walker = object(4, "pedestrian", { { -25.0, 0.0 }, { -25.0, 30.0 } }, 1.0);
  walker.height = 0.5;
  sc.objects.push_back(walker);
  for (const bool needs_hit : { true, false })
  {
    sc.ground_truth.object_needs_hit = needs_hit;
    Simulator sim(sc, smallMap());
    ScanFrame f;
    sim.scan(0, f);
    EXPECT_EQ(classAt(f, -35.25, 0.25), 1) << "the ray passes over the walker to D";
    EXPECT_EQ(classAt(f, -24.75, 0.25), needs_hit ? -1 : 4) << "the walker's cell";
    EXPECT_EQ(classAt(f, -22.25, 0.25), 0) << "free ground in front of it stays observed";
    EXPECT_EQ(classAt(f, 0.25, -7.25), 3) << "the parked car is hit: observed";
    EXPECT_EQ(classAt(f, 7.9, 7.9), 2) << "the pole is hit: observed";
  }
  // Taller, it is hit and observed.
  sc.objects.back().height = 1.75;
  sc.ground_truth.object_needs_hit = true;
  Simulator sim(sc, smallMap());
  ScanFrame f;
  sim.scan(0, f);
  EXPECT_EQ(classAt(f, -24.75, 0.25), 4);
}

TEST(SimSimulator, PointsAreExactWithoutNoise)
{
  Simulator sim(smallScenario(), smallMap());
  ScanFrame f;
  sim.scan(0, f);
  EXPECT_EQ(f.rays, 720u);
  EXPECT_EQ(f.points.size() + f.no_return, f.rays);
  EXPECT_EQ(f.dropped, 0u);
  // The level ray along +x meets A's wall at x = 10, 1 m high -> z = 0 in the lidar frame.
  const auto it = std::find_if(f.points.begin(), f.points.end(),
                               [](const LidarPoint& p) { return std::abs(p.y) < 1e-6 && p.x > 0.0f; });
  ASSERT_NE(it, f.points.end());
  EXPECT_NEAR(it->x, 10.0, 1e-5);
  EXPECT_NEAR(it->z, 0.0, 1e-6);
  EXPECT_EQ(it->ring, 0);
  EXPECT_FLOAT_EQ(it->intensity, materialIntensity(Material::kBuilding));
  // Along -y: the parked car's side y = -7.1.
  const auto car = std::find_if(f.points.begin(), f.points.end(),
                                [](const LidarPoint& p) { return std::abs(p.x) < 1e-6 && p.y < 0.0f; });
  ASSERT_NE(car, f.points.end());
  EXPECT_NEAR(car->y, -7.1, 1e-5);
}

TEST(SimSimulator, RollingSweepFiresEachAzimuthAtItsOwnTimeAndPose)
{
  Scenario sc = smallScenario();
  sc.ego.route = { { -8.0, 0.0 }, { 8.0, 0.0 } };
  sc.ego.motion.speed = 10.0;
  sc.ego.motion.acceleration = 20.0;
  sc.objects.clear();
  sc.lidar.rolling_sweep = true;
  Simulator sim(sc, smallMap());
  ScanFrame f;
  sim.scan(3, f);
  ASSERT_FALSE(f.points.empty());
  EXPECT_EQ(f.points.front().time, 0.0f);
  for (std::size_t i = 1; i < f.points.size(); ++i) ASSERT_GE(f.points[i].time, f.points[i - 1].time);
  EXPECT_LT(f.points.back().time, static_cast<float>(sim.scanPeriod()));
  // The level ray along +x (firing 360 of 720, half a period in) meets A's wall at x = 10 from where the ego is then.
  const auto it = std::find_if(f.points.begin(), f.points.end(),
                               [](const LidarPoint& p) { return std::abs(p.y) < 1e-6 && p.x > 0.0f; });
  ASSERT_NE(it, f.points.end());
  EXPECT_NEAR(it->time, 0.5 * sim.scanPeriod(), 1e-6);
  const double ego_then = sim.egoPose(f.time + it->time).x;
  EXPECT_NEAR(it->x, 10.0 - ego_then, 1e-4);
  EXPECT_GT(ego_then - f.ego.x, 0.4) << "the ego moved half a period at 10 m/s";
  // Without the rolling sweep every point is taken at the stamp.
  sc.lidar.rolling_sweep = false;
  Simulator still(sc, smallMap());
  still.scan(3, f);
  for (const LidarPoint& p : f.points) ASSERT_EQ(p.time, 0.0f);
}

TEST(SimSimulator, TerrainReturnsLieOnTheSurfaceSeenFromThePitchingBody)
{
  Scenario sc = smallScenario();
  sc.lidar.elevations_deg = { -12.0, -8.0 };
  sc.objects.clear();
  sc.terrain.grade = 0.05;
  sc.terrain.grade_length = 100.0;
  sc.terrain.camber = 0.02;
  sc.terrain.pitch_amplitude_deg = 1.0;
  sc.terrain.pitch_period = 2.0;
  Simulator sim(sc, smallMap());
  ScanFrame f;
  sim.scan(5, f);
  double pitch = 0.0, roll = 0.0;
  sim.bodyAttitude(f.time, pitch, roll);
  EXPECT_NE(pitch, 0.0);
  const double lidar_h = sim.terrainHeight(f.lidar.x, f.lidar.y);
  std::size_t ground = 0;
  double worst = 0.0, spread_lo = 1e9, spread_hi = -1e9;
  for (const LidarPoint& p : f.points)
  {
    if (p.intensity != materialIntensity(Material::kGround)) continue;
    // Body → level frame: roll about x, then pitch about y.
    const double y1 = std::cos(roll) * p.y - std::sin(roll) * p.z, z1 = std::sin(roll) * p.y + std::cos(roll) * p.z;
    const double vx = std::cos(pitch) * p.x + std::sin(pitch) * z1, vz = -std::sin(pitch) * p.x + std::cos(pitch) * z1;
    const double c = std::cos(f.lidar.yaw), s = std::sin(f.lidar.yaw);
    const double wx = f.lidar.x + c * vx - s * y1, wy = f.lidar.y + s * vx + c * y1;
    const double wz = lidar_h + sc.lidar.mount_z + vz;
    worst = std::max(worst, std::abs(wz - sim.terrainHeight(wx, wy)));
    spread_lo = std::min(spread_lo, static_cast<double>(p.z));
    spread_hi = std::max(spread_hi, static_cast<double>(p.z));
    ++ground;
  }
  ASSERT_GT(ground, 500u);
  EXPECT_LT(worst, 1e-4);
  // Seen from the body the ground is not at one height (on flat ground every ground return has z = -mount_z).
  EXPECT_GT(spread_hi - spread_lo, 0.1);
  // The terrain: hills along x and a crown on the route (here a single point).
  EXPECT_NEAR(sim.terrainHeight(25.0, 0.0), 0.05 * 100.0 / (2.0 * 3.14159265358979323846) - 0.02 * 7.0, 1e-9);
  EXPECT_NEAR(sim.terrainHeight(0.0, 3.0), -0.06, 1e-9);
}

TEST(SimSimulator, ObjectsMoveAndStopInScans)
{
  Scenario sc = smallScenario();
  sc.objects[1].motion.acceleration = 5.0;
  sc.objects[1].motion.stops = { Stop{ 5.0, 100.0 } };  // brakes from 10 m/s over 10 m: stops at 5 m
  Simulator sim(sc, smallMap());
  std::vector<WorldObject> solids;
  std::vector<ObjectTruth> truth;
  sim.objectsAt(0.5, solids, truth);
  // Braking at once (10 m needed, 5 available -> harder braking: 10 m/s², at rest after 1 s).
  EXPECT_EQ(truth[1].cell_class, core::CellClass::kMoving);
  sim.objectsAt(1.5, solids, truth);
  EXPECT_EQ(truth[1].cell_class, core::CellClass::kStopped);
  EXPECT_NEAR(truth[1].x, -15.0, 1e-9);
  EXPECT_EQ(sim.numScans(), 20);
  EXPECT_DOUBLE_EQ(sim.scanTime(15), 1.5);
  ScanFrame f;
  sim.scan(15, f);
  // The ray to the stopped car's north-east corner hits its face y = -19.1 at x ≈ -12.97: that cell is S.
  EXPECT_EQ(classAt(f, -12.9, -19.2), 3);
  sim.scan(0, f);  // at t = 0 the same car, 5 m further west, is moving
  EXPECT_EQ(classAt(f, -17.9, -19.2), 4);
}

TEST(SimSimulator, DeterministicForASeed)
{
  Scenario sc = smallScenario();
  sc.lidar.range_noise_stddev = 0.05;
  sc.lidar.dropout_probability = 0.1;
  sc.seed = 17;
  Simulator a(sc, smallMap()), b(sc, smallMap());
  ScanFrame fa, fb, fa2;
  a.scan(3, fa);
  a.scan(4, fa2);
  b.scan(3, fb);
  ASSERT_EQ(fa.points.size(), fb.points.size());
  for (std::size_t i = 0; i < fa.points.size(); ++i)
  {
    EXPECT_EQ(fa.points[i].x, fb.points[i].x);
    EXPECT_EQ(fa.points[i].ring, fb.points[i].ring);
  }
  EXPECT_EQ(fa.truth_classes, fb.truth_classes);
  EXPECT_GT(fa.dropped, 0u);
  a.scan(3, fa2);  // scan 3 again, after scan 4: the same
  ASSERT_EQ(fa2.points.size(), fa.points.size());
  EXPECT_EQ(fa2.points.back().y, fa.points.back().y);
  sc.seed = 18;
  Simulator c(sc, smallMap());
  ScanFrame fc;
  c.scan(3, fc);
  bool differs = fc.points.size() != fa.points.size();
  for (std::size_t i = 0; !differs && i < fc.points.size(); ++i) differs = fc.points[i].x != fa.points[i].x;
  EXPECT_TRUE(differs);
}

TEST(SimSimulator, MapErrorNamingNoBuildingIsAnError)
{
  Scenario sc = smallScenario();
  sc.map_errors.absent_at = { Point2{ 100.0, 100.0 } };
  try
  {
    Simulator sim(sc, smallMap());
    FAIL();
  }
  catch (const core::ParameterError& e)
  {
    EXPECT_EQ(e.parameter(), "map_errors.absent_buildings");
  }
}

TEST(SimScenario, ParsesYaml)
{
  const std::string text = R"(
name: test
map: ../maps/town.osm
map_origin: [49.415, 2.823, 40]
duration: 12.5
seed: 99
lidar: {preset: ibeo4, dropout_probability: 0.0}
ground_truth: {size_x: 40, size_y: 30, resolution: 0.25, object_needs_hit: false}
ego:
  route: [[0, 0], [50, 0]]
  speed: 8
  stops: [{at: [20, 1], duration: 2}]
map_errors:
  unmapped_buildings: [{name: kiosk, footprint: [[0, 5], [4, 5], [4, 8]], height: 3}]
  absent_buildings: [{at: [1, 2]}, {id: way/7}]
objects:
  - {kind: bus, path: [[0, 0], [0, 100]], speed: 9, stops: [{s: 40, duration: forever}], end: vanish}
  - {id: 7, kind: tree, at: [3, 4], radius: 0.6}
  - {kind: pedestrian, path: [[0, 6], [30, 6]], speed: 1.4, class: V}
)";
  const Scenario sc = parseScenario(text, "/pkg/scenarios");
  EXPECT_EQ(sc.name, "test");
  EXPECT_EQ(sc.map_file, "/pkg/scenarios/../maps/town.osm");
  EXPECT_DOUBLE_EQ(sc.duration, 12.5);
  EXPECT_DOUBLE_EQ(sc.map_origin_latitude, 49.415);
  EXPECT_DOUBLE_EQ(sc.map_origin_longitude, 2.823);
  EXPECT_DOUBLE_EQ(sc.map_origin_altitude, 40.0);
  EXPECT_EQ(sc.seed, 99u);
  EXPECT_EQ(sc.lidar.preset, "ibeo4");
  EXPECT_EQ(sc.lidar.numBeams(), 4);
  EXPECT_EQ(sc.lidar.numAzimuths(), 221);
  EXPECT_DOUBLE_EQ(sc.lidar.dropout_probability, 0.0);
  EXPECT_DOUBLE_EQ(sc.ground_truth.resolution, 0.25);
  EXPECT_FALSE(sc.ground_truth.object_needs_hit);
  ASSERT_EQ(sc.ego.motion.stops.size(), 1u);
  EXPECT_NEAR(sc.ego.motion.stops[0].s, 20.0, 1e-9);
  ASSERT_EQ(sc.map_errors.unmapped.size(), 1u);
  EXPECT_EQ(sc.map_errors.unmapped[0].id, "kiosk");
  EXPECT_EQ(sc.map_errors.absent_ids, std::vector<std::string>{ "way/7" });
  ASSERT_EQ(sc.objects.size(), 3u);
  EXPECT_EQ(sc.objects[0].id, 1u);
  EXPECT_EQ(sc.objects[0].kind, "bus");
  EXPECT_DOUBLE_EQ(sc.objects[0].length, 12.0);
  EXPECT_TRUE(std::isinf(sc.objects[0].motion.stops[0].duration));
  EXPECT_EQ(sc.objects[0].motion.end, PathEnd::kVanish);
  EXPECT_EQ(sc.objects[1].id, 7u);
  EXPECT_EQ(sc.objects[1].shape, WorldObject::Shape::kCylinder);
  EXPECT_DOUBLE_EQ(sc.objects[1].radius, 0.6);
  EXPECT_FALSE(sc.objects[1].movable);
  EXPECT_EQ(sc.objects[2].id, 8u);
  EXPECT_EQ(sc.objects[2].forced_class, core::CellClass::kMoving);
}

namespace {

/// The parameter a scenario text is refused for ("no error" when it loads).
std::string keyOf(const std::string& text)
{
  try
  {
    parseScenario(text, "");
  }
  catch (const core::ParameterError& e)
  {
    return e.parameter();
  }
  return "no error";
}

}  // namespace

TEST(SimScenario, ErrorsNameTheKey)
{
  const std::string ego = "ego: {route: [[0, 0]], speed: 0}\n";
  EXPECT_EQ(keyOf(ego + "lidar: {preset: vlp32, max_range: -1}"), "lidar.max_range");
  EXPECT_EQ(keyOf(ego + "lidar: {preset: velodyne}"), "lidar.preset");
  EXPECT_EQ(keyOf(ego + "terrain: {grade: 0.5}"), "terrain.grade");
  EXPECT_EQ(keyOf(ego + "terrain: {pitch_period: 0}"), "terrain.pitch_period");
  EXPECT_EQ(keyOf(ego + "lidar: {preset: vlp32, rolling_sweep: maybe}"), "lidar.rolling_sweep");
  EXPECT_EQ(keyOf(ego + "objects: [{kind: dragon, at: [0, 0]}]"), "objects[0].kind");
  EXPECT_EQ(keyOf(ego + "objects: [{kind: car, path: [[0, 0], [1]]}]"), "objects[0].path[1]");
  EXPECT_EQ(keyOf(ego + "duration: abc"), "duration");
  EXPECT_EQ(keyOf("duration: 3"), "ego");
  EXPECT_EQ(keyOf("[unclosed"), "yaml");
  EXPECT_EQ(keyOf(ego + "ground_truth: {resolution: 0}"), "ground_truth.resolution");
  EXPECT_EQ(keyOf(ego + "objects: [{kind: car, at: [0, 0]}, {id: 1, kind: car, at: [5, 0]}]"), "objects[id 1].id");
  EXPECT_EQ(keyOf(ego + "map_origin: [91, 0]"), "map_origin");
  EXPECT_EQ(keyOf(ego), "no error");
}

TEST(SimScenario, UnknownKeysAreErrorsNamingThem)
{
  const std::string ego = "ego: {route: [[0, 0]], speed: 0}\n";
  EXPECT_EQ(keyOf(ego + "speeed: 3"), "speeed");
  EXPECT_EQ(keyOf("ego: {route: [[0, 0]], sped: 2}"), "ego.sped");
  EXPECT_EQ(keyOf("ego: {route: [[0, 0], [9, 0]], stops: [{at: [1, 0], duraton: 2}]}"), "ego.stops[0].duraton");
  EXPECT_EQ(keyOf(ego + "lidar: {preset: vlp32, max_rnge: 50}"), "lidar.max_rnge");
  EXPECT_EQ(keyOf(ego + "objects: [{kind: car, at: [0, 0], colour: red}]"), "objects[0].colour");
  EXPECT_EQ(keyOf(ego + "map_errors: {shift: [0, 0], rotation: 1}"), "map_errors.rotation");
  EXPECT_EQ(keyOf(ego + "map_errors: {absent_buildings: [{at: [0, 0], why: gone}]}"), "map_errors.absent_buildings[0].why");
  EXPECT_EQ(keyOf(ego + "localisation_error: {bais: [0, 0]}"), "localisation_error.bais");
  EXPECT_EQ(keyOf(ego + "terrain: {grad: 0.01}"), "terrain.grad");
  EXPECT_EQ(keyOf(ego + "ground_truth: {size: 10}"), "ground_truth.size");
  EXPECT_EQ(keyOf(ego + "scene: {cells: 1}"), "scene.cells");
}

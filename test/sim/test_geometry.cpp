// Exact ray hits on boxes, cylinders, extruded polygons and the ground, computed by hand; occlusion; the
// acceleration grid against a brute-force cast.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "map_aided_fusion/sim/scene.hpp"

using namespace map_aided_fusion;
using namespace map_aided_fusion::sim;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kTol = 1e-9;

core::Polygon rect(double x0, double y0, double x1, double y1)
{
  core::Polygon p;
  p.outer = { { x0, y0 }, { x1, y0 }, { x1, y1 }, { x0, y1 } };
  return p;
}

WorldObject box(double cx, double cy, double yaw, double l, double w, double z0, double z1,
                core::CellClass c = core::CellClass::kStopped)
{
  WorldObject o;
  o.shape = WorldObject::Shape::kBox;
  o.box = OrientedBox{ cx, cy, yaw, l, w, z0, z1 };
  o.cell_class = c;
  o.material = Material::kVehicle;
  return o;
}

WorldObject cylinder(double cx, double cy, double r, double z0, double z1)
{
  WorldObject o;
  o.shape = WorldObject::Shape::kCylinder;
  o.cylinder = Cylinder{ cx, cy, r, z0, z1 };
  o.cell_class = core::CellClass::kInfrastructure;
  return o;
}

WorldBuilding building(core::Polygon p, double h)
{
  WorldBuilding b;
  b.footprint = std::move(p);
  b.height = h;
  return b;
}

}  // namespace

TEST(SimGeometry, GroundHitByHand)
{
  Scene scene({});
  // From 2 m high, 10 deg down: s = 2 / tan(10 deg), range = 2 / sin(10 deg).
  const double e = -10.0 * kPi / 180.0;
  const BeamHit h = scene.castRay(0.0, 0.0, 2.0, 0.3, e, 100.0);
  EXPECT_EQ(h.solid, BeamHit::kGround);
  EXPECT_NEAR(h.s, 2.0 / std::tan(10.0 * kPi / 180.0), kTol);
  EXPECT_NEAR(h.s / std::cos(e), 2.0 / std::sin(10.0 * kPi / 180.0), kTol);
  // Level and rising rays never meet the ground; a ground hit beyond max range is no return.
  EXPECT_EQ(scene.castRay(0.0, 0.0, 2.0, 0.0, 0.0, 100.0).solid, BeamHit::kNone);
  EXPECT_EQ(scene.castRay(0.0, 0.0, 2.0, 0.0, e, 11.0).solid, BeamHit::kNone);
}

TEST(SimGeometry, BoxSideTopAndMiss)
{
  Scene scene({});
  scene.setObjects({ box(10.0, 0.0, 0.0, 2.0, 2.0, 0.0, 1.5) });
  // Level ray at 1 m: the face x = 9.
  BeamHit h = scene.castRay(0.0, 0.0, 1.0, 0.0, 0.0, 100.0);
  EXPECT_EQ(h.solid, Scene::kObjectBase);
  EXPECT_NEAR(h.s, 9.0, kTol);
  // From 3 m, slope -0.15: z(9) = 1.65 > 1.5, the top z = 1.5 is met at s = 10 (inside [9, 11]).
  const double e = std::atan(-0.15);
  h = scene.castRay(0.0, 0.0, 3.0, 0.0, e, 100.0);
  EXPECT_EQ(h.solid, Scene::kObjectBase);
  EXPECT_NEAR(h.s, 10.0, kTol);
  EXPECT_NEAR(h.s / std::cos(e), 10.0 * std::sqrt(1.0 + 0.15 * 0.15), kTol);
  // From 3 m, slope -0.05: z(11) = 2.45, over the box; ground at s = 60.
  h = scene.castRay(0.0, 0.0, 3.0, 0.0, std::atan(-0.05), 100.0);
  EXPECT_EQ(h.solid, BeamHit::kGround);
  EXPECT_NEAR(h.s, 60.0, kTol);
  // Beside the box (y = 1.01 > half width 1): no hit.
  EXPECT_EQ(scene.castRay(0.0, 1.01, 1.0, 0.0, 0.0, 100.0).solid, BeamHit::kNone);
}

TEST(SimGeometry, RotatedBoxCorner)
{
  Scene scene({});
  scene.setObjects({ box(10.0, 0.0, kPi / 4.0, 2.0, 2.0, 0.0, 2.0) });
  // A 2 m square turned 45 deg shows its corner at x = 10 - sqrt(2).
  const BeamHit h = scene.castRay(0.0, 0.0, 1.0, 0.0, 0.0, 100.0);
  EXPECT_NEAR(h.s, 10.0 - std::sqrt(2.0), kTol);
  // Along y = 0.5 the face x + y = 10 - sqrt 2 ... entered at x = 10 - sqrt(2) + 0.5.
  const BeamHit h2 = scene.castRay(0.0, 0.5, 1.0, 0.0, 0.0, 100.0);
  EXPECT_NEAR(h2.s, 10.0 - std::sqrt(2.0) + 0.5, kTol);
}

TEST(SimGeometry, CylinderAndUnderside)
{
  Scene scene({});
  scene.setObjects({ cylinder(10.0, 0.0, 1.0, 0.0, 3.0) });
  EXPECT_NEAR(scene.castRay(0.0, 0.0, 1.0, 0.0, 0.0, 100.0).s, 9.0, kTol);
  // Off-centre by 0.6: chord half-length 0.8, entry at x = 9.2.
  EXPECT_NEAR(scene.castRay(0.0, 0.6, 1.0, 0.0, 0.0, 100.0).s, 9.2, kTol);
  // A canopy-like cylinder over [2, 5]: a rising ray from z 1 with slope 0.1 meets z = 2 at s = 10.
  scene.setObjects({ cylinder(10.0, 0.0, 1.0, 2.0, 5.0) });
  const BeamHit h = scene.castRay(0.0, 0.0, 1.0, 0.0, std::atan(0.1), 100.0);
  EXPECT_NEAR(h.s, 10.0, kTol);
}

TEST(SimGeometry, ExtrudedPolygonWithCourtyard)
{
  core::Polygon p = rect(20.0, -10.0, 40.0, 10.0);
  p.holes.push_back({ { 25.0, -5.0 }, { 35.0, -5.0 }, { 35.0, 5.0 }, { 25.0, 5.0 } });
  Scene scene({ building(p, 10.0) });
  // Outer wall at x = 20.
  BeamHit h = scene.castRay(0.0, 0.0, 1.0, 0.0, 0.0, 100.0);
  EXPECT_EQ(h.solid, 0);
  EXPECT_NEAR(h.s, 20.0, kTol);
  // From inside the courtyard, the courtyard wall x = 35 at 5 m.
  EXPECT_NEAR(scene.castRay(30.0, 0.0, 1.0, 0.0, 0.0, 100.0).s, 5.0, kTol);
  // Over the roof from 12 m at slope -0.2: z(20) = 8 < 10: wall at 20. Slope -0.05: z(20) = 11 > 10,
  // roof met at s = 40, i.e. past the outer ring [20, 25] -> the second span [35, 40]: z(35) = 10.25,
  // z(40) = 10: roof at s = 40.
  EXPECT_NEAR(scene.castRay(0.0, 0.0, 12.0, 0.0, std::atan(-0.2), 100.0).s, 20.0, kTol);
  h = scene.castRay(0.0, 0.0, 12.0, 0.0, std::atan(-0.05), 100.0);
  EXPECT_EQ(h.solid, 0);
  EXPECT_NEAR(h.s, 40.0, kTol);
}

TEST(SimGeometry, RayThroughAVertexIsCountedOnce)
{
  // A triangle whose apex (20, 0) points at the sensor: the line y = 0 enters at the apex, leaves at x = 30.
  core::Polygon t;
  t.outer = { { 20.0, 0.0 }, { 30.0, -5.0 }, { 30.0, 5.0 } };
  std::vector<Span> spans;
  ASSERT_EQ(appendSpans(t, 0.0, 4.0, Ray2{ core::Point2{ 0.0, 0.0 }, 1.0, 0.0 }, spans), 1u);
  EXPECT_NEAR(spans[0].s_in, 20.0, kTol);
  EXPECT_NEAR(spans[0].s_out, 30.0, kTol);
  Scene scene({ building(t, 4.0) });
  EXPECT_NEAR(scene.castRay(0.0, 0.0, 1.0, 0.0, 0.0, 100.0).s, 20.0, kTol);
}

TEST(SimGeometry, ConcavePolygon)
{
  // An L: the notch (x in [10, 20], y in [5, 10]) is empty.
  core::Polygon l;
  l.outer = { { 10, -10 }, { 20, -10 }, { 20, 5 }, { 15, 5 }, { 15, 10 }, { 10, 10 } };
  Scene scene({ building(l, 5.0) });
  EXPECT_NEAR(scene.castRay(0.0, 7.0, 1.0, 0.0, 0.0, 100.0).s, 10.0, kTol);
  // From inside the notch looking +x: nothing.
  EXPECT_EQ(scene.castRay(16.0, 7.0, 1.0, 0.0, 0.0, 100.0).solid, BeamHit::kNone);
  // From the notch looking -y: the wall y = 5 at 2 m.
  EXPECT_NEAR(scene.castRay(17.0, 7.0, 1.0, -kPi / 2.0, 0.0, 100.0).s, 2.0, kTol);
}

TEST(SimGeometry, OcclusionNearestWinsAndLowObjectsAreOverflown)
{
  Scene scene({ building(rect(30.0, -5.0, 35.0, 5.0), 10.0) });
  scene.setObjects({ box(10.0, 0.0, 0.0, 2.0, 2.0, 0.0, 1.0), box(20.0, 0.0, 0.0, 2.0, 2.0, 0.0, 3.0) });
  const double slopes[3] = { 0.0, 0.1, 0.5 };
  const double max_s[3] = { 100.0, 100.0, 100.0 };
  BeamHit hits[3];
  scene.castFan(0.0, 0.0, 0.5, 0.0, slopes, max_s, 3, hits);
  // Level beam at 0.5 m: first box at 9. Slope 0.1: z(9) = 1.4 > 1, z(19) = 2.4 < 3: second box at 19.
  // Slope 0.5: z(19) = 10 > 3, z(29) = 15 > 10: nothing.
  EXPECT_EQ(hits[0].solid, Scene::kObjectBase + 0);
  EXPECT_NEAR(hits[0].s, 9.0, kTol);
  EXPECT_EQ(hits[1].solid, Scene::kObjectBase + 1);
  EXPECT_NEAR(hits[1].s, 19.0, kTol);
  EXPECT_EQ(hits[2].solid, BeamHit::kNone);
  // Without the objects, the level beam reaches the building.
  scene.setObjects({});
  scene.castFan(0.0, 0.0, 0.5, 0.0, slopes, max_s, 3, hits);
  EXPECT_EQ(hits[0].solid, 0);
  EXPECT_NEAR(hits[0].s, 30.0, kTol);
}

TEST(SimGeometry, GridCastMatchesBruteForce)
{
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> pos(-150.0, 150.0), size(2.0, 25.0), height(3.0, 25.0);
  std::vector<WorldBuilding> bs;
  for (int i = 0; i < 120; ++i)
  {
    const double x = pos(rng), y = pos(rng);
    bs.push_back(building(rect(x, y, x + size(rng), y + size(rng)), height(rng)));
  }
  std::vector<WorldObject> objs;
  std::uniform_real_distribution<double> yaw(-kPi, kPi);
  for (int i = 0; i < 60; ++i)
    objs.push_back(i % 2 ? box(pos(rng), pos(rng), yaw(rng), 4.5, 1.8, 0.0, 1.5)
                         : cylinder(pos(rng), pos(rng), 0.3, 0.0, 1.8));
  objs.push_back(box(400.0, 0.0, 0.3, 10.0, 3.0, 0.0, 4.0));  // outside the grid
  SceneParams params;
  params.cell_size = 3.0;
  Scene scene(bs, params);
  scene.setObjects(objs);
  std::uniform_real_distribution<double> az(-kPi, kPi), el(-0.3, 0.3), z(0.3, 3.0);
  int checked = 0;
  for (int k = 0; k < 3000; ++k)
  {
    const double ox = pos(rng), oy = pos(rng), oz = z(rng), a = az(rng), e = el(rng);
    const double max_range = 500.0;
    const BeamHit h = scene.castRay(ox, oy, oz, a, e, max_range);
    // Brute force over every solid.
    const Ray2 ray{ core::Point2{ ox, oy }, std::cos(a), std::sin(a) };
    const double slope = std::tan(e), max_s = max_range * std::cos(e);
    double best = groundHitDistance(oz, slope);
    std::vector<Span> spans;
    for (const auto& b : bs) appendSpans(b.footprint, 0.0, b.height, ray, spans);
    for (const auto& o : objs)
    {
      Span sp;
      if (o.shape == WorldObject::Shape::kBox ? spanOf(o.box, ray, sp) : spanOf(o.cylinder, ray, sp))
        spans.push_back(sp);
    }
    bool inside = false;
    for (const Span& sp : spans)
    {
      if (sp.s_in < 0.0 && sp.s_out > 0.0) inside = true;
      if (sp.s_out >= 0.0) best = std::min(best, hitDistance(sp, oz, slope));
    }
    if (inside) continue;  // the sensor must not stand inside a footprint
    ++checked;
    if (best > max_s) EXPECT_EQ(h.solid, BeamHit::kNone) << k;
    else EXPECT_NEAR(h.s, best, 1e-9) << k;
  }
  EXPECT_GT(checked, 2000);
}

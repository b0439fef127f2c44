// The shipped scenarios (scenarios/*.yaml) on the town's buildings: they load, nothing collides (objects,
// ego, buildings), and each shows what it promises (bus V then S, parked car that leaves, F/C/N/S/V cells).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>

#include "map_aided_fusion/sim/simulator.hpp"
#include "town_fixture.hpp"

using namespace map_aided_fusion;
using namespace map_aided_fusion::sim;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kEgoLength = 4.6, kEgoWidth = 1.9, kEgoCentreAhead = 1.3;  // footprint around base_link
constexpr double kCheckStep = 0.1;  // s
constexpr int kCircleSides = 16;

using Convex = std::vector<Point2>;

Convex boxCorners(double cx, double cy, double yaw, double l, double w)
{
  const double c = std::cos(yaw), s = std::sin(yaw);
  Convex p;
  for (auto [a, b] : std::array<std::pair<double, double>, 4>{ { { 1, 1 }, { -1, 1 }, { -1, -1 }, { 1, -1 } } })
    p.push_back(Point2{ cx + c * a * l / 2 - s * b * w / 2, cy + s * a * l / 2 + c * b * w / 2 });
  return p;
}

Convex footprint(const WorldObject& o)
{
  if (o.shape == WorldObject::Shape::kBox) return boxCorners(o.box.cx, o.box.cy, o.box.yaw, o.box.length, o.box.width);
  Convex p;
  for (int i = 0; i < kCircleSides; ++i)
  {
    const double a = 2.0 * kPi * i / kCircleSides;
    p.push_back(Point2{ o.cylinder.cx + o.cylinder.radius * std::cos(a), o.cylinder.cy + o.cylinder.radius * std::sin(a) });
  }
  return p;
}

/// Separating axis test for two convex polygons.
bool overlap(const Convex& a, const Convex& b)
{
  for (const Convex* p : { &a, &b })
    for (std::size_t i = 0; i < p->size(); ++i)
    {
      const Point2 u = (*p)[i], v = (*p)[(i + 1) % p->size()];
      const double nx = v.y - u.y, ny = u.x - v.x;
      double a0 = 1e300, a1 = -1e300, b0 = 1e300, b1 = -1e300;
      for (const Point2& q : a) a0 = std::min(a0, q.x * nx + q.y * ny), a1 = std::max(a1, q.x * nx + q.y * ny);
      for (const Point2& q : b) b0 = std::min(b0, q.x * nx + q.y * ny), b1 = std::max(b1, q.x * nx + q.y * ny);
      if (a1 <= b0 || b1 <= a0) return false;
    }
  return true;
}

bool insideRing(const core::Ring& r, Point2 p)
{
  bool in = false;
  for (std::size_t i = 0, j = r.size() - 1; i < r.size(); j = i++)
    if ((r[j].y > p.y) != (r[i].y > p.y) && p.x < r[j].x + (p.y - r[j].y) * (r[i].x - r[j].x) / (r[i].y - r[j].y))
      in = !in;
  return in;
}

bool touchesBuilding(const Convex& c, const std::vector<WorldBuilding>& bs)
{
  for (const auto& b : bs)
  {
    for (const Point2& p : c)
    {
      bool in = insideRing(b.footprint.outer, p);
      for (const auto& h : b.footprint.holes) in = in && !insideRing(h, p);
      if (in) return true;
    }
    for (const Point2& v : b.footprint.outer)
      if (overlap(c, Convex{ v, Point2{ v.x + 1e-3, v.y }, Point2{ v.x, v.y + 1e-3 } })) return true;
  }
  return false;
}

Scenario load(const std::string& name) { return loadScenario(std::string(MAF_SOURCE_DIR) + "/scenarios/" + name); }

/// Runs a scenario's timeline and fails on any collision; returns the class history of each object.
std::map<std::uint32_t, std::vector<int>> checkTimeline(const Simulator& sim)
{
  std::map<std::uint32_t, std::vector<int>> history;
  std::vector<WorldObject> solids;
  std::vector<ObjectTruth> truth;
  int reported = 0;
  for (double t = 0.0; t <= sim.scenario().duration + 1e-9; t += kCheckStep)
  {
    sim.objectsAt(t, solids, truth);
    const Pose2 ego = sim.egoPose(t);
    const Convex ego_box = boxCorners(ego.x + kEgoCentreAhead * std::cos(ego.yaw),
                                      ego.y + kEgoCentreAhead * std::sin(ego.yaw), ego.yaw, kEgoLength, kEgoWidth);
    if (touchesBuilding(ego_box, sim.scene().buildings()) && reported++ < 5) ADD_FAILURE() << "ego in a building at " << t;
    std::vector<Convex> fp;
    for (const auto& o : solids) fp.push_back(footprint(o));
    for (std::size_t i = 0; i < solids.size(); ++i)
    {
      history[truth[i].id].push_back(static_cast<int>(truth[i].cell_class));
      if (overlap(fp[i], ego_box) && reported++ < 5)
        ADD_FAILURE() << "object " << truth[i].id << " hits the ego at t = " << t;
      if (touchesBuilding(fp[i], sim.scene().buildings()) && reported++ < 5)
        ADD_FAILURE() << "object " << truth[i].id << " in a building at t = " << t;
      for (std::size_t j = i + 1; j < solids.size(); ++j)
        if (overlap(fp[i], fp[j]) && reported++ < 5)
          ADD_FAILURE() << "objects " << truth[i].id << " and " << truth[j].id << " collide at t = " << t;
    }
  }
  return history;
}

int firstIndexOf(const std::vector<int>& v, int value)
{
  for (std::size_t i = 0; i < v.size(); ++i)
    if (v[i] == value) return static_cast<int>(i);
  return -1;
}

}  // namespace

TEST(SimScenarios, DefaultIsConsistentAndShowsEveryClass)
{
  const Scenario sc = load("default.yaml");
  EXPECT_EQ(sc.lidar.preset, "vlp32");
  EXPECT_DOUBLE_EQ(sc.duration, 60.0);
  Simulator sim(sc, maf_test::townLikeMap());
  EXPECT_EQ(sim.summary().absent_buildings, 1u);
  EXPECT_EQ(sim.summary().unmapped_buildings, 1u);
  auto history = checkTimeline(sim);
  const auto& bus = history.at(10);
  EXPECT_EQ(bus.front(), 4);  // drives
  EXPECT_EQ(bus.back(), 3);   // then stops for good
  // The ego drives more than 300 m.
  double travelled = 0.0;
  for (double t = kCheckStep; t <= 60.0; t += kCheckStep)
  {
    const Pose2 a = sim.egoPose(t - kCheckStep), b = sim.egoPose(t);
    travelled += std::hypot(b.x - a.x, b.y - a.y);
  }
  EXPECT_GT(travelled, 300.0);
  // Over a few scans along Main Street the ground truth holds every class.
  std::array<int, 5> seen{};
  ScanFrame f;
  for (int k : { 60, 100, 140 })
  {
    sim.scan(k, f);
    for (std::int8_t c : f.truth_classes)
      if (c >= 0) ++seen[static_cast<std::size_t>(c)];
  }
  for (int c = 0; c < 5; ++c) EXPECT_GT(seen[static_cast<std::size_t>(c)], 0) << "class " << c;
}

TEST(SimScenarios, DenseTrafficIsConsistentWithBusAndLeavingCar)
{
  const Scenario sc = load("dense_traffic.yaml");
  Simulator sim(sc, maf_test::townLikeMap());
  auto history = checkTimeline(sim);
  const auto& bus = history.at(1);
  EXPECT_EQ(bus.front(), 4);
  EXPECT_EQ(bus.back(), 3);
  const auto& leaver = history.at(2);
  EXPECT_EQ(leaver.front(), 3);  // parked
  const int leaves = firstIndexOf(leaver, 4);
  EXPECT_NEAR(leaves * kCheckStep, 20.0, 0.15);
  EXPECT_LT(leaver.size(), 600u);  // then vanishes
  // While the ego waits, the bus is hidden in some scans and seen in others: count its S cells.
  int hidden = 0, seen = 0;
  ScanFrame f;
  for (int k = 230; k < 330; k += 2)
  {
    sim.scan(k, f);
    int s_cells = 0;
    for (std::size_t i = 0; i < f.truth_classes.size(); ++i)
    {
      const Point2 c = f.truth_geometry.cellCentre(f.truth_geometry.cellOf(i));
      if (f.truth_classes[i] == 3 && c.x > -36.5 && c.x < -23.5 && c.y > 2.0 && c.y < 6.0) ++s_cells;
    }
    (s_cells < 10 ? hidden : seen)++;
  }
  EXPECT_GT(hidden, 0);
  EXPECT_GT(seen, 0);
}

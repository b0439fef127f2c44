#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "map_aided_fusion/eval/metrics.hpp"
#include "map_aided_fusion/eval/movers.hpp"

using namespace map_aided_fusion;
using namespace map_aided_fusion::eval;
using core::CellClass;

namespace {

constexpr auto V = static_cast<std::int8_t>(CellClass::kMoving);
constexpr auto S = static_cast<std::int8_t>(CellClass::kStopped);
constexpr auto F = static_cast<std::int8_t>(CellClass::kFree);

ClassGrid grid(int w, int h, std::int8_t fill, double res = 1.0)
{
  ClassGrid g;
  g.geometry = core::GridGeometry{ res, w, h, 0.0, 0.0 };
  g.cells.assign(static_cast<std::size_t>(w * h), fill);
  return g;
}

TruthObject box(std::uint32_t id, CellClass c, double x, double y, double length, double width,
                const std::string& kind = "car")
{
  TruthObject o;
  o.id = id;
  o.cell_class = c;
  o.kind = kind;
  o.centre = core::Point2{ x, y };
  o.length = length;
  o.width = width;
  return o;
}

/// A sighting with @p occupied cells of which v are decided V and s decided S (the rest F).
ObjectSighting sighting(std::uint32_t id, const std::string& kind, MotionTruth m, std::uint32_t footprint,
                        std::uint32_t occupied, std::uint32_t v, std::uint32_t s, double speed = 5.0)
{
  ObjectSighting o;
  o.id = id;
  o.kind = kind;
  o.motion = m;
  o.speed = speed;
  o.footprint_cells = footprint;
  o.occupied_cells = occupied;
  o.decided[static_cast<std::size_t>(CellClass::kMoving)] = v;
  o.decided[static_cast<std::size_t>(CellClass::kStopped)] = s;
  o.decided[static_cast<std::size_t>(CellClass::kFree)] = occupied - v - s;
  return o;
}

}  // namespace

TEST(Movers, KindGroupsAndTheSeenRule)
{
  EXPECT_EQ(groupOf("Van"), ObjectGroup::kVehicle);
  EXPECT_EQ(groupOf("bus"), ObjectGroup::kVehicle);
  EXPECT_EQ(groupOf("Tram"), ObjectGroup::kVehicle);
  EXPECT_EQ(groupOf("Cyclist"), ObjectGroup::kCyclist);
  EXPECT_EQ(groupOf("Person_sitting"), ObjectGroup::kPedestrian);
  EXPECT_EQ(groupOf("Misc"), ObjectGroup::kOther);
  const SightingRule rule;  // 3 cells, or half the footprint when smaller
  EXPECT_EQ(rule.needed(32), 3u);
  EXPECT_EQ(rule.needed(6), 3u);
  EXPECT_EQ(rule.needed(5), 3u);
  EXPECT_EQ(rule.needed(4), 2u);
  EXPECT_EQ(rule.needed(1), 1u);
  EXPECT_EQ(rule.needed(0), 1u);
}

// A car moving over five scans 0.1 s apart and a pedestrian never called V; a parked car; an ambiguous object.
//  car: scan 0 unseen (2 of 3 cells), 1 other, 2 S, 3 V, 4 V: first seen 0.1, first V 0.3, delay 0.2 s,
//       V share 2/4; cells while seen 10 + 10 + 10 + 10 = 40, S 2 + 6 + 0 + 0 = 8: S share 0.2; V cells 1+1+6+8 = 16.
//  pedestrian: seen in scans 1-4, never V: never detected; its S cells 0 of 8.
//  parked car: seen twice with 10 cells, 1 V: V share 2 / 20 = 0.1.
TEST(Movers, ScriptedRunGivesTheHandCountedScores)
{
  MoverScorer m;
  const double t0 = 100.0;
  const std::vector<std::vector<ObjectSighting>> scans{
    { sighting(1, "car", MotionTruth::kMoving, 30, 2, 2, 0), sighting(3, "car", MotionTruth::kParked, 30, 10, 1, 9, 0.1),
      sighting(4, "van", MotionTruth::kAmbiguous, 30, 10, 10, 0, 0.3) },
    { sighting(1, "car", MotionTruth::kMoving, 30, 10, 1, 2), sighting(2, "pedestrian", MotionTruth::kMoving, 4, 2, 0, 1, 1.5),
      sighting(3, "car", MotionTruth::kParked, 30, 10, 1, 9, 0.1) },
    { sighting(1, "car", MotionTruth::kMoving, 30, 10, 1, 6), sighting(2, "pedestrian", MotionTruth::kMoving, 4, 2, 0, 0, 1.5) },
    { sighting(1, "car", MotionTruth::kMoving, 30, 10, 6, 0), sighting(2, "pedestrian", MotionTruth::kMoving, 4, 2, 1, 0, 1.5) },
    { sighting(1, "car", MotionTruth::kMoving, 30, 10, 8, 0), sighting(2, "pedestrian", MotionTruth::kMoving, 4, 2, 1, 0, 1.5) },
  };
  const std::uint64_t false_v[] = { 0, 1, 2, 0, 2 };
  for (std::size_t k = 0; k < scans.size(); ++k) m.add(t0 + 0.1 * static_cast<double>(k), scans[k], false_v[k]);

  const MoverRecord& car = m.records().at(1);
  EXPECT_TRUE(car.isMover());
  EXPECT_EQ(car.moving_scans, 5);
  EXPECT_EQ(car.seen_moving, 4);
  EXPECT_DOUBLE_EQ(car.first_seen, t0 + 0.1);
  EXPECT_DOUBLE_EQ(car.first_detected, t0 + 0.3);
  EXPECT_NEAR(car.delay(), 0.2, 1e-12);
  EXPECT_DOUBLE_EQ(car.vShare(), 0.5);
  EXPECT_DOUBLE_EQ(car.sShare(), 8.0 / 40.0);
  EXPECT_DOUBLE_EQ(car.vCellShare(), 16.0 / 40.0);
  ASSERT_EQ(car.timeline.size(), 5u);
  EXPECT_EQ(car.timeline[0].second, SightingState::kUnseen);
  EXPECT_EQ(car.timeline[1].second, SightingState::kOther);
  EXPECT_EQ(car.timeline[2].second, SightingState::kS);
  EXPECT_EQ(car.timeline[3].second, SightingState::kV);
  const MoverRecord& ped = m.records().at(2);
  EXPECT_EQ(ped.seen_moving, 4);  // 2 of 4 footprint cells are enough
  EXPECT_EQ(ped.v_scans, 0);      // 1 of 2 cells V is not more than half
  EXPECT_LT(ped.delay(), 0.0);
  EXPECT_FALSE(m.records().at(3).isMover());
  EXPECT_FALSE(m.records().at(4).isMover());

  const auto s = m.summary();
  EXPECT_DOUBLE_EQ(s.at("movers.all.seen"), 2.0);
  EXPECT_DOUBLE_EQ(s.at("movers.all.detected_within_0_5s"), 1.0);
  EXPECT_DOUBLE_EQ(s.at("movers.all.detected_within_1s"), 1.0);
  EXPECT_DOUBLE_EQ(s.at("movers.all.never_detected"), 1.0);
  EXPECT_TRUE(std::isnan(s.at("movers.all.median_delay_s")));  // median of {0.2, never}
  EXPECT_NEAR(s.at("movers.vehicle.median_delay_s"), 0.2, 1e-12);
  EXPECT_DOUBLE_EQ(s.at("movers.all.mean_v_share"), 0.25);  // (0.5 + 0) / 2
  EXPECT_DOUBLE_EQ(s.at("movers.all.s_share"), (8.0 + 1.0) / 48.0);
  EXPECT_DOUBLE_EQ(s.at("movers.pedestrian.seen"), 1.0);
  EXPECT_DOUBLE_EQ(s.at("parked.all.objects"), 1.0);
  EXPECT_DOUBLE_EQ(s.at("parked.vehicle.v_share"), 0.1);
  EXPECT_DOUBLE_EQ(s.at("movers.false_v_per_scan"), 1.0);
  EXPECT_DOUBLE_EQ(s.at("movers.scans"), 5.0);

  const std::string md = moverObjectsMarkdown(m);
  EXPECT_NE(md.find("| 1 | car | 5.0 | 5 | 4 | 0.1 | 0.3 | 0.2 | 0.50 | 0.40 | 0.20 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| 2 | pedestrian | 1.5 | 4 | 4 | 0.1 | never | – | 0.00 |"), std::string::npos) << md;
  const std::string json = moverObjectsJson(m);
  EXPECT_NE(json.find("\"timeline\": [[0, 0], [1, 3], [2, 2], [3, 1], [4, 1]]"), std::string::npos) << json;
  EXPECT_NE(moversMarkdown({ { "default", &m } }).find("| default | all | 2 | 1/2 | 1/2 | 1 | never | 0.25 |"),
            std::string::npos);
}

TEST(Movers, MedianDelayOverThreeMovers)
{
  MoverScorer m;
  // Three cars seen at t = 0; detected at 0.4, 0.2 and never.
  for (int k = 0; k <= 5; ++k)
  {
    const double t = 0.1 * k;
    m.add(t,
          { sighting(1, "car", MotionTruth::kMoving, 30, 10, k >= 4 ? 10 : 0, 0),
            sighting(2, "car", MotionTruth::kMoving, 30, 10, k >= 2 ? 10 : 0, 0),
            sighting(3, "car", MotionTruth::kMoving, 30, 10, 0, 0) },
          0);
  }
  const auto s = m.summary();
  EXPECT_NEAR(s.at("movers.all.median_delay_s"), 0.4, 1e-12);
  EXPECT_DOUBLE_EQ(s.at("movers.all.detected_within_0_5s"), 2.0);
}

TEST(Movers, SightingsFromTheSimulatorsClassGrid)
{
  // A 4 x 2 m car centred at (5, 5) covers the cells x 3..6, y 4..5 (8 centres); the truth observes 6 of them as V.
  auto truth = grid(10, 10, static_cast<std::int8_t>(CellClass::kUnknown));
  for (int x = 3; x <= 5; ++x)
    for (int y = 4; y <= 5; ++y) truth.cells[truth.geometry.index(x, y)] = V;
  auto decision = grid(10, 10, F);
  decision.cells[decision.geometry.index(3, 4)] = V;
  decision.cells[decision.geometry.index(4, 4)] = V;
  decision.cells[decision.geometry.index(5, 5)] = S;
  decision.cells[decision.geometry.index(6, 5)] = V;  // in the footprint but not observed: not counted
  const auto out = sightingsFromClassGrid(truth, { box(7, CellClass::kMoving, 5, 5, 4, 2),
                                                   box(8, CellClass::kInfrastructure, 1, 1, 1, 1, "pole") },
                                          decision);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].id, 7u);
  EXPECT_EQ(out[0].footprint_cells, 8u);
  EXPECT_EQ(out[0].occupied_cells, 6u);
  EXPECT_EQ(out[0].decidedAs(CellClass::kMoving), 2u);
  EXPECT_EQ(out[0].decidedAs(CellClass::kStopped), 1u);
  EXPECT_EQ(out[0].decidedAs(CellClass::kFree), 3u);
}

TEST(Movers, ReturnsInBoxesAndTheirSightings)
{
  // Points (x, y, z) in a frame equal to the map and the vehicle frame.
  const std::vector<float> xyz{
    5.0f, 5.0f, 1.0f,   // in the car
    5.1f, 5.2f, 1.0f,   // same cell
    6.9f, 5.0f, 1.0f,   // just outside the footprint (x half-length 2 → 7.0), within the 0.2 m margin
    7.5f, 5.0f, 1.0f,   // outside the margin
    4.0f, 5.0f, 0.05f,  // below the obstacle band (ground)
    4.0f, 5.5f, 2.6f,   // above the box's top + margin (centre z 1, height 2 → top 2.0 + 0.2)
    NAN,  5.0f, 1.0f,   // not finite
    3.5f, 4.5f, 1.5f,   // in the car, another cell
  };
  core::PointCloudView cloud;
  cloud.data = reinterpret_cast<const std::uint8_t*>(xyz.data());
  cloud.width = xyz.size() / 3;
  cloud.point_step = 3 * sizeof(float);
  cloud.row_step = cloud.width * cloud.point_step;
  TruthObject car = box(1, CellClass::kMoving, 5, 5, 4, 2);
  car.z = 1.0;
  car.height = 2.0;
  ReturnsInBoxes rule;
  rule.obstacle_low = 0.2;
  rule.obstacle_high = 3.0;
  const auto returns = collectObjectReturns(cloud, Eigen::Isometry3d::Identity(), Eigen::Isometry3d::Identity(),
                                            { car }, rule);
  ASSERT_EQ(returns.size(), 1u);
  ASSERT_EQ(returns[0].returns.size(), 4u);
  auto decision = grid(10, 10, F);
  decision.cells[decision.geometry.index(5, 5)] = V;
  const auto s = sightingsFromReturns(returns, decision);
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s[0].occupied_cells, 3u);  // cells (5, 5), (6, 5), (3, 4)
  EXPECT_EQ(s[0].decidedAs(CellClass::kMoving), 1u);
  EXPECT_EQ(s[0].footprint_cells, 8u);
}

TEST(Movers, FalseVOnlyWhereLabelsAreValidAndFarFromMovers)
{
  auto decision = grid(10, 10, F);
  decision.cells[decision.geometry.index(1, 1)] = V;  // valid, far from everything: false
  decision.cells[decision.geometry.index(5, 5)] = V;  // on the mover
  decision.cells[decision.geometry.index(7, 5)] = V;  // 0.5 m beyond the mover's footprint: within 1 m
  decision.cells[decision.geometry.index(8, 8)] = V;  // on the parked car: false
  decision.cells[decision.geometry.index(1, 8)] = V;  // outside the valid region
  decision.cells[decision.geometry.index(8, 1)] = V;  // on an ambiguous object
  auto valid = grid(10, 10, 100);
  for (int x = 0; x < 10; ++x) valid.cells[valid.geometry.index(x, 8)] = 0;
  valid.cells[valid.geometry.index(8, 8)] = 100;
  const std::vector<TruthObject> objects{ box(1, CellClass::kMoving, 5, 5, 4, 2), box(2, CellClass::kStopped, 8.5, 8.5, 1, 1),
                                          box(3, CellClass::kUnknown, 8.5, 1.5, 1, 1) };
  EXPECT_EQ(countFalseV(decision, &valid, objects, 1.0), 2u);
  EXPECT_EQ(countFalseV(decision, nullptr, objects, 1.0), 3u);
  EXPECT_EQ(countFalseV(decision, &valid, objects, 0.0), 3u);  // (7, 5)'s centre is 0.5 m off the footprint
}

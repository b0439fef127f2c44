#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>

#include "map_aided_fusion/core/parameters.hpp"
#include "map_aided_fusion/core/track_evidence.hpp"
#include "map_aided_fusion/core/tracker.hpp"

using namespace map_aided_fusion::core;

namespace {

/// Returns on the outline of a length × width box centred on (x, y), heading yaw, every 0.1 m.
std::vector<Point2> boxOutline(double x, double y, double yaw, double length, double width)
{
  std::vector<Point2> out;
  const double c = std::cos(yaw), s = std::sin(yaw);
  auto add = [&](double u, double v) { out.push_back(Point2{ x + c * u - s * v, y + s * u + c * v }); };
  for (double u = -0.5 * length; u <= 0.5 * length + 1e-9; u += 0.1)
  {
    add(u, -0.5 * width);
    add(u, 0.5 * width);
  }
  for (double v = -0.5 * width + 0.1; v < 0.5 * width - 1e-9; v += 0.1)
  {
    add(-0.5 * length, v);
    add(0.5 * length, v);
  }
  return out;
}

Measurement at(double x, double y, double sigma = 0.2)
{
  Measurement m;
  m.centroid = Point2{ x, y };
  m.covariance = Eigen::Matrix2d::Identity() * sigma * sigma;
  m.points = 10;
  return m;
}

const Track* byId(const Tracker& t, std::uint32_t id)
{
  for (const Track& k : t.tracks())
    if (k.id == id) return &k;
  return nullptr;
}

}  // namespace

TEST(Tracker, ParametersAreValidatedByName)
{
  TrackerParams p;
  EXPECT_NO_THROW(p.validate());
  p.gate = 0.0;
  try
  {
    p.validate();
    FAIL() << "gate 0 accepted";
  }
  catch (const ParameterError& e)
  {
    EXPECT_EQ(e.parameter(), "tracker_gate");
  }
  p = TrackerParams{};
  p.confirm_hits = 0;
  EXPECT_THROW(Tracker{ p }, ParameterError);
  p = TrackerParams{};
  p.cluster_distance = std::nan("");
  EXPECT_THROW(p.validate(), ParameterError);
}

TEST(Tracker, ClustersAreObjectsAndWallsAreNot)
{
  TrackerParams p;
  std::vector<Point2> pts = boxOutline(10.0, 5.0, 0.3, 4.0, 2.0);   // a car
  const auto ped = boxOutline(20.0, -3.0, 0.0, 0.5, 0.5);            // a pedestrian
  pts.insert(pts.end(), ped.begin(), ped.end());
  for (double x = 0.0; x <= 20.0; x += 0.1) pts.push_back(Point2{ x, 15.0 });  // a 20 m wall
  pts.push_back(Point2{ -30.0, -30.0 });                                       // a lone return
  pts.push_back(Point2{ std::nan(""), 1.0 });
  const auto m = clusterReturns(pts, p);
  ASSERT_EQ(m.size(), 2u);
  const Measurement& car = std::abs(m[0].centroid.x - 10.0) < 1.0 ? m[0] : m[1];
  const Measurement& walker = &car == &m[0] ? m[1] : m[0];
  EXPECT_NEAR(car.centroid.x, 10.0, 0.05);
  EXPECT_NEAR(car.centroid.y, 5.0, 0.05);
  EXPECT_NEAR(car.length, 4.0, 0.15);
  EXPECT_NEAR(car.width, 2.0, 0.15);
  EXPECT_NEAR(std::fmod(car.yaw + 2.0 * M_PI, M_PI), 0.3, 0.02);  // the major axis, either direction
  EXPECT_NEAR(walker.centroid.x, 20.0, 0.05);
  // A larger cluster is less certain along its long axis.
  EXPECT_GT(car.covariance.trace(), walker.covariance.trace());
}

TEST(Tracker, ConstantVelocityObjectIsConfirmedAndMovingWithItsVelocity)
{
  Tracker tracker;
  std::uint32_t id = 0;
  for (int k = 0; k <= 20; ++k)
  {
    const double t = 0.1 * k;
    tracker.update(t, { at(10.0 + 5.0 * t, 2.0 - 1.0 * t) });
    ASSERT_EQ(tracker.tracks().size(), 1u) << "scan " << k;
    const Track& tr = tracker.tracks()[0];
    if (k == 0) id = tr.id;
    EXPECT_EQ(tr.id, id) << "one id all along";
    EXPECT_EQ(tr.state, k < 2 ? TrackState::kTentative : TrackState::kConfirmed) << "scan " << k;
  }
  const Track& tr = tracker.tracks()[0];
  EXPECT_NEAR(tr.velocity().x, 5.0, 0.05);
  EXPECT_NEAR(tr.velocity().y, -1.0, 0.05);
  EXPECT_EQ(tr.motion, TrackMotion::kMoving);
  EXPECT_LT(tr.speedSigma(), 0.5);
}

TEST(Tracker, MovingFlagComesWithinHalfASecondAtCarSpeed)
{
  Tracker tracker;
  int first_moving = -1;
  for (int k = 0; k <= 20 && first_moving < 0; ++k)
  {
    tracker.update(0.1 * k, { at(8.0 * 0.1 * k, 0.0) });
    if (tracker.tracks()[0].motion == TrackMotion::kMoving) first_moving = k;
  }
  ASSERT_GE(first_moving, 0);
  EXPECT_LE(first_moving, 5);  // 8 m/s: moving by the sixth scan
}

TEST(Tracker, StaticObjectBecomesStoppedAfterStoppedTime)
{
  TrackerParams p;
  Tracker tracker(p);
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.05);
  int first_stopped = -1;
  for (int k = 0; k <= 40; ++k)
  {
    tracker.update(0.1 * k, { at(5.0 + noise(rng), -2.0 + noise(rng)) });
    ASSERT_EQ(tracker.tracks().size(), 1u);
    EXPECT_NE(tracker.tracks()[0].motion, TrackMotion::kMoving) << "scan " << k;
    if (first_stopped < 0 && tracker.tracks()[0].motion == TrackMotion::kStopped) first_stopped = k;
  }
  ASSERT_GE(first_stopped, 0);
  EXPECT_GE(0.1 * first_stopped, p.stopped_time);
}

TEST(Tracker, CrossingObjectsKeepTheirIds)
{
  Tracker tracker;
  std::uint32_t a = 0, b = 0;
  for (int k = 0; k <= 30; ++k)
  {
    const double t = 0.1 * k;
    // Two pedestrians crossing: they pass 1 m apart at t = 1.5 s.
    tracker.update(t, { at(-3.0 + 2.0 * t, 0.5), at(3.0 - 2.0 * t, -0.5) });
    ASSERT_EQ(tracker.tracks().size(), 2u) << "scan " << k;
    if (k == 0)
    {
      a = tracker.tracks()[0].id;
      b = tracker.tracks()[1].id;
    }
  }
  ASSERT_NE(byId(tracker, a), nullptr);
  ASSERT_NE(byId(tracker, b), nullptr);
  EXPECT_NEAR(byId(tracker, a)->position().x, 3.0, 0.3);   // the first went right
  EXPECT_NEAR(byId(tracker, b)->position().x, -3.0, 0.3);  // the second went left
  EXPECT_GT(byId(tracker, a)->velocity().x, 1.5);
  EXPECT_LT(byId(tracker, b)->velocity().x, -1.5);
}

TEST(Tracker, LifecycleTentativeDropsConfirmedCoastsThenDrops)
{
  TrackerParams p;
  Tracker tracker(p);
  tracker.update(0.0, { at(0, 0), at(30, 0) });
  tracker.update(0.1, { at(0, 0) });  // the tentative track at 30 m is missed once: deleted
  ASSERT_EQ(tracker.tracks().size(), 1u);
  tracker.update(0.2, { at(0, 0) });
  EXPECT_EQ(tracker.tracks()[0].state, TrackState::kConfirmed);
  tracker.update(0.3, {});
  ASSERT_EQ(tracker.tracks().size(), 1u);
  EXPECT_EQ(tracker.tracks()[0].state, TrackState::kCoasting);
  tracker.update(0.4, { at(0.05, 0) });
  EXPECT_EQ(tracker.tracks()[0].state, TrackState::kConfirmed);
  for (int k = 5; k <= 9; ++k) tracker.update(0.1 * k, {});
  ASSERT_EQ(tracker.tracks().size(), 1u);  // 0.5 s without an association: still coasting
  tracker.update(1.0, {});
  EXPECT_TRUE(tracker.tracks().empty());  // more than max_coast_time
  EXPECT_EQ(tracker.counts().tracks_created, 2u);
  EXPECT_EQ(tracker.counts().tracks_deleted, 2u);
}

TEST(Tracker, TimeGoingBackOrAPoseJumpResetsAndIsCounted)
{
  TrackerParams p;
  p.min_cluster_points = 4;
  Tracker tracker(p);
  tracker.update(1.0, { at(0, 0) });
  tracker.update(0.5, { at(0, 0) });
  EXPECT_EQ(tracker.counts().resets, 1u);
  ASSERT_EQ(tracker.tracks().size(), 1u);  // the scan's measurement starts a new track
  const std::vector<float> xy{ 5.0f, 0.0f, 5.1f, 0.0f, 5.0f, 0.1f, 5.1f, 0.1f };
  const ObstaclePoints returns{ xy.data(), 4 };
  tracker.update(0.6, Pose2{ 0, 0, 0 }, returns);
  tracker.update(0.7, Pose2{ 100, 0, 0 }, returns);  // 1000 m/s
  EXPECT_EQ(tracker.counts().resets, 2u);
}

TEST(Tracker, BadInputNeverReachesATrack)
{
  Tracker tracker;
  Measurement nan_centroid = at(std::nan(""), 0);
  Measurement singular = at(1, 1);
  singular.covariance.setZero();
  Measurement inf_cov = at(2, 2);
  inf_cov.covariance(0, 0) = std::numeric_limits<double>::infinity();
  tracker.update(0.0, { nan_centroid, singular, inf_cov, at(3, 3) });
  ASSERT_EQ(tracker.tracks().size(), 1u);
  EXPECT_EQ(tracker.counts().non_finite_inputs, 3u);
  const std::vector<float> xy{ std::nanf(""), 0.0f };
  tracker.update(0.1, Pose2{ 0, 0, std::nan("") }, ObstaclePoints{ xy.data(), 1 });
  tracker.update(0.2, Pose2{ 0, 0, 0 }, ObstaclePoints{ xy.data(), 1 });
  EXPECT_EQ(tracker.counts().non_finite_inputs, 5u);
  for (const Track& t : tracker.tracks())
  {
    EXPECT_TRUE(t.x.allFinite());
    EXPECT_TRUE(t.P.allFinite());
  }
}

TEST(Tracker, StaticSceneSeenFromADrivingVehicleGivesNoMovingTrack)
{
  Tracker tracker;
  // Parked cars and poles along a street; the vehicle drives past at 10 m/s; returns in the vehicle frame.
  std::vector<Point2> world;
  for (int k = 0; k < 6; ++k)
  {
    const auto car = boxOutline(10.0 + 8.0 * k, 4.0, 0.0, 4.2, 1.8);
    world.insert(world.end(), car.begin(), car.end());
    const auto pole = boxOutline(12.0 + 8.0 * k, -4.0, 0.0, 0.2, 0.2);
    world.insert(world.end(), pole.begin(), pole.end());
  }
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 0.03);
  int moving = 0;
  for (int k = 0; k <= 40; ++k)
  {
    const Pose2 pose{ 1.0 * k, 0.0, 0.02 * std::sin(0.3 * k) };
    std::vector<float> xy;
    const double c = std::cos(pose.yaw), s = std::sin(pose.yaw);
    for (const Point2& w : world)
    {
      const double dx = w.x - pose.x, dy = w.y - pose.y;
      if (std::hypot(dx, dy) > 30.0) continue;  // the sensor's range
      xy.push_back(static_cast<float>(c * dx + s * dy + noise(rng)));
      xy.push_back(static_cast<float>(-s * dx + c * dy + noise(rng)));
    }
    tracker.update(0.1 * k, pose, ObstaclePoints{ xy.data(), xy.size() / 2 });
    for (const Track& t : tracker.tracks()) moving += t.motion == TrackMotion::kMoving;
  }
  EXPECT_EQ(moving, 0);
  EXPECT_GE(tracker.counts().tracks_created, 6u);  // every parked car is tracked (the poles are too small)
}

TEST(Tracker, ClustersMostlyOnStaticBackgroundAreNoCandidates)
{
  // Vehicle at (10, 0) heading +y: vehicle-frame (x, y) is map (10 - y, x).
  const std::vector<float> xy{ 1.0f, 0.0f, 2.0f, 0.0f, 3.0f, 0.0f, 4.0f, 0.0f };
  // ζ by map y: background (0.9) at y = 2, borderline (0.2) at y = 3, outside the grid (-1) at y = 4.
  auto zeta = [](Point2 p) { return p.y > 1.5 && p.y < 2.5 ? 0.9 : p.y > 2.5 && p.y < 3.5 ? 0.2 : p.y > 3.5 ? -1.0 : 0.0; };
  std::vector<std::uint8_t> flags;
  backgroundFlags(Pose2{ 10.0, 0.0, M_PI / 2 }, ObstaclePoints{ xy.data(), 4 }, 0.2, zeta, flags);
  EXPECT_EQ(flags, (std::vector<std::uint8_t>{ 0, 1, 0, 0 }));

  TrackerParams p;
  p.min_cluster_points = 4;
  // Two clusters of 10 returns: a facade piece 9 of whose returns are on background, a car 4 of whose are.
  std::vector<Point2> pts;
  std::vector<std::uint8_t> bg;
  for (int k = 0; k < 10; ++k)
  {
    pts.push_back(Point2{ 0.1 * k, 0.0 });
    bg.push_back(k < 9);
    pts.push_back(Point2{ 0.25 * k, 10.0 });  // closer than half the cluster distance: one cluster
    bg.push_back(k < 4);
  }
  const auto m = clusterReturns(pts, p, &bg);
  ASSERT_EQ(m.size(), 1u);
  EXPECT_NEAR(m[0].centroid.y, 10.0, 1e-9);
  p.background_share = 1.0;  // off
  EXPECT_EQ(clusterReturns(pts, p, &bg).size(), 2u);
  EXPECT_EQ(clusterReturns(pts, TrackerParams{ p }, nullptr).size(), 2u);
}

TEST(Tracker, EvidenceCoversTheCellsOfTheLastClusterWithTheMotionProbability)
{
  Tracker tracker;
  const GridGeometry g{ 0.5, 200, 200, -50.0, -50.0 };
  std::vector<float> xy;
  for (int k = 0; k <= 8; ++k)
  {
    // A 4 x 2 m car driving at 8 m/s along x, seen from the origin (vehicle frame = map frame).
    xy.clear();
    for (const Point2& p : boxOutline(10.0 + 0.8 * k, 5.0, 0.0, 4.0, 2.0))
    {
      xy.push_back(static_cast<float>(p.x));
      xy.push_back(static_cast<float>(p.y));
    }
    tracker.update(0.1 * k, Pose2{ 0.0, 0.0, 0.0 }, ObstaclePoints{ xy.data(), xy.size() / 2 });
  }
  ASSERT_EQ(tracker.tracks().size(), 1u);
  const Track& t = tracker.tracks()[0];
  ASSERT_EQ(t.motion, TrackMotion::kMoving);
  const double p = motionProbability(t, tracker.params());
  EXPECT_NEAR(p, 0.5 * std::erfc(-(t.speed() - tracker.params().moving_speed) / t.speedSigma() / std::sqrt(2.0)), 1e-12);
  EXPECT_GT(p, 0.9);
  const std::vector<CellMotion> cells = trackEvidence(tracker, g);
  std::set<std::size_t> expected;
  for (std::size_t i = 0; i < xy.size(); i += 2)
  {
    CellIndex c;
    ASSERT_TRUE(g.worldToCell(Point2{ xy[i], xy[i + 1] }, c));
    expected.insert(g.index(c));
  }
  std::set<std::size_t> got;
  for (const CellMotion& c : cells)
  {
    got.insert(c.cell);
    EXPECT_EQ(c.motion, CellClass::kMoving);
    EXPECT_NEAR(c.weight, 0.8 * p, 1e-6);
  }
  EXPECT_EQ(got, expected);
  EXPECT_EQ(got.size(), cells.size()) << "one entry per cell";
  TrackerParams off;
  off.evidence_weight = 0.0;
  Tracker silent(off);
  silent.update(0.0, Pose2{}, ObstaclePoints{ xy.data(), xy.size() / 2 });
  EXPECT_TRUE(trackEvidence(silent, g).empty());
}

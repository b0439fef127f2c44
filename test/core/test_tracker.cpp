#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <string>
#include <type_traits>
#include <vector>

#include "map_aided_fusion/core/parameters.hpp"
#include "map_aided_fusion/core/profiles.hpp"
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

/// @p m with a @p length × @p width extent centred on its centroid, its major axis along its yaw.
Measurement withExtent(Measurement m, double length, double width)
{
  m.length = length;
  m.width = width;
  m.lo_u = -0.5 * length;
  m.hi_u = 0.5 * length;
  m.lo_v = -0.5 * width;
  m.hi_v = 0.5 * width;
  return m;
}

const Track* byId(const Tracker& t, std::uint32_t id)
{
  for (const Track& k : t.tracks())
    if (k.id == id) return &k;
  return nullptr;
}

/// Each case breaks one parameter; validate() must refuse it with an error naming it.
void expectRefusedByName(const std::vector<std::pair<std::string, void (*)(TrackerParams&)>>& cases)
{
  for (const auto& [name, set] : cases)
  {
    TrackerParams p;
    set(p);
    try
    {
      p.validate();
      ADD_FAILURE() << name << " accepted";
    }
    catch (const ParameterError& e)
    {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  }
}

}  // namespace

TEST(Tracker, ReturnsFarOutOfRangeAreNoClusterAndNoUndefinedCast)
{
  // fuzz_tracker's first find: a pose 10¹⁹ m out put the returns' cells beyond a 64-bit index (an undefined cast,
  // caught by the sanitizers). They form no cluster; a track far out is still associated through the grid.
  TrackerParams p;
  p.min_cluster_points = 4;
  Tracker tracker(p);
  const std::vector<float> xy{ 5.0f, 0.0f, 5.1f, 0.0f, 5.0f, 0.1f, 5.1f, 0.1f };
  tracker.update(1.0, Pose2{ -1.1e19, 3e18, 0.0 }, ObstaclePoints{ xy.data(), 4 });
  EXPECT_TRUE(tracker.measurements().empty());
  EXPECT_TRUE(tracker.tracks().empty());
  Tracker far;
  far.update(2.0, { at(1e17, -1e17) });
  far.update(2.1, { at(1e17, -1e17) });
  ASSERT_EQ(far.tracks().size(), 1u);
  EXPECT_EQ(far.tracks()[0].hits, 2);
}

TEST(Tracker, AResetFromOutsideIsCountedAndForgetsTheLastStampAndFreeSpace)
{
  Tracker tracker;
  tracker.update(5.0, { at(0, 0) });
  tracker.reset();  // as the fusion does on a time jump
  EXPECT_EQ(tracker.counts().resets, 1u);
  EXPECT_TRUE(tracker.tracks().empty());
  // The next loop starts earlier: no second reset, and the new measurement starts a track.
  tracker.update(1.0, { at(0, 0) });
  EXPECT_EQ(tracker.counts().resets, 1u);
  EXPECT_EQ(tracker.tracks().size(), 1u);
}

namespace {

/// @p n measurements on a line away from the sensor at the origin, 10 m apart (measurement i at 10 (i + 1) m).
std::vector<Measurement> lineAwayFromSensor(int n)
{
  std::vector<Measurement> out;
  for (int i = 0; i < n; ++i)
  {
    Measurement m = withExtent(at(10.0 * (i + 1), 0.0), 1.0, 1.0);
    m.has_sensor = true;
    out.push_back(m);
  }
  return out;
}

}  // namespace

// The counter ζ starts at 0 and grows by delta_inc per consistent occupied scan: it first exceeds background_zeta at
// scan ⌊background_zeta / delta_inc⌋ + 1 (values exact in binary here), never when delta_inc is 0 or the threshold 1.
TEST(Tracker, BackgroundWarmupIsTheFirstScanTheCounterPassesTheThreshold)
{
  for (const double delta : { 0.25, 0.125, 0.0625 })
    for (const double threshold : { 0.0, 0.25, 0.375, 0.5, 0.75 })
    {
      double zeta = 0.0;
      std::size_t k = 0;
      while (!(zeta > threshold))
      {
        zeta = std::min(1.0, zeta + delta);
        ++k;
      }
      EXPECT_EQ(backgroundWarmupScans(threshold, delta), k) << "delta_inc " << delta << ", background_zeta " << threshold;
    }
  EXPECT_EQ(backgroundWarmupScans(0.4, 0.0), 0u) << "a counter that never grows: nothing to wait for";
  EXPECT_EQ(backgroundWarmupScans(1.0, 0.05), 0u) << "ζ never exceeds 1: background by ζ is off";
  EXPECT_EQ(backgroundWarmupScans(std::nan(""), 0.05), 0u);
}

// Tracks born while background is not yet known are confirmed (reported) as usual but published only once moving, or
// once associated after background became known; what stops being seen before that is never published.
TEST(Tracker, TracksBornBeforeBackgroundIsKnownArePublishedOnlyWhenMovingOrSeenAfter)
{
  Tracker tracker;
  tracker.setBackgroundKnown(false);
  std::uint32_t still = 0, mover = 0, gone = 0;
  for (int k = 0; k < 8; ++k)
  {
    const double t = 0.1 * k;
    tracker.update(t, { at(5.0, -2.0), at(10.0 + 8.0 * t, 4.0), at(-6.0, 8.0) });
    ASSERT_EQ(tracker.tracks().size(), 3u) << "scan " << k;
    for (const Track& tr : tracker.tracks())
    {
      EXPECT_TRUE(tr.background_unchecked);
      EXPECT_EQ(tr.reported(), k >= 2) << "confirmed as usual, scan " << k;
      EXPECT_EQ(tr.published(), tr.reported() && tr.motion == TrackMotion::kMoving) << "scan " << k;
    }
    if (k == 0)
    {
      still = tracker.tracks()[0].id;
      mover = tracker.tracks()[1].id;
      gone = tracker.tracks()[2].id;
    }
  }
  ASSERT_NE(byId(tracker, mover), nullptr);
  EXPECT_TRUE(byId(tracker, mover)->published()) << "the mover is out before background is known";
  EXPECT_FALSE(byId(tracker, still)->published());
  tracker.setBackgroundKnown(true);
  tracker.update(0.8, { at(5.0, -2.0), at(10.0 + 8.0 * 0.8, 4.0) });
  ASSERT_NE(byId(tracker, still), nullptr);
  EXPECT_FALSE(byId(tracker, still)->background_unchecked);
  EXPECT_TRUE(byId(tracker, still)->published()) << "associated while background is known: not background";
  ASSERT_NE(byId(tracker, gone), nullptr);
  EXPECT_EQ(byId(tracker, gone)->state, TrackState::kCoasting);
  EXPECT_FALSE(byId(tracker, gone)->published()) << "not seen since background is known";
  tracker.update(0.9, { at(5.0, -2.0), at(10.0 + 8.0 * 0.9, 4.0), at(20.0, -9.0) });
  EXPECT_FALSE(tracker.tracks().back().background_unchecked) << "born while background is known";
}

TEST(Tracker, MeasurementsOverTheBoundAreTheFarthestDroppedAndCounted)
{
  TrackerParams p;
  p.max_measurements = 3;
  Tracker tracker(p);
  std::vector<Measurement> scan = lineAwayFromSensor(5);
  std::swap(scan[0], scan[4]);  // the nearest last: the order given is not the order kept
  tracker.update(1.0, scan);
  ASSERT_EQ(tracker.measurements().size(), 3u);
  // The three nearest (10, 20, 30 m), in the order given (50 m went to the front, 10 m to the back).
  EXPECT_DOUBLE_EQ(tracker.measurements()[0].centroid.x, 20.0);
  EXPECT_DOUBLE_EQ(tracker.measurements()[1].centroid.x, 30.0);
  EXPECT_DOUBLE_EQ(tracker.measurements()[2].centroid.x, 10.0);
  EXPECT_EQ(tracker.counts().measurements_dropped, 2u);
  EXPECT_EQ(tracker.counts().peak_measurements, 5u);
  EXPECT_EQ(tracker.tracks().size(), 3u);
}

TEST(Tracker, TracksOverTheBoundAreNotStartedTheNearestFirstAndCounted)
{
  TrackerParams p;
  p.max_tracks = 4;
  Tracker tracker(p);
  tracker.update(1.0, lineAwayFromSensor(3));
  ASSERT_EQ(tracker.tracks().size(), 3u);
  // Three tracks kept (associated again), room for one of the three new clusters beyond: the nearest, at 40 m.
  tracker.update(1.1, lineAwayFromSensor(6));
  ASSERT_EQ(tracker.tracks().size(), 4u);
  EXPECT_NEAR(tracker.tracks().back().position().x, 40.0, 1e-9);
  EXPECT_EQ(tracker.counts().tracks_refused, 2u);
  EXPECT_EQ(tracker.counts().peak_tracks, 4u);
  p.max_tracks = 0;
  EXPECT_THROW(p.validate(), ParameterError);
  p = TrackerParams{};
  p.max_measurements = 2000000;
  EXPECT_THROW(p.validate(), ParameterError);
}

TEST(Tracker, TheAssociationsGridFindsEveryPairTheGateAllows)
{
  // Objects of every size, 0.5 to 18 m long, at random places and headings, moved by up to the gate's distance:
  // each keeps its id whether the others are near or far (the grid's cells are max_gate_distance wide, and a long
  // object's followed point lies far from its cluster's centroid).
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> where(-60.0, 60.0), size(0.5, 18.0), turn(-M_PI, M_PI), step(-1.5, 1.5);
  std::vector<Measurement> scan;
  for (int i = 0; i < 40; ++i)
  {
    Measurement m = withExtent(at(where(rng), where(rng), 0.1), size(rng), 1.0 + 0.1 * (i % 20));
    m.yaw = turn(rng);
    scan.push_back(m);
  }
  Tracker tracker;
  tracker.update(1.0, scan);
  std::vector<std::uint32_t> ids;
  for (const Track& t : tracker.tracks()) ids.push_back(t.id);
  for (Measurement& m : scan) m.centroid = Point2{ m.centroid.x + step(rng), m.centroid.y + step(rng) };
  tracker.update(1.1, scan);
  ASSERT_EQ(tracker.tracks().size(), ids.size());
  for (std::size_t k = 0; k < ids.size(); ++k) EXPECT_EQ(tracker.tracks()[k].id, ids[k]);
  EXPECT_EQ(tracker.counts().tracks_created, ids.size());
}

// tracker_steps_off names the steps of doc/steps.md: each tracker step of addedSteps() is one switch of the same
// name, which that step's disable() turns off alone, and every switch is such a step.
TEST(TrackerSteps, EachAddedTrackerStepIsOneSwitchOfTheSameName)
{
  std::set<std::string> switched;
  for (const AddedStep& step : addedSteps())
  {
    Profile p = defaultProfile();
    ASSERT_TRUE(stepsOff(p.tracker.steps).empty()) << "every step on by default";
    step.disable(p);
    const std::vector<std::string> off = stepsOff(p.tracker.steps);
    if (off.empty()) continue;  // not the tracker's
    EXPECT_EQ(off, std::vector<std::string>{ step.name }) << step.name;
    EXPECT_TRUE(step.enabled(defaultProfile())) << step.name;
    EXPECT_FALSE(step.enabled(p)) << step.name;
    switched.insert(step.name);
  }
  std::set<std::string> names;
  for (const TrackerStepSwitch& w : trackerStepSwitches()) names.insert(w.name);
  EXPECT_EQ(names.size(), trackerStepSwitches().size()) << "no name twice";
  EXPECT_EQ(switched, names);
  const Profile paper = paperProfile();
  EXPECT_EQ(stepsOff(paper.tracker.steps).size(), names.size()) << "the paper profile has them all off";
}

TEST(TrackerSteps, StepsOffRoundTripsInTheSwitchesOrderAndRefusesAnUnknownName)
{
  const TrackerSteps s = stepsWithOff({ "box_fit", "fragments", "box_fit" });
  EXPECT_FALSE(s.box_fit);
  EXPECT_FALSE(s.fragments);
  EXPECT_TRUE(s.duplicates);
  EXPECT_EQ(stepsOff(s), (std::vector<std::string>{ "fragments", "box_fit" })) << "trackerStepSwitches()' order";
  EXPECT_EQ(stepsOff(stepsWithOff(stepsOff(s))), stepsOff(s));
  EXPECT_TRUE(stepsOff(stepsWithOff({})).empty());
  try
  {
    stepsWithOff({ "fragments", "fragmnets" });
    FAIL() << "a misspelt step accepted";
  }
  catch (const ParameterError& e)
  {
    EXPECT_EQ(e.parameter(), "tracker_steps_off");
    EXPECT_NE(std::string(e.what()).find("fragmnets"), std::string::npos) << e.what();
  }
  // Read and written through forEachParam() as the list of names.
  TrackerParams p;
  forEachParam(p, [](const std::string& name, auto& value, const ParamDoc&) {
    if constexpr (std::is_same_v<std::decay_t<decltype(value)>, std::vector<std::string>>)
      if (name == "tracker_steps_off") value = { "walked", "manoeuvres" };
  });
  EXPECT_FALSE(p.steps.walked);
  EXPECT_FALSE(p.steps.manoeuvres);
  std::vector<std::string> written;
  forEachParam(p, [&](const std::string& name, auto& value, const ParamDoc&) {
    if constexpr (std::is_same_v<std::decay_t<decltype(value)>, std::vector<std::string>>)
      if (name == "tracker_steps_off") written = value;
  });
  EXPECT_EQ(written, (std::vector<std::string>{ "walked", "manoeuvres" }));
}

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
  const auto bus = boxOutline(40.0, -10.0, 0.0, 12.0, 2.5);  // a bus is an object, shorter than max_object_length
  pts.insert(pts.end(), bus.begin(), bus.end());
  const auto m = clusterReturns(pts, p);
  ASSERT_EQ(m.size(), 3u);
  auto near = [&](double x) -> const Measurement& {
    return *std::min_element(m.begin(), m.end(), [&](const Measurement& a, const Measurement& b) {
      return std::abs(a.centroid.x - x) < std::abs(b.centroid.x - x);
    });
  };
  const Measurement& car = near(10.0);
  const Measurement& walker = near(20.0);
  EXPECT_NEAR(near(40.0).length, 12.0, 0.15);
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
  Measurement nan_yaw = at(4, 4);
  nan_yaw.yaw = std::nan("");
  Measurement huge_box = withExtent(at(5, 5), 1.0, 1.0);
  huge_box.hi_u = 1e300;  // a box no object has: its middle would overflow
  Measurement nan_sensor = at(6, 6);
  nan_sensor.has_sensor = true;
  nan_sensor.sensor.x = std::nan("");
  Measurement negative_definite = at(7, 7);
  negative_definite.covariance = -negative_definite.covariance;  // determinant > 0: fuzz_tracker's second find
  Measurement asymmetric = at(8, 8);
  asymmetric.covariance(0, 1) = 0.01;
  tracker.update(0.0, { nan_centroid, singular, inf_cov, nan_yaw, huge_box, nan_sensor, negative_definite, asymmetric,
                        at(3, 3) });
  ASSERT_EQ(tracker.tracks().size(), 1u);
  EXPECT_EQ(tracker.counts().non_finite_inputs, 8u);
  const std::vector<float> xy{ std::nanf(""), 0.0f };
  tracker.update(0.1, Pose2{ 0, 0, std::nan("") }, ObstaclePoints{ xy.data(), 1 });
  tracker.update(0.2, Pose2{ 0, 0, 0 }, ObstaclePoints{ xy.data(), 1 });
  EXPECT_EQ(tracker.counts().non_finite_inputs, 10u);
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
  backgroundFlags(Pose2{ 10.0, 0.0, M_PI / 2 }, ObstaclePoints{ xy.data(), 4 }, [&](Point2 p) { return zeta(p) > 0.2; },
                  flags);
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
  // Step track box: the cells whose centre lies in the cluster's box (16.4 ± 2 m by 5 ± 1 m) and hold no return.
  std::set<std::size_t> expected_interior;
  for (int cy = 0; cy < g.height; ++cy)
    for (int cx = 0; cx < g.width; ++cx)
    {
      const Point2 q = g.cellCentre(CellIndex{ cx, cy });
      if (std::abs(q.x - 16.4) <= 2.0 && std::abs(q.y - 5.0) <= 1.0 && !expected.count(g.index(CellIndex{ cx, cy })))
        expected_interior.insert(g.index(CellIndex{ cx, cy }));
    }
  ASSERT_FALSE(expected_interior.empty());
  std::set<std::size_t> got, got_interior;
  for (const CellMotion& c : cells)
  {
    (c.interior ? got_interior : got).insert(c.cell);
    EXPECT_EQ(c.motion, CellClass::kMoving);
    EXPECT_NEAR(c.weight, 0.8 * p, 1e-6);
  }
  EXPECT_EQ(got, expected);
  EXPECT_EQ(got_interior, expected_interior);
  EXPECT_EQ(got.size() + got_interior.size(), cells.size()) << "one entry per cell";
  TrackerParams no_box;
  no_box.steps.track_box = false;
  Tracker returns_only(no_box);
  for (int k = 0; k <= 8; ++k)
  {
    std::vector<float> car;
    for (const Point2& q : boxOutline(10.0 + 0.8 * k, 5.0, 0.0, 4.0, 2.0))
    {
      car.push_back(static_cast<float>(q.x));
      car.push_back(static_cast<float>(q.y));
    }
    returns_only.update(0.1 * k, Pose2{ 0.0, 0.0, 0.0 }, ObstaclePoints{ car.data(), car.size() / 2 });
  }
  EXPECT_EQ(trackEvidence(returns_only, g).size(), expected.size());
  TrackerParams off;
  off.steps.track_evidence = false;
  Tracker silent(off);
  silent.update(0.0, Pose2{}, ObstaclePoints{ xy.data(), xy.size() / 2 });
  EXPECT_TRUE(trackEvidence(silent, g).empty());
  TrackerParams weightless;
  weightless.evidence_weight = 0.0;
  Tracker weightless_tracker(weightless);
  weightless_tracker.update(0.0, Pose2{}, ObstaclePoints{ xy.data(), xy.size() / 2 });
  EXPECT_TRUE(trackEvidence(weightless_tracker, g).empty());
}

namespace {

/// A ScanGrid of 60 × 60 m at 0.5 m centred on the vehicle: m(F) = 0.7 where @p free(vehicle-frame cell centre),
/// m(O) = 0.8 in the cells holding @p returns (vehicle frame), vacuous elsewhere.
template <class Free>
ScanMassGrid scanGrid(const std::vector<float>& returns, Free&& free)
{
  ScanMassGrid grid(GridGeometry::centred(60.0, 60.0, 0.5));
  const GridGeometry& g = grid.geometry();
  for (std::size_t i = 0; i < g.numCells(); ++i)
    grid.setCell(i, free(g.cellCentre(g.cellOf(i))) ? MassSG{ { FrameSG::kF, 0.7 }, { FrameSG::kOmega, 0.3 } }
                                                      : MassSG{ { FrameSG::kOmega, 1.0 } });
  for (std::size_t k = 0; k + 1 < returns.size(); k += 2)
  {
    CellIndex c;
    if (g.worldToCell(Point2{ returns[k], returns[k + 1] }, c))
      grid.setCell(g.index(c), MassSG{ { FrameSG::kO, 0.8 }, { FrameSG::kOmega, 0.2 } });
  }
  return grid;
}

std::vector<float> flatten(const std::vector<Point2>& points)
{
  std::vector<float> xy;
  for (const Point2& p : points)
  {
    xy.push_back(static_cast<float>(p.x));
    xy.push_back(static_cast<float>(p.y));
  }
  return xy;
}

}  // namespace

TEST(SeenFree, ClearMeansEveryCellWithinTheMarginWasSeenFree)
{
  // Free everywhere but one occupied cell at vehicle (2.25, 0.25) and the vacuous half-plane y >= 10.
  const std::vector<float> occupied{ 2.3f, 0.2f };
  const ScanMassGrid scan = scanGrid(occupied, [](Point2 p) { return p.y < 10.0; });
  const Pose2 pose{ 10.0, 0.0, M_PI / 2 };  // vehicle (x, y) is map (10 − y, x)
  auto map = [&](double x, double y) { return Point2{ 10.0 - y, x }; };
  const SeenFree one_cell(scan, pose, 3.0, 0.5);
  EXPECT_DOUBLE_EQ(one_cell.stamp(), 3.0);
  EXPECT_FALSE(one_cell.clear(map(2.25, 0.25))) << "the occupied cell";
  EXPECT_FALSE(one_cell.clear(map(2.75, 0.25))) << "next to it";
  EXPECT_FALSE(one_cell.clear(map(1.75, -0.25))) << "diagonally next to it";
  EXPECT_TRUE(one_cell.clear(map(3.25, 0.25)));
  EXPECT_TRUE(one_cell.clear(map(-3.0, 9.25)));
  EXPECT_FALSE(one_cell.clear(map(-3.0, 9.75))) << "next to space not seen";
  EXPECT_FALSE(one_cell.clear(map(-3.0, 12.0))) << "not seen";
  EXPECT_FALSE(one_cell.clear(map(40.0, 0.0))) << "outside the grid";
  EXPECT_FALSE(one_cell.clear(Point2{ std::nan(""), 0.0 }));
  EXPECT_DOUBLE_EQ(one_cell.clearShare({ map(2.25, 0.25), map(3.25, 0.25), map(5.0, 5.0), map(0.0, 20.0) }), 0.5);
  EXPECT_DOUBLE_EQ(one_cell.clearShare({}), 0.0);
  // Margin 0: the cell itself; 0.6 m rounds up to two cells.
  const SeenFree own_cell(scan, pose, 3.0, 0.0);
  EXPECT_FALSE(own_cell.clear(map(2.25, 0.25)));
  EXPECT_TRUE(own_cell.clear(map(2.75, 0.25)));
  EXPECT_TRUE(own_cell.clear(map(-3.0, 9.75)));
  // A second, smaller margin answers clear(p, true); the first answers clear(p) and counts the clear cells.
  const SeenFree both(scan, pose, 3.0, 0.5, 0.0);
  EXPECT_FALSE(both.clear(map(2.75, 0.25)));
  EXPECT_TRUE(both.clear(map(2.75, 0.25), true));
  EXPECT_FALSE(both.clear(map(2.25, 0.25), true)) << "the occupied cell";
  EXPECT_DOUBLE_EQ(both.clearShare({ map(2.75, 0.25), map(2.25, 0.25) }, true), 0.5);
  EXPECT_EQ(both.clearCells(), one_cell.clearCells());
  EXPECT_FALSE(one_cell.clear(map(2.75, 0.25), true)) << "without a small margin, the margin";
  const SeenFree two_cells(scan, pose, 3.0, 0.6);
  EXPECT_FALSE(two_cells.clear(map(3.25, 0.25)));
  EXPECT_TRUE(two_cells.clear(map(3.75, 0.25)));
  // Clear cells: 120 × 120 minus the 40 rows from y = 10 on, the margin's row before them, and the 3 × 3 block.
  EXPECT_EQ(one_cell.clearCells(), 120u * 120u - 40u * 120u - 120u - 9u);
}

TEST(SeenFree, EveryMarginAndGridShapeMatchesTheDefinitionCellByCell)
{
  // Random patches of free space on grids of odd shapes, margins from 0 to 12 cells (both ways of finding a row's
  // neighbourhood, and margins wider than the grid): clear(p) at each cell centre is, by definition, every cell within
  // the margin (square, inside the grid) having m(F) ≥ kSeenFreeMass.
  std::mt19937 rng(7);
  for (int trial = 0; trial < 200; ++trial)
  {
    const int w = 1 + static_cast<int>(rng() % 37), h = 1 + static_cast<int>(rng() % 29);
    const double res = 0.5;
    ScanMassGrid scan(GridGeometry::centred(w * res, h * res, res));
    const GridGeometry& g = scan.geometry();
    ASSERT_EQ(g.width, w);
    ASSERT_EQ(g.height, h);
    // Half the grids have a few blocked cells only, so that wide margins leave clear cells and their edges.
    const unsigned blocked_permille = trial % 2 ? static_cast<unsigned>(rng() % 400) : static_cast<unsigned>(rng() % 8);
    std::vector<char> free(g.numCells());
    for (std::size_t i = 0; i < g.numCells(); ++i)
    {
      free[i] = rng() % 1000 >= blocked_permille;
      const float m = free[i] ? (rng() % 2 ? SeenFree::kSeenFreeMass : 0.9f) : (rng() % 2 ? 0.49f : 0.0f);
      scan.setCell(i, MassSG{ { FrameSG::kF, m }, { FrameSG::kOmega, 1.0 - m } });
    }
    const int r = static_cast<int>(rng() % 13);
    const int small = static_cast<int>(rng() % 13);
    const SeenFree seen(scan, Pose2{ 0.0, 0.0, 0.0 }, 1.0, r * res, small * res);
    std::size_t clear = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
      {
        auto within = [&](int k) {
          for (int yy = std::max(0, y - k); yy <= std::min(h - 1, y + k); ++yy)
            for (int xx = std::max(0, x - k); xx <= std::min(w - 1, x + k); ++xx)
              if (!free[static_cast<std::size_t>(yy) * w + xx]) return false;
          return true;
        };
        const Point2 centre = g.cellCentre(CellIndex{ x, y });
        ASSERT_EQ(seen.clear(centre), within(r)) << "cell " << x << ", " << y << " of " << w << " x " << h << ", margin " << r;
        ASSERT_EQ(seen.clear(centre, true), within(small)) << "small margin " << small;
        clear += within(r);
      }
    EXPECT_EQ(seen.clearCells(), clear);
  }
}

TEST(Tracker, FreeSpaceCheckTellsAMoverFromAWallFragmentThatSlidesAlong)
{
  // Vehicle frame = map frame. A 4 × 2 m car at 5 m/s along y = 5 over free road; a 1 m piece of a wall along y = 15
  // (all that is seen of it) whose visible part slides at 5 m/s as if the view changed, space behind the wall not seen.
  auto run = [](bool check, std::uint32_t& car_moving_from, bool& wall_moving) {
    TrackerParams p;
    p.steps.free_space_check = check;
    Tracker tracker(p);
    car_moving_from = 0;
    wall_moving = false;
    for (int k = 0; k <= 15; ++k)
    {
      std::vector<Point2> car = boxOutline(-10.0 + 0.5 * k, 5.0, 0.0, 4.0, 2.0);
      std::vector<Point2> wall;
      for (int j = 0; j <= 20; ++j) wall.push_back(Point2{ -10.0 + 0.5 * k + 0.05 * j, 15.1 });
      for (int j = 0; j <= 20; ++j) wall.push_back(Point2{ -10.0 + 0.5 * k + 0.05 * j, 15.2 });
      std::vector<float> xy = flatten(car);
      const std::vector<float> w = flatten(wall);
      xy.insert(xy.end(), w.begin(), w.end());
      // The car hides nothing the test looks at; the road is seen free up to the wall.
      const ScanMassGrid scan = scanGrid(xy, [](Point2 q) { return q.y < 15.0; });
      tracker.update(0.1 * k, Pose2{}, ObstaclePoints{ xy.data(), xy.size() / 2 }, nullptr, &scan);
      for (const Track& t : tracker.tracks())
      {
        if (t.motion != TrackMotion::kMoving) continue;
        if (t.x(1) > 10.0)
          wall_moving = true;
        else if (!car_moving_from)
          car_moving_from = static_cast<std::uint32_t>(k);
      }
    }
    return tracker.counts().tracks_created;
  };
  std::uint32_t car_from = 0;
  bool wall = false;
  EXPECT_EQ(run(true, car_from, wall), 2u);
  EXPECT_FALSE(wall) << "a sliding view of a wall is not a mover";
  EXPECT_GE(car_from, static_cast<std::uint32_t>(TrackerParams{}.confirm_hits - 1)) << "tentative before";
  EXPECT_LE(car_from, 6u) << "the car is moving within half a second";
  std::uint32_t car_without = 0;
  EXPECT_EQ(run(false, car_without, wall), 2u);
  EXPECT_TRUE(wall) << "without the check, the velocity alone calls the wall fragment moving";
  EXPECT_LE(car_without, 6u);
  // Without a ScanGrid (update(stamp, measurements) or no scan given), the motion comes from the velocity alone.
  Tracker no_scan;
  for (int k = 0; k <= 8; ++k) no_scan.update(0.1 * k, { at(8.0 * 0.1 * k, 0.0) });
  ASSERT_EQ(no_scan.tracks().size(), 1u);
  EXPECT_EQ(no_scan.tracks()[0].motion, TrackMotion::kMoving);
}

namespace {

/// The first scan from which the track of a 4 × 2 m car driving along y = 5 at @p speed over road seen free is
/// moving (-1 if never within 2 s), with a ScanGrid (the free-space check runs) or without one (velocity alone); the
/// track's speed and its standard deviation at that scan.
int carMovingFrom(const TrackerParams& params, double speed, bool with_scan, double& s, double& sigma)
{
  Tracker tracker(params);
  for (int k = 0; k < 20; ++k)
  {
    const std::vector<float> xy = flatten(boxOutline(-10.0 + speed * 0.1 * k, 5.0, 0.0, 4.0, 2.0));
    const ScanMassGrid scan = scanGrid(xy, [](Point2 q) { return q.y < 15.0; });
    tracker.update(0.1 * k, Pose2{}, ObstaclePoints{ xy.data(), xy.size() / 2 }, nullptr, with_scan ? &scan : nullptr);
    EXPECT_LE(tracker.tracks().size(), 1u);
    if (!tracker.tracks().empty() && tracker.tracks()[0].motion == TrackMotion::kMoving)
    {
      s = tracker.tracks()[0].speed();
      sigma = tracker.tracks()[0].speedSigma();
      return k;
    }
  }
  return -1;
}

}  // namespace

TEST(Tracker, FreeSpaceMotionSigmasApplyOnlyWhileTheCheckRuns)
{
  TrackerParams p;
  ASSERT_DOUBLE_EQ(kFreeSpaceMotionSigmas, 0.5);
  ASSERT_DOUBLE_EQ(p.motion_sigmas, 1.5);
  // Placed by its open rear end (step open anchor), the car's speed is certain enough for both thresholds by the
  // scan free space shows its motion: without that step the scene tells them apart.
  p.steps.open_anchor = false;
  double s = 0.0, sigma = 0.0;
  const int relaxed = carMovingFrom(p, 1.5, true, s, sigma);
  ASSERT_GE(relaxed, 0);
  EXPECT_GT(s - kFreeSpaceMotionSigmas * sigma, p.moving_speed);
  EXPECT_LE(s - p.motion_sigmas * sigma, p.moving_speed) << "moving while motion_sigmas would not yet clear";
  // Without a ScanGrid the velocity alone decides, with motion_sigmas: later.
  const int alone = carMovingFrom(p, 1.5, false, s, sigma);
  ASSERT_GE(alone, 0);
  EXPECT_GT(alone, relaxed) << "motion_sigmas standard deviations take longer";
  EXPECT_GT(s - p.motion_sigmas * sigma, p.moving_speed);
}

namespace {

/// The first scan from which the track of a small object walking along x at @p speed (from x = -2, returns at
/// y = 5.1 … 5.4, every 0.1 m over 0.4 m along x, or a single row at y = 5.3 with @p sliver) is moving, -1 if never
/// within 2 s. Free space is seen up to y = 5.5 only (beyond: a facade's shadow), so that every cell of the object
/// lies next to space not seen.
int walkBesideAFacade(const TrackerParams& params, double speed, bool sliver)
{
  Tracker tracker(params);
  for (int k = 0; k < 20; ++k)
  {
    const double x0 = -2.0 + speed * 0.1 * k;
    std::vector<Point2> points;
    for (int i = 0; i <= 12; ++i)
    {
      if (sliver)
        points.push_back(Point2{ x0 + 0.4 * i / 12.0, 5.3 });
      else if (i <= 4)
        for (const double y : { 5.1, 5.2, 5.3, 5.4 }) points.push_back(Point2{ x0 + 0.1 * i, y });
    }
    const std::vector<float> xy = flatten(points);
    const ScanMassGrid scan = scanGrid(xy, [](Point2 q) { return q.y < 5.5; });
    tracker.update(0.1 * k, Pose2{}, ObstaclePoints{ xy.data(), xy.size() / 2 }, nullptr, &scan);
    EXPECT_LE(tracker.tracks().size(), 1u);
    if (!tracker.tracks().empty() && tracker.tracks()[0].motion == TrackMotion::kMoving) return k;
  }
  return -1;
}

}  // namespace

TEST(Tracker, SmallFreeSpaceLetsAPedestrianBesideAFacadeMove)
{
  TrackerParams p;
  ASSERT_DOUBLE_EQ(kSmallFreeSpaceMargin, 0.0);
  ASSERT_DOUBLE_EQ(kSmallMinExtent, 0.1);
  const int from = walkBesideAFacade(p, 1.4, false);
  EXPECT_GE(from, p.confirm_hits - 1) << "tentative before";
  EXPECT_LE(from, 10) << "a pedestrian at 1.4 m/s is moving within a second";
  TrackerParams off = p;
  off.steps.small_free_space = false;
  EXPECT_EQ(walkBesideAFacade(off, 1.4, false), -1) << "the general margin never sees its cells free";
  // 3 m/s: at 2.5 m/s the speed estimated from the first three scans is still under the 2 m/s cap when the track is
  // confirmed, and that first check passes.
  EXPECT_EQ(walkBesideAFacade(p, 3.0, false), -1) << "faster than a walk: the general margin";
  EXPECT_EQ(walkBesideAFacade(p, 1.4, true), -1) << "a sliver thinner than the least extent: the general margin";
}

namespace {

/// A 4 × 2 m car driving along y = 0 at @p speed (m/s) for 12 scans, seen whole from the origin, and from scan 6 on
/// a second cluster (a 0.3 × 0.3 m block of returns) riding along with it @p offset m beside its side (its centre at
/// y = 1 + offset). Returns the tracker after the last scan.
Tracker carWithACompanion(const TrackerParams& params, double speed, double offset)
{
  Tracker tracker(params);
  for (int k = 0; k < 12; ++k)
  {
    const double x = 10.0 + speed * 0.1 * k;
    std::vector<Point2> points = boxOutline(x, 0.0, 0.0, 4.0, 2.0);
    if (k >= 6)
      for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) points.push_back(Point2{ x - 0.15 + 0.1 * i, 1.0 + offset - 0.15 + 0.1 * j });
    const std::vector<float> xy = flatten(points);
    tracker.update(0.1 * k, Pose2{}, ObstaclePoints{ xy.data(), xy.size() / 2 });
  }
  return tracker;
}

}  // namespace

TEST(Tracker, FragmentsOfAMovingTrackStartNoTrack)
{
  TrackerParams p;
  ASSERT_DOUBLE_EQ(kFragmentMargin, 1.0);
  // 0.8 m beside the moving car's side (its box grown by 1 m): a fragment, no track of its own, counted.
  const Tracker beside = carWithACompanion(p, 8.0, 0.8);
  ASSERT_EQ(beside.tracks().size(), 1u);
  EXPECT_EQ(beside.tracks()[0].motion, TrackMotion::kMoving);
  EXPECT_EQ(beside.counts().fragments, 6u) << "one per scan from scan 6";
  EXPECT_EQ(beside.counts().tracks_created, 1u);
  // The step off (and step duplicates, which deletes the second track once both move): a second track.
  TrackerParams off = p;
  off.steps.fragments = false;
  off.steps.duplicates = false;
  const Tracker without = carWithACompanion(off, 8.0, 0.8);
  EXPECT_EQ(without.tracks().size(), 2u);
  EXPECT_EQ(without.counts().fragments, 0u);
  // 1.4 m beside it (beyond the margin), or beside a parked car (no moving track): a track of its own.
  EXPECT_EQ(carWithACompanion(p, 8.0, 1.4).tracks().size(), 2u);
  const Tracker parked = carWithACompanion(p, 0.0, 0.8);
  EXPECT_EQ(parked.tracks().size(), 2u);
  EXPECT_EQ(parked.counts().fragments, 0u);
}

TEST(Tracker, FreeSpaceParametersAreValidatedByName)
{
  expectRefusedByName({
      { "tracker_pedestrian_size", [](TrackerParams& p) { p.pedestrian_size = 0.0; } },
      { "tracker_pedestrian_size", [](TrackerParams& p) { p.pedestrian_size = 1e3; } },
      { "tracker_pedestrian_size", [](TrackerParams& p) { p.pedestrian_size = std::nan(""); } },
      { "tracker_free_space_share", [](TrackerParams& p) { p.free_space_share = 0.0; } },
      { "tracker_free_space_share", [](TrackerParams& p) { p.free_space_share = 1.5; } },
      { "tracker_free_space_margin", [](TrackerParams& p) { p.free_space_margin = -0.1; } },
      { "tracker_free_space_time", [](TrackerParams& p) { p.free_space_time = 0.0; } },
      { "tracker_free_space_time", [](TrackerParams& p) { p.free_space_time = std::nan(""); } } });
}

namespace {

/// A box of @p length × @p width driving at 5 m/s from (10, 0) past a sensor at the origin, straight for 1 s, then
/// turning by @p turn_deg per scan for 8 scans, then straight again: 3 s at 10 Hz, the whole outline seen. Returns
/// the ids of the track followed (the one nearest the object) scan after scan, and that track at the end.
std::vector<std::uint32_t> driveAndTurn(const TrackerParams& params, double length, double width, double turn_deg,
                                        Track& last)
{
  Tracker tracker(params);
  std::vector<std::uint32_t> ids;
  double x = 10.0, y = 0.0, heading = 0.0;
  constexpr double kSpeed = 5.0, kDt = 0.1;
  for (int k = 0; k < 30; ++k)
  {
    if (k >= 10 && k < 18) heading += turn_deg * M_PI / 180.0;
    x += kSpeed * kDt * std::cos(heading);
    y += kSpeed * kDt * std::sin(heading);
    std::vector<float> xy;
    for (const Point2& p : boxOutline(x, y, heading, length, width))
    {
      xy.push_back(static_cast<float>(p.x));
      xy.push_back(static_cast<float>(p.y));
    }
    tracker.update(kDt * k, Pose2{ 0.0, 0.0, 0.0 }, ObstaclePoints{ xy.data(), xy.size() / 2 });
    const Track* nearest = nullptr;
    for (const Track& t : tracker.tracks())
      if (!nearest || std::hypot(t.x(0) - x, t.x(1) - y) < std::hypot(nearest->x(0) - x, nearest->x(1) - y))
        nearest = &t;
    if (nearest && k >= 3) ids.push_back(nearest->id);
    if (nearest) last = *nearest;
  }
  return ids;
}

}  // namespace

TEST(Tracker, HeadingBoxTurnsTheBoxOfAShortObjectThatTurns)
{
  TrackerParams on, off;
  off.steps.heading_box = false;
  Track with, without;
  // A cyclist (1.6 × 0.6 m) turning by 48° in all.
  const std::vector<std::uint32_t> ids = driveAndTurn(on, 1.6, 0.6, 6.0, with);
  driveAndTurn(off, 1.6, 0.6, 6.0, without);
  ASSERT_FALSE(ids.empty());
  for (const std::uint32_t id : ids) EXPECT_EQ(id, ids.front()) << "one id all along";
  EXPECT_EQ(with.motion, TrackMotion::kMoving);
  // Its box turned with it: its axes within kHeadingBoxAngleDeg of the heading (48°), so its width is at most that of
  // the outline seen that much askew, 0.6 cos a + 1.6 sin a (plus the outline's 0.1 m spacing).
  const double a = kHeadingBoxAngleDeg * M_PI / 180.0;
  const double askew_width = 0.6 * std::cos(a) + 1.6 * std::sin(a) + 0.1;
  EXPECT_LE(std::abs(std::remainder(with.extent_yaw - 48.0 * M_PI / 180.0, 0.5 * M_PI)), a + 1e-9);
  EXPECT_LE(std::min(with.extent_length, with.extent_width), askew_width);
  EXPECT_NEAR(std::max(with.extent_length, with.extent_width), 1.6, 0.25);
  // Without the step the box keeps its first axes and grows wider than that to hold the outline.
  EXPECT_NEAR(std::remainder(without.extent_yaw, 0.5 * M_PI), 0.0, 0.05);
  EXPECT_GT(std::min(without.extent_length, without.extent_width), askew_width);
}

TEST(Tracker, HeadingBoxLeavesTheBoxOfALongObjectAlone)
{
  TrackerParams on;
  Track van;
  // A van (5 × 2 m), longer than kHeadingBoxMaxLength and shorter than kLongBoxMinLength: its box keeps the axes
  // of its first cluster.
  driveAndTurn(on, 5.0, 2.0, 6.0, van);
  EXPECT_NEAR(std::remainder(van.extent_yaw, 0.5 * M_PI), 0.0, 0.05);
}

// Step long box: a bus (12 × 2.5 m) pulling out by 16° keeps the axes of its first cluster without the step, and its
// box swells to hold the bus askew; with it the box turns to the bus's long cluster and keeps the bus's size.
TEST(Tracker, LongBoxTurnsTheBoxOfABusThatTurns)
{
  TrackerParams on, off;
  ASSERT_TRUE(on.steps.long_box);
  ASSERT_LT(kLongBoxMinLength, 12.0);
  ASSERT_GT(12.0, kHeadingBoxMaxLength) << "the bus is not step heading box's";
  off.steps.long_box = false;
  Track with, without;
  constexpr double kTurn = 16.0;
  const std::vector<std::uint32_t> ids = driveAndTurn(on, 12.0, 2.5, kTurn / 8.0, with);
  driveAndTurn(off, 12.0, 2.5, kTurn / 8.0, without);
  ASSERT_FALSE(ids.empty());
  for (const std::uint32_t id : ids) EXPECT_EQ(id, ids.front()) << "one id all along";
  EXPECT_EQ(with.motion, TrackMotion::kMoving);
  // Its axes within 0.1 rad (the smallest turn) of the bus's, so its width at most that of the bus seen that much
  // askew (plus the outline's 0.1 m spacing).
  constexpr double kSmallestTurn = 0.1;
  EXPECT_LE(std::abs(std::remainder(with.extent_yaw - kTurn * M_PI / 180.0, 0.5 * M_PI)), kSmallestTurn + 1e-9);
  EXPECT_LE(std::min(with.extent_length, with.extent_width),
            2.5 * std::cos(kSmallestTurn) + 12.0 * std::sin(kSmallestTurn) + 0.1);
  EXPECT_NEAR(std::max(with.extent_length, with.extent_width), 12.0, 0.5);
  // Without the step: the first axes, and a box as wide as the bus seen 16° askew.
  const double a = kTurn * M_PI / 180.0, askew_width = 2.5 * std::cos(a) + 12.0 * std::sin(a);
  EXPECT_NEAR(std::remainder(without.extent_yaw, 0.5 * M_PI), 0.0, 0.05);
  EXPECT_GT(std::min(without.extent_length, without.extent_width), askew_width - 0.2);
}

namespace {

/// The cells of track evidence of a face (@p width m wide across y = 5, two rows of returns every 0.1 m) that drives along x at
/// 8 m/s for 9 scans from @p x0 (direction @p dir, ±1), seen from the origin; @p face_x receives its last x.
/// The tracker of faceEvidence()'s drive.
Tracker faceTracker(const TrackerParams& params, double x0, double dir, double width, double& face_x)
{
  Tracker tracker(params);
  for (int k = 0; k <= 8; ++k)
  {
    face_x = x0 + dir * 0.8 * k;
    std::vector<float> xy;
    for (double y = 5.0 - 0.5 * width; y <= 5.0 + 0.5 * width + 1e-9; y += 0.1)
      for (const double dx : { 0.0, 0.05 })
      {
        xy.push_back(static_cast<float>(face_x + dx));
        xy.push_back(static_cast<float>(y));
      }
    tracker.update(0.1 * k, Pose2{ 0.0, 0.0, 0.0 }, ObstaclePoints{ xy.data(), xy.size() / 2 });
  }
  return tracker;
}

std::vector<CellMotion> faceEvidence(const TrackerParams& params, const GridGeometry& g, double x0, double dir,
                                     double width, double& face_x)
{
  const Tracker tracker = faceTracker(params, x0, dir, width, face_x);
  EXPECT_EQ(tracker.tracks().size(), 1u);
  if (tracker.tracks().size() != 1u) return {};
  EXPECT_EQ(tracker.tracks()[0].motion, TrackMotion::kMoving);
  return trackEvidence(tracker, g);
}

/// How many of @p cells lie, by their centre, with x in [x_lo, x_hi] and y within @p half of 5.
std::size_t cellsIn(const std::vector<CellMotion>& cells, const GridGeometry& g, double x_lo, double x_hi, double half)
{
  std::size_t n = 0;
  for (const CellMotion& c : cells)
  {
    const Point2 q = g.cellCentre(g.cellOf(c.cell));
    n += q.x >= x_lo && q.x <= x_hi && std::abs(q.y - 5.0) <= half;
  }
  return n;
}

}  // namespace

TEST(Tracker, HiddenLengthExtendsTheBoxOfAVehicleSeenEndOnAwayFromTheSensor)
{
  const GridGeometry g{ 0.5, 200, 200, -50.0, -50.0 };
  TrackerParams p;
  const double len = p.vehicle_length, margin = 0.3;  // cells well inside or well outside, at 0.5 m
  // The body lies away from the sensor (at the origin: +x) behind a rear face (the vehicle drives away) and behind a
  // front face (it drives towards the sensor): every cell of the 4 m × 1.8 m box.
  for (const double dir : { 1.0, -1.0 })
  {
    double face = 0.0;
    const auto cells = faceEvidence(p, g, dir > 0 ? 10.0 : 30.0, dir, 1.8, face);
    const double far_lo = face + margin, far_hi = face + len - margin;
    // Cell centres every 0.5 m in [far_lo, far_hi] along x, and the two rows within 0.5 m of y = 5 (4.75, 5.25).
    const std::size_t inside = static_cast<std::size_t>(std::floor(far_hi / 0.5 - 0.5) - std::ceil(far_lo / 0.5 - 0.5) + 1) * 2;
    EXPECT_GE(cellsIn(cells, g, far_lo, far_hi, 0.5), inside) << "direction " << dir;
    // Nothing beyond the length, nothing on the sensor's side of the face.
    EXPECT_EQ(cellsIn(cells, g, face + len + margin, 1e9, 5.0), 0u) << "direction " << dir;
    EXPECT_EQ(cellsIn(cells, g, -1e9, face - margin, 5.0), 0u) << "direction " << dir;
    for (const CellMotion& c : cells) EXPECT_EQ(c.motion, CellClass::kMoving);
  }
  // A face narrower than kVehicleMinEndWidth (a cyclist's), or the step off: the box is the face only (without step
  // small box, which grows a face this small to a pedestrian's size).
  double face = 0.0;
  TrackerParams no_small_box = p;
  no_small_box.steps.small_box = false;
  const auto narrow = faceEvidence(no_small_box, g, 10.0, 1.0, 0.6, face);
  EXPECT_FALSE(narrow.empty());
  EXPECT_EQ(cellsIn(narrow, g, face + margin, 1e9, 5.0), 0u);
  TrackerParams off;
  off.steps.hidden_length = false;
  const auto without = faceEvidence(off, g, 10.0, 1.0, 1.8, face);
  EXPECT_FALSE(without.empty());
  EXPECT_EQ(cellsIn(without, g, face + margin, 1e9, 5.0), 0u) << "step off";
}

namespace {

/// A car's rear face (1.8 m wide across y = 5, two rows of returns every 0.1 m) driving away from the sensor at the
/// origin along +x at 8 m/s for 14 scans from x = 10, and from scan 1 on (before the face's track is confirmed) a
/// block of 4 × 4 returns (0.3 × 0.3 m, on
/// y = 5) @p ahead m beyond the face that slides back by 0.1 m a scan (7 m/s: a lidar ring along the roof when
/// @p ahead is within the car). @p ring_cell receives the cell of @p g under the block's centre in the last scan.
Tracker faceAndRing(const TrackerParams& params, double ahead, const GridGeometry& g, std::size_t& ring_cell)
{
  Tracker tracker(params);
  for (int k = 0; k < 14; ++k)
  {
    const double face_x = 10.0 + 0.8 * k;
    std::vector<Point2> points;
    for (double y = 4.1; y <= 5.9 + 1e-9; y += 0.1)
      for (const double dx : { 0.0, 0.05 }) points.push_back(Point2{ face_x + dx, y });
    const double ring_x = face_x + ahead - 0.1 * k;
    if (k >= 1)
      for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) points.push_back(Point2{ ring_x - 0.15 + 0.1 * i, 5.0 - 0.15 + 0.1 * j });
    ring_cell = g.index(g.cellAt(Point2{ ring_x, 5.0 }));
    const std::vector<float> xy = flatten(points);
    tracker.update(0.1 * k, Pose2{}, ObstaclePoints{ xy.data(), xy.size() / 2 });
  }
  return tracker;
}

}  // namespace

TEST(Tracker, DuplicatesLeaveOneTrackPerObjectAndTheirReturnsTakeItsMotion)
{
  const GridGeometry g{ 0.5, 200, 200, -50.0, -50.0 };
  TrackerParams p;
  ASSERT_TRUE(p.steps.duplicates);
  ASSERT_DOUBLE_EQ(kFragmentMargin, 1.0);
  std::size_t ring_cell = 0;
  // The block 2.5 m beyond the face lies in the car's object box (step hidden length: 4 m away from the sensor
  // behind its face): its track is deleted once both move, and from then on the block is the car's fragment, outside
  // the face's own box (0.05 m deep) and its margin.
  const Tracker one = faceAndRing(p, 2.5, g, ring_cell);
  ASSERT_EQ(one.tracks().size(), 1u);
  const Track& car = one.tracks()[0];
  EXPECT_EQ(car.id, 1u) << "the track with more hits keeps the object";
  EXPECT_EQ(car.motion, TrackMotion::kMoving);
  EXPECT_EQ(one.counts().duplicates, 1u);
  EXPECT_EQ(one.counts().tracks_created, 2u) << "the block starts no track after its duplicate is deleted";
  EXPECT_GT(one.counts().fragments, 0u);
  ASSERT_EQ(car.fragments.size(), 1u) << "the block, in the last scan";
  EXPECT_EQ(one.measurements()[car.fragments[0]].points, 16);
  // Its returns take the car's motion and β, as the car's own returns (not as box cells).
  const std::vector<CellMotion> cells = trackEvidence(one, g);
  const auto ring = std::find_if(cells.begin(), cells.end(), [&](const CellMotion& c) { return c.cell == ring_cell; });
  ASSERT_NE(ring, cells.end());
  EXPECT_EQ(ring->motion, CellClass::kMoving);
  EXPECT_FALSE(ring->interior);
  EXPECT_FLOAT_EQ(ring->weight, static_cast<float>(p.evidence_weight * motionProbability(car, p)));
  // The step off: two moving tracks on one car.
  TrackerParams off = p;
  off.steps.duplicates = false;
  const Tracker two = faceAndRing(off, 2.5, g, ring_cell);
  ASSERT_EQ(two.tracks().size(), 2u);
  for (const Track& t : two.tracks()) EXPECT_EQ(t.motion, TrackMotion::kMoving);
  EXPECT_EQ(two.counts().duplicates, 0u);
  // 6.5 m beyond the face (a car ahead: past the 4 m box and its 1 m margin): its own track.
  const Tracker ahead = faceAndRing(p, 6.5, g, ring_cell);
  EXPECT_EQ(ahead.tracks().size(), 2u);
  EXPECT_EQ(ahead.counts().duplicates, 0u);
}

TEST(Tracker, HiddenCentreReportsTheVehicleBehindItsFace)
{
  TrackerParams p;
  const double len = p.vehicle_length, width = 1.8, depth = 0.05;  // the face's returns: x and x + depth
  constexpr double kTolerance = 0.2;  // m: the filtered position against the last face
  // Driving away (the rear face) and towards the sensor (the front face): the body lies away from the sensor, so
  // the object's centre is half the length behind the face's near side, and its box the hidden length's.
  for (const double dir : { 1.0, -1.0 })
  {
    SCOPED_TRACE("direction " + std::to_string(dir));
    double face = 0.0;
    const Tracker tracker = faceTracker(p, dir > 0 ? 10.0 : 30.0, dir, width, face);
    ASSERT_EQ(tracker.tracks().size(), 1u);
    const Track& t = tracker.tracks()[0];
    ASSERT_EQ(t.motion, TrackMotion::kMoving);
    const ObjectBox b = reportedBox(t, tracker);
    EXPECT_NEAR(b.centre.x, face + 0.5 * len, kTolerance);
    EXPECT_NEAR(b.centre.y, 5.0, kTolerance);
    EXPECT_NEAR(b.length, len, 1e-9);
    EXPECT_NEAR(b.width, width, 1e-3);
    EXPECT_NEAR(std::cos(b.yaw), dir, 1e-3) << "along the heading";
    // The track still follows its face: only what it reports moved.
    EXPECT_NEAR(t.x(0), face + 0.5 * depth, kTolerance);
    const std::vector<ObjectBox> all = reportedBoxes(tracker);
    ASSERT_EQ(all.size(), 1u);
    EXPECT_EQ(all[0].centre.x, b.centre.x);
  }
  // A face narrower than kVehicleMinEndWidth (a cyclist's), or the step off: the track's own position and box.
  auto expectOwnBox = [](const TrackerParams& params, double width) {
    double face = 0.0;
    const Tracker tracker = faceTracker(params, 10.0, 1.0, width, face);
    ASSERT_EQ(tracker.tracks().size(), 1u);
    const Track& t = tracker.tracks()[0];
    const ObjectBox b = reportedBox(t, tracker);
    EXPECT_EQ(b.centre.x, t.x(0));
    EXPECT_EQ(b.centre.y, t.x(1));
    EXPECT_EQ(b.yaw, t.extent_yaw);
    EXPECT_EQ(b.length, t.extent_length);
    EXPECT_EQ(b.width, t.extent_width);
  };
  expectOwnBox(p, 0.6);
  TrackerParams off = p;
  off.steps.hidden_centre = false;
  expectOwnBox(off, width);
}

TEST(Tracker, HiddenCentreKeepsTheLastSeenBoxWhileTheTrackCoasts)
{
  TrackerParams p;
  p.steps.manoeuvres = false;  // the constant-velocity prediction, which the coasting box follows below
  const double len = p.vehicle_length, width = 1.8;
  for (const bool step : { true, false })
  {
    SCOPED_TRACE(step ? "step hidden centre" : "without it");
    TrackerParams params = p;
    params.steps.hidden_centre = step;
    double face = 0.0;
    Tracker tracker = faceTracker(params, 10.0, 1.0, width, face);
    ASSERT_EQ(tracker.tracks().size(), 1u);
    const ObjectBox seen = reportedBox(tracker.tracks()[0], tracker);
    const Point2 seen_at = tracker.tracks()[0].position(), v = tracker.tracks()[0].velocity();
    // A scan without its returns (the sparse lidar missed it): the track coasts on its prediction.
    const std::vector<float> none;
    tracker.update(0.9, Pose2{ 0.0, 0.0, 0.0 }, ObstaclePoints{ none.data(), 0 });
    ASSERT_EQ(tracker.tracks().size(), 1u);
    const Track& t = tracker.tracks()[0];
    ASSERT_EQ(t.state, TrackState::kCoasting);
    ASSERT_EQ(t.measurement, -1);
    ASSERT_EQ(t.motion, TrackMotion::kMoving);
    EXPECT_NEAR(t.x(0) - seen_at.x, 0.1 * v.x, 1e-9) << "the constant-velocity prediction";
    const ObjectBox coast = reportedBox(t, tracker);
    if (step)
    {
      // The box the last sighting reported, moved with the track: no jump back to the face.
      EXPECT_NEAR(seen.centre.x, face + 0.5 * len, 0.2);
      EXPECT_NEAR(coast.centre.x, seen.centre.x + 0.1 * v.x, 1e-9);
      EXPECT_NEAR(coast.centre.y, seen.centre.y + 0.1 * v.y, 1e-9);
      EXPECT_NEAR(coast.yaw, seen.yaw, 1e-9);
      EXPECT_NEAR(coast.length, len, 1e-9);
      EXPECT_NEAR(coast.width, seen.width, 1e-9);
    }
    else
    {
      EXPECT_EQ(coast.centre.x, t.x(0));
      EXPECT_EQ(coast.centre.y, t.x(1));
      EXPECT_EQ(coast.length, t.extent_length);
    }
  }
}

TEST(Tracker, SmallMoversLetTheCellsOfAPedestrianSizedMovingTrackTakeN)
{
  const GridGeometry g{ 0.5, 200, 200, -50.0, -50.0 };
  TrackerParams p;
  auto flags = [&](const TrackerParams& params, double width) {
    double face = 0.0;
    const std::vector<CellMotion> cells = faceEvidence(params, g, 10.0, 1.0, width, face);
    std::size_t take_n = 0;
    for (const CellMotion& c : cells) take_n += c.take_n;
    EXPECT_FALSE(cells.empty());
    return std::pair{ take_n, cells.size() };
  };
  const auto [small, small_cells] = flags(p, 0.6);  // a pedestrian's width, a face 5 cm deep
  EXPECT_EQ(small, small_cells) << "every cell of a moving track within pedestrian_size";
  EXPECT_EQ(flags(p, 1.8).first, 0u) << "a vehicle's face is wider";
  TrackerParams off = p;
  off.steps.small_movers = false;
  EXPECT_EQ(flags(off, 0.6).first, 0u) << "the step off";
  // Step small specialised flags exactly the small mover's cells.
  auto specialised = [&](const TrackerParams& params, double width) {
    double face = 0.0;
    std::size_t n = 0;
    for (const CellMotion& c : faceEvidence(params, g, 10.0, 1.0, width, face))
    {
      EXPECT_TRUE(!c.take_specialised || c.take_n);
      n += c.take_specialised;
    }
    return n;
  };
  EXPECT_EQ(specialised(p, 0.6), small_cells);
  EXPECT_EQ(specialised(p, 1.8), 0u);
  TrackerParams not_specialised = p;
  not_specialised.steps.small_specialised = false;
  EXPECT_EQ(specialised(not_specialised, 0.6), 0u);
}

namespace {

/// The track evidence of a pedestrian's near side (0.6 m wide across y = 0, two rows of returns 5 cm apart along x)
/// seen from the origin, walking along x at 1.5 m/s for 13 scans to x = 11.1 (@p dir 1: away from the sensor, -1:
/// towards it).
std::vector<CellMotion> pedestrianEvidence(const TrackerParams& params, const GridGeometry& g, double dir)
{
  Tracker tracker(params);
  constexpr int kScans = 13;
  constexpr double kLastX = 11.1, kStep = 0.15;
  for (int k = 0; k < kScans; ++k)
  {
    const double x = kLastX - dir * kStep * (kScans - 1 - k);
    std::vector<float> xy;
    for (int j = -3; j <= 3; ++j)
      for (const double dx : { 0.0, 0.05 })
      {
        xy.push_back(static_cast<float>(x + dx));
        xy.push_back(static_cast<float>(0.1 * j));
      }
    tracker.update(0.1 * k, Pose2{ 0.0, 0.0, 0.0 }, ObstaclePoints{ xy.data(), xy.size() / 2 });
  }
  EXPECT_EQ(tracker.tracks().size(), 1u);
  if (tracker.tracks().size() != 1u) return {};
  EXPECT_EQ(tracker.tracks()[0].motion, TrackMotion::kMoving);
  return trackEvidence(tracker, g);
}

/// The centres of @p cells, sorted.
std::vector<std::pair<double, double>> centres(const std::vector<CellMotion>& cells, const GridGeometry& g)
{
  std::vector<std::pair<double, double>> out;
  for (const CellMotion& c : cells)
  {
    const Point2 q = g.cellCentre(g.cellOf(c.cell));
    out.emplace_back(q.x, q.y);
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

TEST(Tracker, SmallBoxCoversThePedestrianBehindItsReturns)
{
  const GridGeometry g{ 0.5, 200, 200, -50.0, -50.0 };  // cell centres at x, y = k/2 + 1/4
  TrackerParams p;
  ASSERT_DOUBLE_EQ(p.pedestrian_size, 1.0);
  // The returns (x in [11.1, 11.15], |y| <= 0.3) lie in the cells centred at (11.25, ±0.25). The box grows away from
  // the sensor to x = 11.1 + 1 and across to |y| <= 0.5: it also holds the cells centred at (11.75, ±0.25), not those
  // at x = 12.25 nor at |y| = 0.75. Whether the pedestrian walks away from the sensor or towards it.
  const std::vector<std::pair<double, double>> box{ { 11.25, -0.25 }, { 11.25, 0.25 }, { 11.75, -0.25 }, { 11.75, 0.25 } };
  for (const double dir : { 1.0, -1.0 })
  {
    const std::vector<CellMotion> cells = pedestrianEvidence(p, g, dir);
    EXPECT_EQ(centres(cells, g), box) << "direction " << dir;
    for (const CellMotion& c : cells)
    {
      EXPECT_EQ(c.motion, CellClass::kMoving);
      EXPECT_TRUE(c.take_n);
    }
  }
  // The step off: the cells of its returns only (the box of the returns holds no other cell centre).
  TrackerParams off = p;
  off.steps.small_box = false;
  const std::vector<std::pair<double, double>> returns_only{ { 11.25, -0.25 }, { 11.25, 0.25 } };
  EXPECT_EQ(centres(pedestrianEvidence(off, g, 1.0), g), returns_only);
  // Not for a track larger than pedestrian_size (here 0.5 m, below the 0.6 m width): no small mover.
  TrackerParams half_metre = p;
  half_metre.pedestrian_size = 0.5;
  EXPECT_EQ(centres(pedestrianEvidence(half_metre, g, 1.0), g), returns_only);
}

TEST(Tracker, TrackEvidenceSizeParametersAreValidatedByName)
{
  expectRefusedByName({
      { "tracker_vehicle_length", [](TrackerParams& p) { p.vehicle_length = 0.0; } },
      { "tracker_vehicle_length", [](TrackerParams& p) { p.vehicle_length = 1e3; } },
      { "tracker_vehicle_length", [](TrackerParams& p) { p.vehicle_length = std::nan(""); } },
      { "tracker_evidence_weight", [](TrackerParams& p) { p.evidence_weight = -0.1; } },
      { "tracker_evidence_weight", [](TrackerParams& p) { p.evidence_weight = 1.5; } } });
}

TEST(Tracker, BoxMarginGivesTheMotionToTheCellsAVehiclesSidesHalfCover)
{
  // A van 2 m wide whose sides lie on the centres of a row of 0.5 m cells (y = 4.25 and 6.25), driving away along x
  // at 8 m/s from a sensor at the origin. Its rear face's outermost returns are a beam step (5 cm) inside its sides.
  const GridGeometry g{ 0.5, 200, 200, -50.0, -50.0 };
  ASSERT_DOUBLE_EQ(kBoxMargin, 0.1);
  auto evidence = [&](bool margin, double& face_x) {
    TrackerParams p;
    p.steps.box_margin = margin;
    Tracker tracker(p);
    for (int k = 0; k <= 8; ++k)
    {
      face_x = 10.0 + 0.8 * k;
      std::vector<Point2> points;
      for (int j = 0; j < 20; ++j)
        for (const double dx : { 0.0, 0.05 }) points.push_back(Point2{ face_x + dx, 4.3 + 0.1 * j });
      const std::vector<float> xy = flatten(points);
      tracker.update(0.1 * k, Pose2{}, ObstaclePoints{ xy.data(), xy.size() / 2 });
    }
    EXPECT_EQ(tracker.tracks().size(), 1u);
    EXPECT_EQ(tracker.tracks().empty() ? TrackMotion::kUnknown : tracker.tracks()[0].motion, TrackMotion::kMoving);
    return trackEvidence(tracker, g);
  };
  // The cells of the row whose centre has y = @p y, behind the face and within the hidden length.
  auto row = [&](const std::vector<CellMotion>& cells, double face_x, double y) {
    std::size_t n = 0;
    for (const CellMotion& c : cells)
    {
      const Point2 q = g.cellCentre(g.cellOf(c.cell));
      if (std::abs(q.y - y) < 1e-9 && q.x > face_x + 0.3 && q.x < face_x + 3.7)
      {
        ++n;
        EXPECT_EQ(c.motion, CellClass::kMoving);
        EXPECT_TRUE(c.interior);
      }
    }
    return n;
  };
  double face = 0.0;
  const auto with = evidence(true, face);
  // Cell centres every 0.5 m in (face + 0.3, face + 3.7): 7 on each side row, as on the rows inside.
  EXPECT_EQ(row(with, face, 4.25), 7u);
  EXPECT_EQ(row(with, face, 6.25), 7u);
  EXPECT_EQ(row(with, face, 5.25), 7u);
  // Not the next rows out: the margin is less than half a cell.
  EXPECT_EQ(row(with, face, 3.75), 0u);
  EXPECT_EQ(row(with, face, 6.75), 0u);
  const auto without = evidence(false, face);
  EXPECT_EQ(row(without, face, 4.25), 0u);
  EXPECT_EQ(row(without, face, 6.25), 0u);
  EXPECT_EQ(row(without, face, 5.25), 7u);
  // Everything the margin adds is box cells of the two side rows (without it, those rows hold only the face's
  // outermost returns).
  auto sides = [&](const std::vector<CellMotion>& cells) {
    return static_cast<std::size_t>(std::count_if(cells.begin(), cells.end(), [&](const CellMotion& c) {
      const double y = g.cellCentre(g.cellOf(c.cell)).y;
      return c.interior && (std::abs(y - 4.25) < 1e-9 || std::abs(y - 6.25) < 1e-9);
    }));
  };
  EXPECT_EQ(sides(without), 0u);
  EXPECT_EQ(with.size(), without.size() + sides(with));
}

namespace {

constexpr double kOccluderY = 5.5, kOccluderHalf = 1.8;  // a parked car's face across the line of sight, at the origin's x

/// True behind the parked car's face, as seen from a sensor at the origin.
bool inShadow(Point2 q) { return q.y > kOccluderY && std::abs(q.x) < q.y * kOccluderHalf / kOccluderY; }

std::vector<Point2> occluderFace()
{
  std::vector<Point2> face;
  for (double x = -kOccluderHalf; x <= kOccluderHalf + 1e-9; x += 0.1) face.push_back(Point2{ x, kOccluderY });
  return face;
}

/// The near side (y = 9.1) of a 4 m car driving along +x at 10 m/s, 9 m from a sensor at the origin, out of the shadow
/// of a parked car's face (inShadow(), whose edge is at x = 2.98 on the car's side): returns every 0.1 m on the part
/// seen and on the face, and the ScanGrid, free up to y = 12 but in the shadow and on and behind the car. Returns the
/// track nearest the car's centre after @p scans scans, whose true x is @p true_x.
Track emergeFromShadow(bool open_ends, int scans, double& true_x)
{
  TrackerParams params;
  params.steps.open_ends = open_ends;
  Tracker tracker(params);
  constexpr double kSpeed = 10.0, kDt = 0.1, kSide = 9.1, kLength = 4.0;
  const double edge = kSide * kOccluderHalf / kOccluderY;
  Track last;
  for (int k = 0; k < scans; ++k)
  {
    const double front = edge + 0.2 + kSpeed * kDt * k;
    true_x = front - 0.5 * kLength;
    std::vector<Point2> seen = occluderFace();
    for (double x = std::max(front - kLength, edge + 0.05); x <= front + 1e-9; x += 0.1) seen.push_back(Point2{ x, kSide });
    const std::vector<float> xy = flatten(seen);
    auto car = [&](Point2 q) { return q.y > kSide - 0.5 && q.x > front - kLength - 0.3 && q.x < front + 0.3; };
    const ScanMassGrid scan = scanGrid(xy, [&](Point2 q) { return !inShadow(q) && !car(q) && q.y < 12.0; });
    tracker.update(kDt * k, Pose2{ 0.0, 0.0, 0.0 }, ObstaclePoints{ xy.data(), xy.size() / 2 }, nullptr, &scan);
  }
  for (const Track& t : tracker.tracks())
    if (last.id == 0 || std::abs(t.x(0) - true_x) + std::abs(t.x(1) - kSide) <
                            std::abs(last.x(0) - true_x) + std::abs(last.x(1) - kSide))
      last = t;
  return last;
}

}  // namespace

TEST(Tracker, OpenEndsAnchorOnTheOtherEndWhenAnOccluderCutsTheNearOne)
{
  // A 1.9 m line of returns along x from x = 3.1 at y = 9.1, the sensor at the origin: its end nearest the sensor
  // (x = 3.1) lies just past the shadow of a parked car's face; the scan saw free space beyond x = 5.
  std::vector<Point2> line;
  for (double x = 3.1; x < 5.05; x += 0.1) line.push_back(Point2{ x, 9.1 });
  std::vector<Point2> all = occluderFace();
  all.insert(all.end(), line.begin(), line.end());
  const std::vector<float> xy = flatten(all);
  auto seen_free = [](Point2 q) { return !inShadow(q) && q.y < 8.6; };
  const ScanMassGrid scan = scanGrid(xy, [&](Point2 q) { return seen_free(q) || (q.x > 5.1 && q.y < 12.0); });
  const Pose2 origin{};
  const SeenFree free(scan, origin, 0.0, 0.5);
  TrackerParams params;
  params.min_cluster_points = 5;
  std::vector<Measurement> found = clusterReturns(line, params);
  ASSERT_EQ(found.size(), 1u);
  Measurement m = found[0];
  m.has_sensor = true;
  const bool u_along_x = std::cos(m.yaw) > 0.0;
  const std::uint8_t plus_x = u_along_x ? Measurement::kHighU : Measurement::kLowU;
  const std::uint8_t minus_x = u_along_x ? Measurement::kLowU : Measurement::kHighU;
  const Eigen::Vector2d along_x(1.0, 0.0);
  EXPECT_TRUE(viewAlong(m, along_x).anchor_lo) << "without the step: the end nearest the sensor, x = 3.1";

  findOpenEnds(m, free, scan, origin, 1.0);
  ASSERT_TRUE(m.ends_seen);
  EXPECT_TRUE(m.open & plus_x) << "free space 1 m beyond x = 5";
  EXPECT_FALSE(m.open & minus_x) << "the shadow before x = 3.1";
  EXPECT_TRUE(m.occluded & minus_x) << "the parked car blocks the view of x = 2.1";
  EXPECT_FALSE(m.occluded & plus_x);
  EXPECT_FALSE(viewAlong(m, along_x).anchor_lo) << "the open end, x = 5";
  EXPECT_TRUE(viewAlong(m, -along_x).anchor_lo) << "the same end along −x";
  EXPECT_TRUE(hiddenFromSensor(scan, origin, Point2{ 2.0, 9.1 }, 2.0));
  EXPECT_FALSE(hiddenFromSensor(scan, origin, Point2{ 2.0, 9.1 }, 4.0)) << "the face is 3.7 m before the point";
  // The near end not occluded, or the far end not open: the end nearest the sensor.
  Measurement clear_near = m, closed_far = m;
  clear_near.occluded = 0;
  closed_far.open = 0;
  EXPECT_TRUE(viewAlong(clear_near, along_x).anchor_lo);
  EXPECT_TRUE(viewAlong(closed_far, along_x).anchor_lo);
  // An axis 30° off the cluster's: the end nearest the sensor.
  const Eigen::Vector2d askew(std::cos(M_PI / 6), std::sin(M_PI / 6));
  Measurement by_sensor = m;
  by_sensor.ends_seen = false;
  EXPECT_EQ(viewAlong(m, askew).anchor_lo, viewAlong(by_sensor, askew).anchor_lo);
}

TEST(Tracker, OpenEndsFollowTheFrontOfACarComingOutOfAShadow)
{
  // The end nearest the sensor is the shadow's edge, which stands still while the car comes out, so a box anchored on
  // it lags; the open end is the car's front.
  double true_x = 0.0;
  const Track with = emergeFromShadow(true, 8, true_x);
  const Track without = emergeFromShadow(false, 8, true_x);
  ASSERT_GT(with.id, 0u);
  ASSERT_GT(without.id, 0u);
  const double err_with = std::abs(with.x(2) - 10.0), err_without = std::abs(without.x(2) - 10.0);
  EXPECT_LT(err_with, 0.5 * err_without) << "vx with " << with.x(2) << ", without " << without.x(2);
  EXPECT_LT(err_with, 1.0) << "vx " << with.x(2);
  EXPECT_LT(std::abs(with.x(0) - true_x), 0.5) << "the box's centre, " << with.x(0) << " for " << true_x;
  EXPECT_NEAR(with.extent_length, 4.0, 0.3);
}


namespace {

constexpr int kStaticObjects = 24;  // above kCommonMotionMinTracks (20)
constexpr int kDriftScans = 30;

/// Scan @p k (0.1 s apart) of kStaticObjects static objects 4 m apart and one walker at @p walker_speed along −y, all
/// seen through a pose that drifts at @p drift m/s along x (the map frame moves them all by as much).
std::vector<Measurement> driftScan(int k, double drift, double walker_speed)
{
  const double t = 0.1 * k;
  std::vector<Measurement> out;
  for (int j = 0; j < kStaticObjects; ++j) out.push_back(at(drift * t + 4.0 * j, 10.0 + (j % 3)));
  out.push_back(at(drift * t + 40.0, -20.0 - walker_speed * t));
  return out;
}

/// A tracker with @p on and one with @p off, each fed kDriftScans scans @p scan(k) 0.1 s apart.
template <typename Scan>
std::pair<Tracker, Tracker> runBoth(const TrackerParams& on, const TrackerParams& off, Scan scan)
{
  std::pair<Tracker, Tracker> both{ Tracker(on), Tracker(off) };
  for (int k = 0; k < kDriftScans; ++k)
  {
    both.first.update(0.1 * k, scan(k));
    both.second.update(0.1 * k, scan(k));
  }
  return both;
}

}  // namespace

// Step common motion: a pose drifting at 1.2 m/s makes every static object's track move at 1.2 m/s. With the step,
// their median is the scan's common motion and, relative to it, none is moving (they end stopped), while a walker at
// 1.5 m/s relative to them is; without it every static track is moving. The step changes no track's state.
TEST(Tracker, CommonMotionOfADriftingPoseIsNoMotion)
{
  TrackerParams on;
  ASSERT_TRUE(on.steps.common_motion);
  ASSERT_LT(kCommonMotionMinTracks, kStaticObjects + 1);
  TrackerParams off = on;
  off.steps.common_motion = false;
  constexpr double kDrift = 1.2, kWalker = 1.5;
  const auto [with, without] = runBoth(on, off, [&](int k) { return driftScan(k, kDrift, kWalker); });
  ASSERT_EQ(with.tracks().size(), static_cast<std::size_t>(kStaticObjects + 1));
  ASSERT_EQ(without.tracks().size(), with.tracks().size());
  ASSERT_TRUE(with.hasCommonMotion());
  EXPECT_FALSE(without.hasCommonMotion());
  EXPECT_EQ(without.counts().common_motion_scans, 0u);
  // Confirmed from the third scan: a common motion on every scan from there.
  EXPECT_EQ(with.counts().common_motion_scans, static_cast<std::uint64_t>(kDriftScans - on.confirm_hits + 1));
  const Track& first = with.tracks()[0];
  // The static tracks share one velocity (to rounding: their positions differ): the median is it.
  EXPECT_NEAR(with.commonMotion().x, first.decisionVelocity().x, 1e-9);
  EXPECT_NEAR(with.commonMotion().y, first.decisionVelocity().y, 1e-9);
  EXPECT_NEAR(with.commonMotion().x, kDrift, 0.05);
  for (std::size_t i = 0; i < with.tracks().size(); ++i)
  {
    const Track& a = with.tracks()[i];
    const Track& b = without.tracks()[i];
    ASSERT_EQ(a.id, b.id);
    EXPECT_EQ(a.x, b.x) << "the filter is the same";
    const bool walker = i + 1 == with.tracks().size();
    EXPECT_EQ(a.motion, walker ? TrackMotion::kMoving : TrackMotion::kStopped) << "track " << a.id;
    EXPECT_EQ(b.motion, TrackMotion::kMoving) << "track " << b.id << " without the step";
    EXPECT_NEAR(with.decisionSpeed(a), walker ? std::hypot(0.0, kWalker) : 0.0, 0.05);
    EXPECT_EQ(without.decisionSpeed(b), std::hypot(b.decisionVelocity().x, b.decisionVelocity().y));
  }
}

// A common motion must be slow, shared by most tracks, and seen on enough of them: traffic at 8 m/s and a drift seen
// on too few tracks never have one, a scene whose tracks split evenly between two motions has none once their
// velocities are known, and every decision stays the one without the step.
TEST(Tracker, TrafficFewTracksAndSplitMotionsAreNoCommonMotion)
{
  TrackerParams on, off;
  off.steps.common_motion = false;
  auto run = [](const TrackerParams& p, int objects, double v_first, double v_rest, int first_count) {
    Tracker tracker(p);
    for (int k = 0; k < kDriftScans; ++k)
    {
      std::vector<Measurement> scan;
      for (int j = 0; j < objects; ++j)
        scan.push_back(at((j < first_count ? v_first : v_rest) * 0.1 * k + 5.0 * j, 3.0 * (j % 4)));
      tracker.update(0.1 * k, scan);
    }
    return tracker;
  };
  struct Case
  {
    const char* what;
    int objects;
    double v_first, v_rest;
    int first_count;
  };
  for (const Case& c : { Case{ "traffic at 8 m/s", 24, 8.0, 8.0, 24 }, Case{ "a drift on 19 tracks", 19, 1.2, 1.2, 19 },
                         Case{ "12 at rest, 12 at 1.5 m/s", 24, 0.0, 1.5, 12 } })
  {
    const Tracker with = run(on, c.objects, c.v_first, c.v_rest, c.first_count);
    const Tracker without = run(off, c.objects, c.v_first, c.v_rest, c.first_count);
    EXPECT_FALSE(with.hasCommonMotion()) << c.what;
    // The split scene's first confirmed scans have one: every velocity is still uncertain enough to agree with it.
    if (c.v_first == c.v_rest)
    {
      EXPECT_EQ(with.counts().common_motion_scans, 0u) << c.what;
    }
    ASSERT_EQ(with.tracks().size(), without.tracks().size()) << c.what;
    for (std::size_t i = 0; i < with.tracks().size(); ++i)
      EXPECT_EQ(with.tracks()[i].motion, without.tracks()[i].motion) << c.what << ", track " << i;
  }
}

namespace {

constexpr double kTurnRate = 0.03;  // rad/s, below kCommonMotionMaxTurnRate

/// Scan @p k (0.1 s apart) seen from a sensor at rest at the origin through a heading that drifts at @p turn_rate:
/// kStaticObjects static objects all round at 10 to 55 m and a walker at 1.5 m/s along −y, the whole scene turned by
/// turn_rate · t about the sensor. @p sensor: the measurements know the sensor position.
std::vector<Measurement> turnScan(int k, double turn_rate, bool sensor)
{
  const double t = 0.1 * k, c = std::cos(turn_rate * t), s = std::sin(turn_rate * t);
  auto seen = [&](double x, double y) {
    Measurement m = at(c * x - s * y, s * x + c * y);
    m.has_sensor = sensor;
    return m;
  };
  std::vector<Measurement> out;
  for (int j = 0; j < kStaticObjects; ++j)
  {
    const double bearing = 2.0 * M_PI * j / kStaticObjects, range = 10.0 + 45.0 * (j % 4) / 3.0;
    out.push_back(seen(range * std::cos(bearing), range * std::sin(bearing)));
  }
  out.push_back(seen(12.0, 6.0 - 1.5 * t));
  return out;
}

}  // namespace

// Step common turn: a heading drifting at 0.03 rad/s moves static objects at 0.3 to 1.65 m/s, each its own way, so
// no one velocity is shared. With the step the common motion turns at that rate about the sensor and, relative to it,
// no static object moves while the walker does; with the median alone the far ones are moving. The filter is the same.
TEST(Tracker, CommonTurnOfADriftingHeadingIsNoMotion)
{
  TrackerParams on;
  ASSERT_TRUE(on.steps.common_turn);
  ASSERT_LE(kTurnRate, kCommonMotionMaxTurnRate);
  TrackerParams off = on;
  off.steps.common_turn = false;
  const auto [with, without] = runBoth(on, off, [](int k) { return turnScan(k, kTurnRate, true); });
  ASSERT_EQ(with.tracks().size(), static_cast<std::size_t>(kStaticObjects + 1));
  ASSERT_EQ(without.tracks().size(), with.tracks().size());
  ASSERT_TRUE(with.hasCommonMotion());
  EXPECT_NEAR(with.commonTurnRate(), kTurnRate, 0.1 * kTurnRate);
  EXPECT_NEAR(std::hypot(with.commonMotion().x, with.commonMotion().y), 0.0, 0.1) << "the sensor is at rest";
  EXPECT_EQ(without.commonTurnRate(), 0.0);
  EXPECT_EQ(without.counts().common_turn_scans, 0u);
  EXPECT_GT(with.counts().common_turn_scans, 0u);
  EXPECT_LE(with.counts().common_turn_scans, with.counts().common_motion_scans);
  int static_moving_without = 0;
  for (std::size_t i = 0; i < with.tracks().size(); ++i)
  {
    const Track& a = with.tracks()[i];
    const Track& b = without.tracks()[i];
    ASSERT_EQ(a.id, b.id);
    EXPECT_EQ(a.x, b.x) << "the filter is the same";
    const bool walker = i + 1 == with.tracks().size();
    EXPECT_EQ(a.motion == TrackMotion::kMoving, walker) << "track " << a.id;
    EXPECT_NEAR(with.decisionSpeed(a), walker ? 1.5 : 0.0, 0.15) << "track " << a.id;
    const Point2 field = with.commonMotionAt(a.position());
    EXPECT_NEAR(field.x, with.commonMotion().x - with.commonTurnRate() * a.x(1), 1e-12);
    EXPECT_NEAR(field.y, with.commonMotion().y + with.commonTurnRate() * a.x(0), 1e-12);
    static_moving_without += !walker && b.motion == TrackMotion::kMoving;
  }
  EXPECT_GT(static_moving_without, 0) << "without the step the scene must show the cause";
}

// The common motion turns only when the turn is real and its centre is known: a drift without a turn keeps the
// median (ω = 0, every decision the same as without the step), and so does a turning scene whose measurements do not
// know the sensor; a turn faster than kCommonMotionMaxTurnRate is not a drift.
TEST(Tracker, CommonTurnNeedsAKnownSensorAndASignificantSlowTurn)
{
  struct Case
  {
    const char* what;
    double turn_rate;
    bool sensor;
  };
  for (const Case& c : { Case{ "no turn", 0.0, true }, Case{ "no sensor", kTurnRate, false },
                         Case{ "too fast a turn", 2.0 * kCommonMotionMaxTurnRate, true } })
  {
    TrackerParams on;
    TrackerParams off = on;
    off.steps.common_turn = false;
    Tracker with(on), without(off);
    for (int k = 0; k < kDriftScans; ++k)
    {
      with.update(0.1 * k, turnScan(k, c.turn_rate, c.sensor));
      without.update(0.1 * k, turnScan(k, c.turn_rate, c.sensor));
      ASSERT_EQ(with.commonTurnRate(), 0.0) << c.what << ", scan " << k;
      ASSERT_EQ(with.hasCommonMotion(), without.hasCommonMotion()) << c.what << ", scan " << k;
      ASSERT_EQ(with.commonMotion().x, without.commonMotion().x) << c.what << ", scan " << k;
      ASSERT_EQ(with.commonMotion().y, without.commonMotion().y) << c.what << ", scan " << k;
    }
    EXPECT_EQ(with.counts().common_turn_scans, 0u) << c.what;
    ASSERT_EQ(with.tracks().size(), without.tracks().size()) << c.what;
    for (std::size_t i = 0; i < with.tracks().size(); ++i)
      EXPECT_EQ(with.tracks()[i].motion, without.tracks()[i].motion) << c.what << ", track " << i;
  }
}

namespace {

/// A wall along y = 0 from x = 0 to @p wall_length (two rows of returns, every 0.05 m, on background) and a
/// @p ped_length × 0.3 m block of returns from x = min(10, wall_length / 2), y = 0.3 (every 0.1 m: touching the
/// wall's cells), on background when @p ped_on_background.
std::vector<Measurement> wallAndPedestrian(const TrackerParams& p, double wall_length, double ped_length,
                                           bool ped_on_background, bool flags = true)
{
  std::vector<Point2> pts;
  std::vector<std::uint8_t> bg;
  for (double x = 0.0; x <= wall_length + 1e-9; x += 0.05)
    for (const double y : { 0.0, 0.1 })
    {
      pts.push_back(Point2{ x, y });
      bg.push_back(1);
    }
  const double x0 = std::min(10.0, 0.5 * wall_length);
  for (double x = x0; x <= x0 + ped_length + 1e-9; x += 0.1)
    for (const double y : { 0.3, 0.4, 0.5, 0.6 })
    {
      pts.push_back(Point2{ x, y });
      bg.push_back(ped_on_background ? 1 : 0);
    }
  return clusterReturns(pts, p, flags ? &bg : nullptr);
}

}  // namespace

TEST(Tracker, BackgroundSplitFindsAPedestrianTouchingAWall)
{
  TrackerParams p;
  ASSERT_TRUE(p.steps.background_split);
  ASSERT_DOUBLE_EQ(p.pedestrian_size, 1.0);
  const std::vector<Measurement> found = wallAndPedestrian(p, 30.0, 0.4, false);
  ASSERT_EQ(found.size(), 1u) << "the pedestrian, split off the 30 m wall it touches";
  const Measurement& m = found[0];
  EXPECT_TRUE(m.split);
  EXPECT_EQ(m.points, 20);
  EXPECT_NEAR(m.centroid.x, 10.2, 1e-9);
  EXPECT_NEAR(m.centroid.y, 0.45, 1e-9);
  EXPECT_NEAR(std::max(m.length, m.width), 0.4, 1e-9);
  EXPECT_NEAR(std::min(m.length, m.width), 0.3, 1e-9);
  EXPECT_EQ(m.returns.size(), 20u);

  TrackerParams off = p;
  off.steps.background_split = false;
  EXPECT_TRUE(wallAndPedestrian(off, 30.0, 0.4, false).empty()) << "without the step: one cluster too long";
  EXPECT_TRUE(wallAndPedestrian(p, 30.0, 0.4, false, false).empty()) << "without background flags nothing tells them apart";
  EXPECT_TRUE(wallAndPedestrian(p, 30.0, 0.4, true).empty()) << "returns on background are no piece";
  EXPECT_TRUE(wallAndPedestrian(p, 30.0, 1.5, false).empty()) << "a piece longer than pedestrian_size";
  TrackerParams larger = p;
  larger.pedestrian_size = 2.0;
  EXPECT_EQ(wallAndPedestrian(larger, 30.0, 1.5, false).size(), 1u);
  EXPECT_TRUE(wallAndPedestrian(p, 5.0, 0.4, false).empty())
      << "a short cluster dropped for its background share alone is not split";
}

namespace {

Measurement piece(double x, double y, double length, double width, bool split)
{
  Measurement m = withExtent(at(x, y, 0.15), length, width);
  m.split = split;
  return m;
}

/// A track of a @p length × @p width object at (10, 0) seen in 4 scans, then a 0.4 × 0.3 m piece at (10.2, 0) in the
/// fifth: the consecutive hits of the first track after it.
int hitsAfterAPiece(double length, double width, bool split)
{
  Tracker tracker{ TrackerParams{} };
  for (int k = 0; k < 4; ++k) tracker.update(0.1 * k, { piece(10.0, 0.0, length, width, false) });
  tracker.update(0.4, { piece(10.2, 0.0, 0.4, 0.3, split) });
  const Track* t = byId(tracker, 1);
  return t ? t->consecutive_hits : -1;
}

}  // namespace

TEST(Tracker, BackgroundSplitPiecesFollowOnlySmallTracks)
{
  ASSERT_EQ(hitsAfterAPiece(4.0, 2.0, false), 5) << "a cluster of the car's: associated";
  EXPECT_EQ(hitsAfterAPiece(4.0, 2.0, true), 0) << "a piece split off background: not the car's track";
  EXPECT_EQ(hitsAfterAPiece(0.5, 0.4, true), 5) << "a pedestrian's track follows its pieces";
}

namespace {

/// The first scan from which the track of a @p length × 0.4 m object walking along x at @p speed (from x = -2, returns
/// every 0.1 m at y = 5.1 … 5.4) is moving, -1 if never within 2 s. The scan sees no free space anywhere: a
/// pedestrian behind parked cars, whose ground is hidden.
int walkUnseen(const TrackerParams& params, double speed, double length = 0.4, std::uint64_t* walked = nullptr)
{
  Tracker tracker(params);
  for (int k = 0; k < 20; ++k)
  {
    const double x0 = -2.0 + speed * 0.1 * k;
    std::vector<Point2> points;
    for (double u = 0.0; u <= length + 1e-9; u += 0.1)
      for (const double y : { 5.1, 5.2, 5.3, 5.4 }) points.push_back(Point2{ x0 + u, y });
    const std::vector<float> xy = flatten(points);
    const ScanMassGrid scan = scanGrid(xy, [](Point2) { return false; });
    tracker.update(0.1 * k, Pose2{}, ObstaclePoints{ xy.data(), xy.size() / 2 }, nullptr, &scan);
    EXPECT_LE(tracker.tracks().size(), 1u);
    if (walked) *walked = tracker.counts().walked;
    if (!tracker.tracks().empty() && tracker.tracks()[0].motion == TrackMotion::kMoving) return k;
  }
  return -1;
}

}  // namespace

TEST(Tracker, WalkedLetsAPedestrianWhoseGroundIsHiddenMove)
{
  TrackerParams p;
  ASSERT_TRUE(p.steps.walked);
  ASSERT_EQ(kWalkMinHits, 10);
  ASSERT_DOUBLE_EQ(kWalkDistance, 0.5);
  std::uint64_t walked = 0;
  const int from = walkUnseen(p, 0.8, 0.4, &walked);
  EXPECT_EQ(walked, 1u) << "counted";
  // Scan 9 is its 10th association; it moved 0.72 m since its first sighting, 0.9 s before.
  EXPECT_EQ(from, kWalkMinHits - 1);
  TrackerParams off = p;
  off.steps.walked = false;
  EXPECT_EQ(walkUnseen(off, 0.8), -1) << "free space never shows its motion";
  // At 0.3 m/s, below tracker_moving_speed, it never clears the speed test (nor covers kWalkDistance, 0.33 m at most
  // within the 1 s of sightings kept): with the default speeds the distance test does not bind on its own here.
  EXPECT_EQ(walkUnseen(p, 0.3), -1) << "slower than tracker_moving_speed: not moving";
  EXPECT_EQ(walkUnseen(p, 0.0), -1) << "a pedestrian standing still";
  EXPECT_EQ(walkUnseen(p, 0.8, 2.0), -1) << "a 2 m object is no small walker";
}

namespace {

constexpr double kCornerYaw = 0.37, kCornerLength = 1.10, kCornerWidth = 0.53;

/// A cluster along x at y = 2.4 from @p front to @p front + @p length, seen from (20, 42): its −x end (the front of a car
/// driving along −x) open, its +x end occluded while the car is still partly in a shadow.
Measurement sideOf(double front, double length, double width, bool in_shadow)
{
  Measurement m = withExtent(at(front + 0.5 * length, 2.4, 0.15), length, width);
  m.has_sensor = true;
  m.sensor = Point2{ 20.0, 42.0 };
  m.ends_seen = true;
  m.open = Measurement::kLowU;
  m.occluded = in_shadow ? Measurement::kHighU : 0;
  return m;
}

/// A 4.5 m car driving along −x at 12 m/s comes out of a shadow whose edge is at x = 10.4: first its corner, a
/// @p corner_length × @p corner_width cluster whose axes are @p corner_yaw off the car's, then its side, a
/// @p side_width wide cluster from its front to the shadow's edge (scan 1: 3.15 m). After @p scans scans: the track the
/// corner started, and how many tracks there are in @p tracks.
Track comeOutOfAShadow(const TrackerParams& params, int scans, std::uint64_t* turned = nullptr, std::size_t* tracks = nullptr,
                       double corner_yaw = kCornerYaw, double corner_length = kCornerLength,
                       double corner_width = kCornerWidth, double side_width = 0.08, double edge = 10.4)
{
  Tracker tracker(params);
  Measurement corner = sideOf(8.45, corner_length, corner_width, true);
  corner.centroid = Point2{ 9.0, 2.3 };
  corner.yaw = corner_yaw;
  tracker.update(0.0, { corner });
  for (int k = 1; k < scans; ++k)
  {
    const double front = 8.45 - 1.2 * k, length = std::min(4.5, edge - front);
    tracker.update(0.1 * k, { sideOf(front, length, side_width, length < 4.5) });
  }
  if (turned) *turned = tracker.counts().second_axes;
  if (tracks) *tracks = tracker.tracks().size();
  const Track* first = byId(tracker, 1);
  return first ? *first : Track{};
}

}  // namespace

TEST(Tracker, SecondAxesTurnTheBoxOfACarWhoseCornerCameFirst)
{
  TrackerParams p;
  ASSERT_TRUE(p.steps.second_axes);
  ASSERT_DOUBLE_EQ(kSecondAxesRound, 0.4);
  ASSERT_DOUBLE_EQ(kSecondAxesElongation, 0.5);
  ASSERT_DOUBLE_EQ(kSecondAxesGrowth, 1.5);
  std::uint64_t turned = 0;
  const Track second = comeOutOfAShadow(p, 2, &turned);
  ASSERT_EQ(second.hits, 2);
  EXPECT_EQ(turned, 1u) << "counted";
  EXPECT_DOUBLE_EQ(second.extent_yaw, 0.0) << "the side's axes";
  // Across: the corner's box seen along the side's axes, wider than the side (0.08 m), which cannot grow it.
  EXPECT_DOUBLE_EQ(second.extent_width, kCornerLength * std::sin(kCornerYaw) + kCornerWidth * std::cos(kCornerYaw));
  // Along: the corner's box seen along them (1.22 m) grew to the side's 3.15 m, away from the open front.
  EXPECT_NEAR(second.extent_length, 3.15, 1e-9);

  // Five scans on: the box anchored on the car's front follows it; without the step, the box keeps the corner's axes,
  // 21° off the side's, too far for step open ends, and follows the shadow's edge that stands still.
  std::size_t tracks = 0;
  const Track with = comeOutOfAShadow(p, 5, nullptr, &tracks);
  EXPECT_EQ(tracks, 1u);
  EXPECT_EQ(with.hits, 5);
  TrackerParams off = p;
  off.steps.second_axes = false;
  std::uint64_t off_turned = 0;
  const Track without = comeOutOfAShadow(off, 5, &off_turned);
  ASSERT_GT(without.id, 0u);
  EXPECT_EQ(off_turned, 0u);
  EXPECT_DOUBLE_EQ(without.extent_yaw, kCornerYaw);
  const double err_with = std::hypot(with.x(2) + 12.0, with.x(3)), err_without = std::hypot(without.x(2) + 12.0, without.x(3));
  EXPECT_LT(err_with, 0.5 * err_without) << "vx with " << with.x(2) << ", without " << without.x(2);
}

TEST(Tracker, SecondAxesLeaveABoxWithAnAxisOrAClusterWithout)
{
  TrackerParams p;
  auto keeps = [&](const TrackerParams& params, double corner_yaw, double corner_length, double corner_width,
                   double side_width, double edge) {
    std::uint64_t turned = 0;
    const Track t = comeOutOfAShadow(params, 2, &turned, nullptr, corner_yaw, corner_length, corner_width, side_width, edge);
    return turned == 0 && t.extent_yaw == corner_yaw;
  };
  ASSERT_FALSE(keeps(p, kCornerYaw, kCornerLength, kCornerWidth, 0.08, 10.4)) << "the scene above turns";
  EXPECT_TRUE(keeps(p, kCornerYaw, kCornerLength, 0.4, 0.08, 10.4)) << "a first cluster 0.4 × 1.1 m has an axis";
  EXPECT_TRUE(keeps(p, kCornerYaw, kCornerLength, kCornerWidth, 1.6, 10.4)) << "a 3.15 × 1.6 m side has none";
  EXPECT_TRUE(keeps(p, kCornerYaw, kCornerLength, kCornerWidth, 0.08, 8.8)) << "1.55 m: not longer than 1.5 × 1.1 m";
  EXPECT_TRUE(keeps(p, 0.05, kCornerLength, kCornerWidth, 0.08, 10.4)) << "within 6° of the side's axes";
}

namespace {

/// Scans 0 … @p scans − 1 of a car's side at y = 2.4 seen from (20, 42) through a 2 m gap between two parked cars: a
/// cluster 2 m long whose centroid drifts from x = 11.4 at @p gap_speed (the gap's edges move as the vehicle drives),
/// both its ends hidden and neither open (@p ends: Measurement::occluded; open none). With @p moving_first, a car
/// driving along −x at 12 m/s seen whole for eight scans first (both ends open), then its rear 2 m at its speed.
Tracker throughAGap(const TrackerParams& params, int scans, double gap_speed, bool moving_first,
                    std::uint8_t ends = Measurement::kLowU | Measurement::kHighU)
{
  Tracker tracker(params);
  double t = 0.0;
  if (moving_first)
    for (int k = 0; k < 8; ++k, t += 0.1)
    {
      Measurement whole = sideOf(20.0 - 1.2 * k, 4.5, 0.08, false);
      whole.open = Measurement::kLowU | Measurement::kHighU;
      tracker.update(t, { whole });
    }
  // After the whole car, the view is its last 2 m, so that its end nearest the sensor is the car's.
  const double start = moving_first ? 20.0 - 1.2 * 8 + 4.5 - 2.0 : 10.4;
  for (int k = 0; k < scans; ++k, t += 0.1)
  {
    Measurement view = sideOf(start + gap_speed * 0.1 * k, 2.0, 0.08, false);
    view.open = 0;
    view.occluded = ends;
    tracker.update(t, { view });
  }
  return tracker;
}

}  // namespace

TEST(Tracker, HiddenEndsKeepACarSeenThroughAGapFromMovingWithTheGap)
{
  TrackerParams p;
  ASSERT_TRUE(p.steps.hidden_ends);
  ASSERT_DOUBLE_EQ(kHiddenEndsSigma, 5.0);
  p.steps.free_space_check = false;  // no ScanGrid here: the speed alone decides
  TrackerParams off = p;
  off.steps.hidden_ends = false;
  const Tracker without = throughAGap(off, 8, -2.0, false);
  ASSERT_EQ(without.tracks().size(), 1u);
  EXPECT_EQ(without.tracks()[0].motion, TrackMotion::kMoving) << "the gap's drift, taken for the car's motion";
  EXPECT_NEAR(without.tracks()[0].x(2), -2.0, 0.5);
  const Tracker with = throughAGap(p, 8, -2.0, false);
  ASSERT_EQ(with.tracks().size(), 1u);
  EXPECT_NE(with.tracks()[0].motion, TrackMotion::kMoving);
  EXPECT_EQ(with.counts().hidden_ends, 7u) << "every association after the first";
  EXPECT_EQ(without.counts().hidden_ends, 0u);
  // Across the axis the views still tell where the object is: no speed across it.
  EXPECT_NEAR(with.tracks()[0].x(3), 0.0, 1e-9);
}

TEST(Tracker, HiddenEndsLeaveAMovingTrackAndAViewWithAnEnd)
{
  TrackerParams p;
  p.steps.free_space_check = false;
  TrackerParams off = p;
  off.steps.hidden_ends = false;
  auto same = [](const Tracker& a, const Tracker& b) {
    return a.tracks().size() == 1u && b.tracks().size() == 1u && a.tracks()[0].x == b.tracks()[0].x &&
           a.tracks()[0].P == b.tracks()[0].P;
  };
  const Tracker moving = throughAGap(p, 3, -12.0, true);
  ASSERT_EQ(moving.tracks().size(), 1u);
  EXPECT_EQ(moving.tracks()[0].motion, TrackMotion::kMoving);
  EXPECT_TRUE(same(moving, throughAGap(off, 3, -12.0, true))) << "a moving track: bit for bit as without the step";
  EXPECT_EQ(moving.counts().hidden_ends, 0u);
  EXPECT_TRUE(same(throughAGap(p, 8, -2.0, false, Measurement::kLowU), throughAGap(off, 8, -2.0, false, Measurement::kLowU)))
      << "one end not hidden";
}

namespace {

constexpr double kVehicleYaw = 30.0 * M_PI / 180.0;  // a multiple of kBoxFitStepDeg (3°)
constexpr double kVehicleLength = 4.5, kVehicleWidth = 1.8;

/// The returns of a 4.5 × 1.8 m vehicle centred on (10, 5), heading kVehicleYaw, seen on its rear and its left side
/// (an L, every 5 cm), or of a smaller L of @p length × @p width.
std::vector<Point2> rearAndSide(double length = kVehicleLength, double width = kVehicleWidth)
{
  std::vector<Point2> out;
  const double c = std::cos(kVehicleYaw), s = std::sin(kVehicleYaw);
  auto add = [&](double u, double v) { out.push_back(Point2{ 10.0 + c * u - s * v, 5.0 + s * u + c * v }); };
  const int along = static_cast<int>(std::lround(length / 0.05)), across = static_cast<int>(std::lround(width / 0.05));
  for (int i = 0; i <= along; ++i) add(-0.5 * length + 0.05 * i, -0.5 * width);
  for (int i = 1; i <= across; ++i) add(-0.5 * length, -0.5 * width + 0.05 * i);
  return out;
}

/// The only measurement of @p points.
Measurement onlyCluster(const std::vector<Point2>& points, const TrackerParams& p)
{
  const std::vector<Measurement> found = clusterReturns(points, p, nullptr);
  EXPECT_EQ(found.size(), 1u);
  return found.empty() ? Measurement{} : found[0];
}

}  // namespace

TEST(Tracker, BoxFitTakesTheAxesOfAVehicleSeenOnItsRearAndSide)
{
  TrackerParams p;
  ASSERT_TRUE(p.steps.box_fit);
  ASSERT_DOUBLE_EQ(kBoxFitStepDeg, 3.0);
  ASSERT_DOUBLE_EQ(kBoxFitCloseness, 0.05);
  ASSERT_DOUBLE_EQ(kBoxFitMinLength, 1.5);
  const Measurement fitted = onlyCluster(rearAndSide(), p);
  EXPECT_TRUE(fitted.fitted);
  EXPECT_NEAR(fitted.yaw, kVehicleYaw, 1e-12) << "the rectangle every return lies on";
  EXPECT_NEAR(fitted.length, kVehicleLength, 1e-9);
  EXPECT_NEAR(fitted.width, kVehicleWidth, 1e-9);
  // The principal axes of the L lie between its two faces (11.4° off, towards the rear): its box is askew and
  // longer than the vehicle.
  TrackerParams off = p;
  off.steps.box_fit = false;
  const Measurement principal = onlyCluster(rearAndSide(), off);
  EXPECT_FALSE(principal.fitted);
  EXPECT_GT(std::abs(std::remainder(principal.yaw - kVehicleYaw, M_PI)), 10.0 * M_PI / 180.0);
  EXPECT_GT(principal.length, kVehicleLength + 0.2);
  // The centroid is the returns' mean either way; the box around it is the vehicle's.
  EXPECT_DOUBLE_EQ(fitted.centroid.x, principal.centroid.x);
  EXPECT_DOUBLE_EQ(fitted.centroid.y, principal.centroid.y);
  const double cu = 0.5 * (fitted.lo_u + fitted.hi_u), cv = 0.5 * (fitted.lo_v + fitted.hi_v);
  const double c = std::cos(fitted.yaw), s = std::sin(fitted.yaw);
  EXPECT_NEAR(fitted.centroid.x + c * cu - s * cv, 10.0, 1e-9);
  EXPECT_NEAR(fitted.centroid.y + s * cu + c * cv, 5.0, 1e-9);
  // The tracker counts the measurements whose box turned.
  Tracker tracker(p);
  const std::vector<float> xy = flatten(rearAndSide());
  tracker.update(0.0, Pose2{}, ObstaclePoints{ xy.data(), xy.size() / 2 }, nullptr, nullptr);
  EXPECT_EQ(tracker.counts().box_fit, 1u);
}

TEST(Tracker, BoxFitLeavesAPedestrianAndAClusterWhoseAxesAreItsBox)
{
  TrackerParams p;
  TrackerParams off = p;
  off.steps.box_fit = false;
  auto same = [](const Measurement& a, const Measurement& b) {
    return a.yaw == b.yaw && a.length == b.length && a.width == b.width && a.lo_u == b.lo_u && a.hi_v == b.hi_v &&
           a.covariance == b.covariance && !a.fitted && !b.fitted;
  };
  // A 0.6 × 0.5 m L: shorter than kBoxFitMinLength along its principal axis, it keeps them, bit for bit.
  EXPECT_TRUE(same(onlyCluster(rearAndSide(0.6, 0.5), p), onlyCluster(rearAndSide(0.6, 0.5), off)));
  // A straight side: its principal axis is its rectangle's, within a step.
  const Measurement side = onlyCluster(rearAndSide(kVehicleLength, 0.0), p);
  EXPECT_FALSE(side.fitted);
  EXPECT_NEAR(side.yaw, kVehicleYaw, 1e-9);
  EXPECT_NEAR(side.length, kVehicleLength, 1e-9);
}

namespace {

constexpr double kBusLength = 12.0, kBusWidth = 2.5;
constexpr double kBusSpeed = 6.6, kBusBraking = 1.5;  // m/s, m/s²

/// A cluster of @p length × @p width m about (x, y), its major axis along x, with clusterReturns()' σ; it knows the
/// sensor and which of its ends step open ends saw (set them).
Measurement boxCluster(double x, double y, double length, double width, const TrackerParams& params)
{
  Measurement m = withExtent(at(x, y), length, width);
  const double su = params.measurement_sigma + params.extent_sigma * length;
  const double sv = params.measurement_sigma + params.extent_sigma * width;
  m.covariance = Eigen::Vector2d(su * su, sv * sv).asDiagonal();
  m.has_sensor = true;
  m.ends_seen = true;
  return m;
}

/// A 12 × 2.5 m bus driving along −x at 6.6 m/s for ten scans, then braking at 1.5 m/s² over @p braking scans, seen
/// whole from behind (the sensor 20 m beyond its rear), each cluster with clusterReturns()' σ; its rear has free space
/// beyond it when @p rear_open. The tracker after the last scan; the bus's speed then in @p speed.
Tracker busThatBrakes(const TrackerParams& params, int braking, bool rear_open, double& speed)
{
  Tracker tracker(params);
  double front = 40.0;
  speed = kBusSpeed;
  for (int k = 0; k < 10 + braking; ++k)
  {
    if (k > 0)
    {
      const double v0 = speed;
      if (k >= 10) speed -= kBusBraking * 0.1;
      front -= 0.05 * (v0 + speed);
    }
    Measurement m = boxCluster(front + 0.5 * kBusLength, 2.4, kBusLength, kBusWidth, params);
    m.sensor = Point2{ front + kBusLength + 20.0, 2.4 };
    m.open = rear_open ? Measurement::kHighU : 0;
    tracker.update(0.1 * k, { m });
  }
  return tracker;
}

constexpr double kCarLength = 4.4, kCarSide = 0.3, kCarSpeed = 12.0;  // m, m, m/s
constexpr double kOccluderEdge = 41.2;                                // m: x beyond which the car is hidden

/// A 4.4 m car driving along −x at 12 m/s out from behind an occluder whose edge is at x = 41.2, seen from ahead (the
/// sensor 30 m beyond its front) over @p scans scans: its front is open, its rear hidden until it is out, and its
/// cluster (one side, 0.3 m wide) grows by 1.2 m a scan at its rear: 1.2, 2.4, 3.6, then 4.4 m. The cluster's axes
/// are turned by @p turn from the x axis after the first scan.
Tracker carComingOut(const TrackerParams& params, int scans, double turn = 0.0)
{
  Tracker tracker(params);
  for (int k = 0; k < scans; ++k)
  {
    const double front = 40.0 - kCarSpeed * 0.1 * k;
    const double rear = std::min(front + kCarLength, kOccluderEdge), seen = rear - front;
    Measurement m = boxCluster(0.5 * (front + rear), 2.0, seen, kCarSide, params);
    m.yaw = k > 0 ? turn : 0.0;
    m.sensor = Point2{ front - 30.0, 2.0 };
    m.open = Measurement::kLowU;
    m.occluded = rear < front + kCarLength ? Measurement::kHighU : 0;
    tracker.update(0.1 * k, { m });
  }
  return tracker;
}

}  // namespace

TEST(Tracker, OpenAnchorFollowsALongVehicleThatBrakes)
{
  TrackerParams p;
  ASSERT_TRUE(p.steps.open_anchor);
  p.steps.free_space_check = false;  // no ScanGrid here: the speed alone decides
  TrackerParams off = p;
  off.steps.open_anchor = false;
  double speed = 0.0;
  const Tracker with = busThatBrakes(p, 20, true, speed);
  const Tracker without = busThatBrakes(off, 20, true, speed);
  ASSERT_EQ(with.tracks().size(), 1u);
  ASSERT_EQ(without.tracks().size(), 1u);
  ASSERT_NEAR(speed, kBusSpeed - 2.0 * kBusBraking, 1e-9);
  const double lag_with = std::abs(with.tracks()[0].x(2)) - speed;
  const double lag_without = std::abs(without.tracks()[0].x(2)) - speed;
  EXPECT_GT(lag_without, 1.0) << "a 1.35 m σ along the bus keeps the constant-velocity filter's gain low";
  EXPECT_LT(std::abs(lag_with), 0.5 * lag_without);
  EXPECT_EQ(with.counts().open_anchor, 29u) << "every association after the first";
  EXPECT_EQ(without.counts().open_anchor, 0u);
}

TEST(Tracker, OpenAnchorLeavesAClusterWhoseAnchoringEndIsNotOpen)
{
  TrackerParams p;
  p.steps.free_space_check = false;
  TrackerParams off = p;
  off.steps.open_anchor = false;
  double speed = 0.0;
  const Tracker with = busThatBrakes(p, 20, false, speed);
  const Tracker without = busThatBrakes(off, 20, false, speed);
  ASSERT_EQ(with.tracks().size(), 1u);
  ASSERT_EQ(without.tracks().size(), 1u);
  EXPECT_EQ(with.tracks()[0].x, without.tracks()[0].x) << "bit for bit as without the step";
  EXPECT_EQ(with.tracks()[0].P, without.tracks()[0].P);
  EXPECT_EQ(with.counts().open_anchor, 0u);
}

TEST(Tracker, FarGrowthFollowsACarComingOutFromBehindAnOccluder)
{
  TrackerParams p;
  ASSERT_TRUE(p.steps.open_anchor);
  ASSERT_TRUE(p.steps.far_growth);
  ASSERT_EQ(p.confirm_hits, 3);
  p.steps.free_space_check = false;
  TrackerParams off = p;
  off.steps.far_growth = false;
  // Its velocity when it is confirmed, the first one reported.
  const Tracker with = carComingOut(p, 3);
  const Tracker without = carComingOut(off, 3);
  ASSERT_EQ(with.tracks().size(), 1u);
  ASSERT_EQ(without.tracks().size(), 1u);
  const double error_with = std::abs(with.tracks()[0].x(2) + kCarSpeed);
  const double error_without = std::abs(without.tracks()[0].x(2) + kCarSpeed);
  EXPECT_GT(error_without, 2.0) << "half of each 1.2 m growth in the sigma keeps the velocity near its prior of 0";
  EXPECT_LT(error_with, 0.5 * error_without);
  EXPECT_EQ(with.counts().far_growth, 2u) << "every association after the first";
  EXPECT_EQ(with.counts().open_anchor, 2u);
  EXPECT_EQ(without.counts().far_growth, 0u);
  TrackerParams no_anchor = p;
  no_anchor.steps.open_anchor = false;
  EXPECT_EQ(carComingOut(no_anchor, 3).counts().far_growth, 0u) << "far growth is a part of step open anchor";
}

TEST(Tracker, FarGrowthLeavesAClusterTurnedOffTheBoxAxes)
{
  TrackerParams p;
  p.steps.free_space_check = false;
  TrackerParams off = p;
  off.steps.far_growth = false;
  const double turn = 0.2;  // rad: more than the 0.1 rad within which two axes are the same
  const Tracker with = carComingOut(p, 4, turn);
  const Tracker without = carComingOut(off, 4, turn);
  ASSERT_EQ(with.tracks().size(), 1u);
  ASSERT_EQ(without.tracks().size(), 1u);
  EXPECT_EQ(with.tracks()[0].x, without.tracks()[0].x) << "bit for bit as without the step";
  EXPECT_EQ(with.tracks()[0].P, without.tracks()[0].P);
  EXPECT_EQ(with.counts().far_growth, 0u);
  EXPECT_GT(with.counts().open_anchor, 0u) << "the open anchor itself still holds";
}

// Step manoeuvres: a car at 10 m/s that brakes at 4 m/s² for 2 s (the default scenario's bus pulling in lagged its
// braking by about 1 m/s for 2 s). Its reported velocity follows with the step; the constant-velocity filter lags.
// Step manoeuvres per class: the IMM for a vehicle, the constant-velocity model alone for a track born of a
// pedestrian's size (and for every track with the step off).
TEST(Tracker, ManoeuvresRunTheImmForVehiclesAndNotForWalkers)
{
  auto born = [](const TrackerParams& p, double length, double width) {
    Tracker tracker(p);
    const std::vector<float> xy = flatten(boxOutline(10.0, 5.0, 0.0, length, width));
    tracker.update(0.0, Pose2{}, ObstaclePoints{ xy.data(), xy.size() / 2 });
    EXPECT_EQ(tracker.tracks().size(), 1u);
    return tracker.tracks().empty() ? Track{} : tracker.tracks()[0];
  };
  TrackerParams p;
  p.min_cluster_points = 4;
  ASSERT_DOUBLE_EQ(p.pedestrian_size, 1.0);
  EXPECT_TRUE(born(p, 4.0, 2.0).manoeuvres) << "a car";
  const Track walker = born(p, 0.6, 0.5);
  EXPECT_LE(std::max(walker.length, walker.width), p.pedestrian_size);
  EXPECT_FALSE(walker.manoeuvres) << "a pedestrian-sized cluster";
  TrackerParams off = p;
  off.steps.manoeuvres = false;
  EXPECT_FALSE(born(off, 4.0, 2.0).manoeuvres);
}

TEST(Tracker, ManoeuvresLetTheReportedVelocityFollowABrakingCar)
{
  auto lag = [](const TrackerParams& p) {
    Tracker tracker(p);
    double error = 0.0;
    int n = 0;
    for (int k = 0; k <= 45; ++k)
    {
      const double t = 0.1 * k, braking = std::clamp(t - 2.0, 0.0, 2.0);
      const double x = 10.0 * t - 2.0 * braking * braking - 8.0 * std::max(0.0, t - 4.0);
      tracker.update(t, { withExtent(at(x, 0.0, 0.15), 4.0, 1.8) });
      EXPECT_EQ(tracker.tracks().size(), 1u) << "scan " << k;
      if (t > 2.0 + 1e-9 && !tracker.tracks().empty())
      {
        error += std::abs(tracker.tracks()[0].velocity().x - (10.0 - 4.0 * braking));
        ++n;
      }
    }
    return error / n;
  };
  TrackerParams on;
  ASSERT_TRUE(on.steps.manoeuvres);
  TrackerParams off = on;
  off.steps.manoeuvres = false;
  const double with = lag(on), without = lag(off);
  EXPECT_GT(without, 0.5) << "the constant-velocity filter lags";
  EXPECT_LT(with, 0.7 * without) << "the IMM follows the braking";
}

TEST(Tracker, ManoeuvreParameterIsValidatedByName)
{
  expectRefusedByName({ { "tracker_manoeuvre_jerk_sigma", [](TrackerParams& p) { p.manoeuvre_jerk_sigma = 0.0; } },
                        { "tracker_manoeuvre_jerk_sigma", [](TrackerParams& p) { p.manoeuvre_jerk_sigma = -1.0; } },
                        { "tracker_manoeuvre_jerk_sigma", [](TrackerParams& p) { p.manoeuvre_jerk_sigma = 101.0; } },
                        { "tracker_manoeuvre_jerk_sigma",
                          [](TrackerParams& p) { p.manoeuvre_jerk_sigma = std::nan(""); } } });
}

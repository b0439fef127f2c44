// Object motion along paths: trapezoidal speed profile, stops, start times, vanishing, rounded corners.
#include <gtest/gtest.h>

#include <cmath>

#include "map_aided_fusion/core/parameters.hpp"
#include "map_aided_fusion/sim/motion.hpp"

using namespace map_aided_fusion;
using namespace map_aided_fusion::sim;

namespace {
constexpr double kTol = 1e-9;
constexpr double kPi = 3.14159265358979323846;

MotionParams straight(double speed, double accel)
{
  MotionParams m;
  m.speed = speed;
  m.acceleration = accel;
  m.corner_radius = 0.0;
  return m;
}
}  // namespace

TEST(SimMotion, CruiseThenBrakeToTheEnd)
{
  // 100 m at 10 m/s, 2 m/s²: braking takes 25 m and 5 s, so cruise ends at 75 m (7.5 s), rest at 12.5 s.
  const PathMotion m({ { 0.0, 0.0 }, { 100.0, 0.0 } }, straight(10.0, 2.0));
  EXPECT_NEAR(m.length(), 100.0, kTol);
  MotionState s = m.at(0.0);
  EXPECT_TRUE(s.present);
  EXPECT_NEAR(s.x, 0.0, kTol);
  EXPECT_NEAR(s.speed, 10.0, kTol);
  EXPECT_NEAR(m.at(1.0).x, 10.0, kTol);
  s = m.at(8.5);  // 1 s into braking: 75 + 10 - 1
  EXPECT_NEAR(s.x, 84.0, kTol);
  EXPECT_NEAR(s.speed, 8.0, kTol);
  EXPECT_NEAR(m.endTime(), 12.5, kTol);
  s = m.at(20.0);
  EXPECT_NEAR(s.x, 100.0, kTol);
  EXPECT_NEAR(s.speed, 0.0, kTol);
  EXPECT_TRUE(s.present);
  EXPECT_NEAR(s.yaw, 0.0, kTol);
}

TEST(SimMotion, StopOnTheWay)
{
  MotionParams p = straight(10.0, 2.0);
  p.stops = { Stop{ 50.0, 3.0 } };
  const PathMotion m({ { 0.0, 0.0 }, { 100.0, 0.0 } }, p);
  // Cruise 25 m (2.5 s), brake 25 m (5 s): at rest at 50 m from 7.5 s to 10.5 s.
  EXPECT_NEAR(m.at(7.5).x, 50.0, kTol);
  EXPECT_NEAR(m.at(9.0).x, 50.0, kTol);
  EXPECT_NEAR(m.at(9.0).speed, 0.0, kTol);
  // 1 s after leaving: 0.5 · 2 · 1² = 1 m.
  EXPECT_NEAR(m.at(11.5).x, 51.0, kTol);
  EXPECT_NEAR(m.at(11.5).speed, 2.0, kTol);
  // 50 m from rest to rest: 25 m up (5 s), 25 m down (5 s).
  EXPECT_NEAR(m.endTime(), 20.5, kTol);
}

TEST(SimMotion, ParkedThenLeavesAndStartTimes)
{
  MotionParams p = straight(5.0, 1.0);
  p.stops = { Stop{ 0.0, 5.0 } };
  p.start_time = 2.0;
  p.end = PathEnd::kVanish;
  const PathMotion m({ { 10.0, 3.0 }, { 10.0, 103.0 } }, p);
  EXPECT_FALSE(m.at(1.9).present);
  EXPECT_TRUE(m.at(2.0).present);
  EXPECT_NEAR(m.at(6.0).y, 3.0, kTol);  // parked until 7 s
  EXPECT_NEAR(m.at(6.0).speed, 0.0, kTol);
  EXPECT_NEAR(m.at(9.0).y, 5.0, kTol);  // 0.5 · 1 · 2²
  EXPECT_NEAR(m.at(9.0).yaw, kPi / 2.0, kTol);
  EXPECT_NEAR(m.at(9.0).vy(), 2.0, kTol);
  // Accelerates for 5 s (12.5 m), cruises 87.5 m (17.5 s) and vanishes at 7 + 22.5 s.
  EXPECT_NEAR(m.endTime(), 29.5, kTol);
  EXPECT_TRUE(m.at(29.4).present);
  EXPECT_FALSE(m.at(29.5).present);
}

TEST(SimMotion, StaticObjectAndForeverStop)
{
  MotionParams p = straight(0.0, 1.0);
  const PathMotion still({ { 4.0, 5.0 } }, p);
  EXPECT_TRUE(still.at(100.0).present);
  EXPECT_NEAR(still.at(100.0).x, 4.0, kTol);
  EXPECT_NEAR(still.at(100.0).speed, 0.0, kTol);

  MotionParams q = straight(10.0, 2.0);
  q.stops = { Stop{ 50.0, std::numeric_limits<double>::infinity() } };
  const PathMotion bus({ { 0.0, 0.0 }, { 100.0, 0.0 } }, q);
  EXPECT_NEAR(bus.at(1000.0).x, 50.0, kTol);
  EXPECT_TRUE(std::isinf(bus.endTime()));
}

TEST(SimMotion, RoundedCornerStaysOnTheArc)
{
  MotionParams p = straight(5.0, 1.0);
  p.corner_radius = 5.0;
  const PathMotion m({ { 0.0, 0.0 }, { 20.0, 0.0 }, { 20.0, 20.0 } }, p);
  // Two straight 15 m pieces and a quarter circle of radius 5 (polygonal, 5 deg steps: a chord per step).
  const double chord = 18 * 2.0 * 5.0 * std::sin(2.5 * kPi / 180.0);
  EXPECT_NEAR(m.length(), 30.0 + chord, 1e-9);
  for (const Point2& q : m.points())
  {
    if (q.x > 15.0 && q.y < 5.0)
    {
      EXPECT_NEAR(std::hypot(q.x - 15.0, q.y - 5.0), 5.0, 1e-9);
    }
  }
  EXPECT_NEAR(m.project(Point2{ 20.0, 10.0 }), 15.0 + chord + 5.0, 1e-9);
  EXPECT_NEAR(m.at(1000.0).yaw, kPi / 2.0, kTol);
}

TEST(SimMotion, InvalidParametersNameThemselves)
{
  MotionParams p = straight(-1.0, 1.0);
  try
  {
    PathMotion m({ { 0.0, 0.0 }, { 1.0, 0.0 } }, p);
    FAIL() << "negative speed accepted";
  }
  catch (const core::ParameterError& e)
  {
    EXPECT_EQ(e.parameter(), "speed");
  }
  EXPECT_THROW(PathMotion({}, straight(1.0, 1.0)), core::ParameterError);
}

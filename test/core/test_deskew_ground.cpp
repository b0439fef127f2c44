// Sweep deskewing and the per-scan ground model on scripted scenes with a known answer.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "map_aided_fusion/core/deskew.hpp"
#include "map_aided_fusion/core/parameters.hpp"
#include "map_aided_fusion/core/scan_grid.hpp"

using namespace map_aided_fusion::core;

namespace {

constexpr double kPi = 3.14159265358979323846;

/// A Velodyne-like point: x, y, z, then its time (float32 s after the stamp).
struct TimedPoint
{
  float x, y, z, t;
};

PointTimeField velodyneTime() { return PointTimeField{ 12, TimeEncoding::kFloat32, 1.0, false, "time" }; }

PointCloudView view(const std::vector<TimedPoint>& pts)
{
  return PointCloudView::packed(pts.data(), pts.size(), sizeof(TimedPoint));
}

/// A wall at x = wall_x (fixed frame), seen from a sensor moving along +x at speed v, one point per firing:
/// firing k of n at τ = k/n · period sees the wall point (wall_x, y_k) from the sensor at (v·τ, 0).
std::vector<TimedPoint> wallFromMovingSensor(double wall_x, double v, double period, int n)
{
  std::vector<TimedPoint> pts;
  for (int k = 0; k < n; ++k)
  {
    const double tau = period * k / n;
    const double y = -10.0 + 20.0 * k / n;
    pts.push_back({ static_cast<float>(wall_x - v * tau), static_cast<float>(y), 1.0f, static_cast<float>(tau) });
  }
  return pts;
}

SweepMotion translationMotion(double v, double duration)
{
  SweepMotion m;
  m.delta = Eigen::Isometry3d::Identity();
  m.delta.translation() = Eigen::Vector3d(v * duration, 0.0, 0.0);
  m.duration = duration;
  return m;
}

}  // namespace

TEST(Deskew, InterpolationEndsAndMiddle)
{
  Eigen::Isometry3d delta = Eigen::Isometry3d::Identity();
  delta.rotate(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()));
  delta.translation() = Eigen::Vector3d(1.5, -0.5, 0.1);
  EXPECT_TRUE(interpolateMotion(delta, 0.0).isApprox(Eigen::Isometry3d::Identity(), 1e-12));
  EXPECT_TRUE(interpolateMotion(delta, 1.0).isApprox(delta, 1e-12));
  const Eigen::Isometry3d half = interpolateMotion(delta, 0.5);
  EXPECT_NEAR(Eigen::AngleAxisd(half.rotation()).angle(), 0.1, 1e-12);
  EXPECT_TRUE(half.translation().isApprox(Eigen::Vector3d(0.75, -0.25, 0.05), 1e-12));
}

TEST(Deskew, StraightWallFromAMovingSensorIsStraightAgain)
{
  constexpr double kWall = 20.0, kSpeed = 15.0, kPeriod = 0.1;
  const std::vector<TimedPoint> pts = wallFromMovingSensor(kWall, kSpeed, kPeriod, 1000);
  // Before: the wall is smeared over v · period = 1.5 m.
  EXPECT_GT(pts.front().x - pts.back().x, 1.4f);
  std::vector<float> out;
  PointCloudView deskewed;
  ASSERT_EQ(deskew(view(pts), velodyneTime(), 0.0, translationMotion(kSpeed, kPeriod), 0.2, out, deskewed),
            DeskewOutcome::kApplied);
  ASSERT_EQ(deskewed.size(), pts.size());
  // The table's step moves a point by at most half a step of the sweep's motion.
  const double tolerance = kSpeed * kPeriod / (kDeskewSteps - 1) + 1e-5;
  for (std::size_t i = 0; i < pts.size(); ++i)
  {
    EXPECT_NEAR(out[3 * i], kWall, tolerance) << i;
    EXPECT_FLOAT_EQ(out[3 * i + 1], pts[i].y);
    EXPECT_FLOAT_EQ(out[3 * i + 2], pts[i].z);
  }
}

TEST(Deskew, MotionFromThePastIsExtrapolated)
{
  constexpr double kWall = 20.0, kSpeed = 10.0, kPeriod = 0.1;
  const std::vector<TimedPoint> pts = wallFromMovingSensor(kWall, kSpeed, kPeriod, 500);
  // The sensor's pose 0.1 s before the stamp, in the frame at the stamp: 1 m behind.
  SweepMotion past;
  past.delta = Eigen::Isometry3d::Identity();
  past.delta.translation() = Eigen::Vector3d(-kSpeed * kPeriod, 0.0, 0.0);
  past.duration = -kPeriod;
  std::vector<float> out;
  PointCloudView deskewed;
  ASSERT_EQ(deskew(view(pts), velodyneTime(), 0.0, past, 0.2, out, deskewed), DeskewOutcome::kApplied);
  for (std::size_t i = 0; i < pts.size(); ++i) EXPECT_NEAR(out[3 * i], kWall, 1e-3) << i;
}

TEST(Deskew, RotatingSensorSeesAFixedDirectionAgain)
{
  // The sensor yaws at ω; a landmark at (10, 0) in the reference frame appears at angle −ω τ at time τ.
  constexpr double kOmega = 1.0, kPeriod = 0.1;
  std::vector<TimedPoint> pts;
  for (int k = 0; k <= 100; ++k)
  {
    const double tau = kPeriod * k / 100.0;
    pts.push_back({ static_cast<float>(10.0 * std::cos(-kOmega * tau)), static_cast<float>(10.0 * std::sin(-kOmega * tau)),
                    0.5f, static_cast<float>(tau) });
  }
  SweepMotion m;
  m.delta = Eigen::Isometry3d(Eigen::AngleAxisd(kOmega * kPeriod, Eigen::Vector3d::UnitZ()));
  m.duration = kPeriod;
  std::vector<float> out;
  PointCloudView deskewed;
  ASSERT_EQ(deskew(view(pts), velodyneTime(), 0.0, m, 0.2, out, deskewed), DeskewOutcome::kApplied);
  for (std::size_t i = 0; i < pts.size(); ++i)
  {
    EXPECT_NEAR(out[3 * i], 10.0, 1e-3);
    EXPECT_NEAR(out[3 * i + 1], 0.0, 1e-3);
    EXPECT_FLOAT_EQ(out[3 * i + 2], 0.5f);
  }
}

TEST(Deskew, NoReturnAndNonFinitePointsAreCopiedUnchanged)
{
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::vector<TimedPoint> pts{ { 0.0f, 0.0f, 0.0f, 0.05f }, { nan, 1.0f, 1.0f, 0.05f }, { 5.0f, 0.0f, 0.0f, 0.1f } };
  std::vector<float> out;
  PointCloudView deskewed;
  ASSERT_EQ(deskew(view(pts), velodyneTime(), 0.0, translationMotion(10.0, 0.1), 0.2, out, deskewed),
            DeskewOutcome::kApplied);
  EXPECT_EQ(out[0], 0.0f);
  EXPECT_EQ(out[1], 0.0f);
  EXPECT_EQ(out[2], 0.0f);
  EXPECT_TRUE(std::isnan(out[3]));
  EXPECT_NEAR(out[6], 6.0f, 1e-5);  // taken 0.1 s later, 1 m further on: 1 m further in the reference frame
}

TEST(Deskew, BadTimesLeaveTheCloudAsItIs)
{
  std::vector<TimedPoint> pts = wallFromMovingSensor(20.0, 10.0, 0.1, 10);
  const SweepMotion m = translationMotion(10.0, 0.1);
  struct Case
  {
    float t;
    DeskewOutcome expected;
  };
  for (const Case c : { Case{ std::numeric_limits<float>::quiet_NaN(), DeskewOutcome::kNonFinite },
                        Case{ std::numeric_limits<float>::infinity(), DeskewOutcome::kNonFinite },
                        Case{ -0.01f, DeskewOutcome::kNegative }, Case{ 0.5f, DeskewOutcome::kOutOfSweep } })
  {
    std::vector<TimedPoint> bad = pts;
    bad[4].t = c.t;
    std::vector<float> out{ 42.0f };
    PointCloudView deskewed;
    EXPECT_EQ(deskew(view(bad), velodyneTime(), 0.0, m, 0.2, out, deskewed), c.expected) << c.t;
    EXPECT_EQ(out, std::vector<float>{ 42.0f });
    double span = -1.0;
    EXPECT_EQ(sweepSpan(view(bad), velodyneTime(), 0.0, 0.2, span), c.expected);
  }
  std::vector<float> out;
  PointCloudView deskewed;
  SweepMotion broken = m;
  broken.duration = 0.0;
  EXPECT_EQ(deskew(view(pts), velodyneTime(), 0.0, broken, 0.2, out, deskewed), DeskewOutcome::kBadMotion);
  broken = m;
  broken.delta.translation().x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(deskew(view(pts), velodyneTime(), 0.0, broken, 0.2, out, deskewed), DeskewOutcome::kBadMotion);
  // A time field that does not fit in the point is refused, not read past the record.
  PointTimeField outside = velodyneTime();
  outside.offset = 14;
  EXPECT_NE(deskew(view(pts), outside, 0.0, m, 0.2, out, deskewed), DeskewOutcome::kApplied);
}

TEST(Deskew, NanosecondAndAbsoluteEncodings)
{
  struct Ouster
  {
    float x, y, z;
    std::uint32_t t;
  };
  struct Hesai
  {
    float x, y, z;
    double stamp;
  };
  const std::vector<Ouster> o{ { 20.0f, 0.0f, 1.0f, 0u }, { 19.0f, 1.0f, 1.0f, 100000000u } };  // 0 and 0.1 s
  const std::vector<Hesai> h{ { 20.0f, 0.0f, 1.0f, 1000.0 }, { 19.0f, 1.0f, 1.0f, 1000.1 } };
  const SweepMotion m = translationMotion(10.0, 0.1);
  std::vector<float> out;
  PointCloudView deskewed;
  ASSERT_EQ(deskew(PointCloudView::packed(o.data(), o.size(), sizeof(Ouster)),
                   PointTimeField{ 12, TimeEncoding::kUint32, 1e-9, false, "t" }, 0.0, m, 0.2, out, deskewed),
            DeskewOutcome::kApplied);
  EXPECT_NEAR(out[3], 20.0f, 1e-3);
  ASSERT_EQ(deskew(PointCloudView::packed(h.data(), h.size(), sizeof(Hesai)),
                   PointTimeField{ 16, TimeEncoding::kFloat64, 1.0, true, "timestamp" }, 1000.0, m, 0.2, out, deskewed),
            DeskewOutcome::kApplied);
  EXPECT_NEAR(out[3], 20.0f, 1e-3);
  double span = 0.0;
  EXPECT_EQ(sweepSpan(PointCloudView::packed(h.data(), h.size(), sizeof(Hesai)),
                      PointTimeField{ 16, TimeEncoding::kFloat64, 1.0, true, "timestamp" }, 1000.0, 0.2, span),
            DeskewOutcome::kApplied);
  EXPECT_NEAR(span, 0.1, 1e-9);
  // Stamped after its points: negative offsets.
  EXPECT_EQ(sweepSpan(PointCloudView::packed(h.data(), h.size(), sizeof(Hesai)),
                      PointTimeField{ 16, TimeEncoding::kFloat64, 1.0, true, "timestamp" }, 1000.05, 0.2, span),
            DeskewOutcome::kNegative);
}

// ---- ground model ---------------------------------------------------------------------------------------------

namespace {

struct P
{
  float x, y, z;
};

/// A ring-sampled ground surface z = g(x, y) from 2 to 60 m around the origin, one point every 360° / @p azimuths
/// and @p step metres (default: 2° and 0.5 m).
template <class G>
std::vector<P> groundSurface(G&& g, int azimuths = 180, double step = 0.5)
{
  std::vector<P> pts;
  for (double r = 2.0; r <= 60.0; r += step)
    for (int a = 0; a < azimuths; ++a)
    {
      const double t = 2.0 * kPi * a / azimuths;
      const float x = static_cast<float>(r * std::cos(t)), y = static_cast<float>(r * std::sin(t));
      pts.push_back({ x, y, static_cast<float>(g(x, y)) });
    }
  return pts;
}

ScanGridParams groundParams(const std::string& model)
{
  ScanGridParams p;
  p.grid_size_x = p.grid_size_y = 120.0;
  p.min_range = 1.0;
  p.max_range = 70.0;
  p.relative_height_limit = 0.0;
  p.ground_model = model;
  return p;
}

ScanGridStats buildStats(const std::string& model, const std::vector<P>& pts, ScanGridBuilder* out = nullptr)
{
  ScanGridBuilder b(groundParams(model), Eigen::Isometry3d::Identity());
  ScanMassGrid grid;
  ScanGridStats st;
  EXPECT_TRUE(b.build(PointCloudView::packed(pts.data(), pts.size(), sizeof(P)), grid, &st));
  if (out) *out = b;
  return st;
}

/// Every plane of @p b is the 5 % grade of the graded-plane tests, and every return in range is ground.
void expectGradedGround(const ScanGridBuilder& b, const ScanGridStats& st, std::size_t points)
{
  for (const GroundPlane& plane : b.groundModel().planes())
  {
    EXPECT_NEAR(plane.a, 0.05, 1e-3);
    EXPECT_NEAR(plane.b, 0.0, 1e-3);
    EXPECT_NEAR(plane.c, -1.8, 0.02);
  }
  EXPECT_EQ(st.ground, points - st.below_min_range - st.beyond_max_range);
  EXPECT_EQ(st.obstacle, 0u);
}

}  // namespace

TEST(GroundModel, ParsesItsNames)
{
  EXPECT_EQ(parseGroundModel("flat"), GroundModel::kFlat);
  EXPECT_EQ(parseGroundModel("planes"), GroundModel::kPlanes);
  EXPECT_STREQ(toString(GroundModel::kPlanes), "planes");
  try
  {
    parseGroundModel("mesh");
    FAIL() << "no error";
  }
  catch (const ParameterError& e)
  {
    EXPECT_EQ(e.parameter(), "ground_model");
  }
  ScanGridParams p;
  p.ground_model = "mesh";
  EXPECT_THROW(p.validate(), ParameterError);
  p = ScanGridParams{};
  p.ground_fit_tolerance = 2.0 * p.ground_search_band;
  try
  {
    p.validate();
    FAIL() << "no error";
  }
  catch (const ParameterError& e)
  {
    EXPECT_EQ(e.parameter(), "ground_fit_tolerance");
  }
  p = ScanGridParams{};
  p.ground_sectors = 0;
  EXPECT_THROW(p.validate(), ParameterError);
  p = ScanGridParams{};
  p.deskew_max_sweep_duration = 0.0;
  EXPECT_THROW(p.validate(), ParameterError);
}

TEST(GroundModel, AGradedPlaneIsFoundInEveryZone)
{
  // 5 % up along x, the sensor's ground 1.8 m below it.
  const auto g = [](double x, double) { return 0.05 * x - 1.8; };
  ScanGridParams params = groundParams("planes");
  params.ground_height = -1.8;
  ScanGridBuilder b(params, Eigen::Isometry3d::Identity());
  const std::vector<P> pts = groundSurface(g);
  ScanMassGrid grid;
  ScanGridStats st;
  ASSERT_TRUE(b.build(PointCloudView::packed(pts.data(), pts.size(), sizeof(P)), grid, &st));
  EXPECT_EQ(st.ground_fit.zones, static_cast<std::size_t>(kGroundRings * params.ground_sectors));
  EXPECT_EQ(st.ground_fit.fitted, st.ground_fit.zones);
  EXPECT_FALSE(st.ground_fit.flat_fallback);
  expectGradedGround(b, st, pts.size());
}

TEST(GroundModel, SlopeAndCamberBreakTheFlatModelNotThePlanes)
{
  // Rolling grade and a 2 % crown across y, and a 1.5 m high box 15 m ahead.
  const auto g = [](double x, double y) { return 0.05 * 50.0 / kPi * std::sin(kPi * x / 50.0) - 0.02 * std::fabs(y); };
  std::vector<P> pts = groundSurface(g);
  std::size_t box = 0;
  for (float y = -1.0f; y <= 1.0f; y += 0.1f)
    for (float z = 0.5f; z <= 1.5f; z += 0.25f, ++box) pts.push_back({ 15.0f, y, static_cast<float>(g(15.0, y)) + z });

  const ScanGridStats flat = buildStats("flat", pts);
  const ScanGridStats planes = buildStats("planes", pts);
  // Flat: the road 20 m away is already 0.5 m up or down: obstacle or below ground.
  EXPECT_GT(flat.obstacle + flat.below_ground, pts.size() / 4);
  // Planes: the box and at most 2 % of the surface (where a zone's plane departs from the curved grade) are
  // obstacles; the surface is ground.
  EXPECT_GE(planes.obstacle, box - box / 5);
  EXPECT_LE(planes.obstacle, box + pts.size() / 50);
  EXPECT_GT(planes.ground, (pts.size() - box) * 95 / 100);
  EXPECT_FALSE(planes.ground_fit.flat_fallback);
}

TEST(GroundModel, AWallIsNotGroundAndTooFewPointsFallBackToFlat)
{
  // Only a wall across the ground band, 12 m ahead, and nothing else: every zone is too steep or too sparse.
  std::vector<P> wall;
  for (float y = -4.0f; y <= 4.0f; y += 0.05f)
    for (float z = -0.5f; z <= 0.5f; z += 0.05f) wall.push_back({ 12.0f, y, z });
  const ScanGridStats st = buildStats("planes", wall);
  EXPECT_GE(st.ground_fit.too_steep, 1u);
  EXPECT_EQ(st.ground_fit.fitted, 0u);
  EXPECT_TRUE(st.ground_fit.flat_fallback);
  // With the flat fallback the split is the flat model's.
  const ScanGridStats flat = buildStats("flat", wall);
  EXPECT_EQ(st.ground, flat.ground);
  EXPECT_EQ(st.obstacle, flat.obstacle);

  const std::vector<P> none;
  const ScanGridStats empty = buildStats("planes", none);
  EXPECT_EQ(empty.ground_fit.few_points, empty.ground_fit.zones);
  EXPECT_TRUE(empty.ground_fit.flat_fallback);
}

TEST(GroundModel, OnFlatGroundPlanesAndFlatAgree)
{
  const auto g = [](double, double) { return 0.0; };
  std::vector<P> pts = groundSurface(g);
  for (float y = -1.0f; y <= 1.0f; y += 0.1f) pts.push_back({ 10.0f, y, 1.0f });
  const ScanGridStats flat = buildStats("flat", pts);
  ScanGridBuilder b;
  const ScanGridStats planes = buildStats("planes", pts, &b);
  EXPECT_EQ(planes.ground, flat.ground);
  EXPECT_EQ(planes.obstacle, flat.obstacle);
  // Deterministic: the same cloud gives the same planes (PCL's RANSAC is seeded).
  ScanGridBuilder again;
  buildStats("planes", pts, &again);
  for (int z = 0; z < b.groundModel().numZones(); ++z)
  {
    EXPECT_EQ(b.groundModel().plane(z).a, again.groundModel().plane(z).a);
    EXPECT_EQ(b.groundModel().plane(z).c, again.groundModel().plane(z).c);
  }
}

TEST(GroundModel, ZonesParseAndLayTheConcentricZones)
{
  EXPECT_EQ(parseGroundModel("zones"), GroundModel::kZones);
  EXPECT_STREQ(toString(GroundModel::kZones), "zones");
  GroundModelParams p;
  p.model = GroundModel::kZones;
  GroundPlaneFitter f;
  f.configure(p);
  int zones = 0;
  for (const int n : kZoneRingSectors) zones += n;
  EXPECT_EQ(f.numZones(), zones);
  EXPECT_EQ(f.numZones(), 504);
  EXPECT_EQ(f.numRings(), static_cast<int>(kZoneRingSectors.size()));
  // Ring edges: a return just inside 7.5 m is in ring 0, just outside in ring 1 (zone 16 on); the last ring has
  // no outer edge; the azimuth picks the sector of the ring.
  EXPECT_EQ(f.zoneOf(7.49f * 7.49f, 0.0f), 0);
  EXPECT_EQ(f.zoneOf(7.51f * 7.51f, 0.0f), 16);
  EXPECT_EQ(f.zoneOf(7.51f * 7.51f, 0.999f), 31);
  EXPECT_EQ(f.zoneOf(12.5f * 12.5f, 0.5f), 32 + 16);
  EXPECT_EQ(f.zoneOf(500.0f * 500.0f, 0.0f), 504 - 32);
  // `planes` keeps its own layout.
  p.model = GroundModel::kPlanes;
  f.configure(p);
  EXPECT_EQ(f.numZones(), kGroundRings * p.sectors);
}

TEST(GroundModel, ZonesFindAGradedPlaneWhereverThereAreReturns)
{
  const auto g = [](double x, double) { return 0.05 * x - 1.8; };
  ScanGridParams params = groundParams("zones");
  params.ground_height = -1.8;
  ScanGridBuilder b(params, Eigen::Isometry3d::Identity());
  const std::vector<P> pts = groundSurface(g, 720, 0.25);  // as dense as a 64-beam lidar's ground
  ScanMassGrid grid;
  ScanGridStats st;
  ASSERT_TRUE(b.build(PointCloudView::packed(pts.data(), pts.size(), sizeof(P)), grid, &st));
  EXPECT_EQ(st.ground_fit.zones, 504u);
  // The surface reaches 60 m: the two outer rings (60.7 m on) hold no return and keep the predicted plane.
  EXPECT_EQ(st.ground_fit.fitted, 504u - 64u);
  EXPECT_EQ(st.ground_fit.few_points, 64u);
  expectGradedGround(b, st, pts.size());
}

TEST(GroundModel, ZonesTakeAnEmbankmentAsGroundAndKeepABoxOnTheRoadAnObstacle)
{
  // A flat road, an embankment rising at 15° from 8 m to the left of it, and a 1.5 m high box 15 m ahead.
  const double rise = std::tan(15.0 * kPi / 180.0);
  const auto g = [rise](double, double y) { return y > 8.0 ? rise * (y - 8.0) : 0.0; };
  std::vector<P> pts = groundSurface(g, 720, 0.25);
  std::size_t embankment = 0;
  for (const P& p : pts) embankment += p.y > 9.0f;
  std::size_t box = 0;
  for (float y = -1.0f; y <= 1.0f; y += 0.1f)
    for (float z = 0.5f; z <= 1.5f; z += 0.25f, ++box) pts.push_back({ 15.0f, y, z });

  const ScanGridStats planes = buildStats("planes", pts);
  const ScanGridStats zones = buildStats("zones", pts);
  // `planes` refuses planes steeper than 5°: most of the embankment stands above its predicted ground.
  EXPECT_GT(planes.obstacle + planes.above_clearance, embankment / 2);
  // `zones` follows it: the box and at most a tenth of the embankment (in the zones that hold its foot and the road:
  // their lowest returns are the road's) remain.
  EXPECT_GE(zones.obstacle, box - box / 5);
  EXPECT_LE(zones.obstacle + zones.above_clearance, box + embankment / 10);
}

TEST(GroundModel, ZonesRefuseAFlatRoofThatDoesNotContinueTheGround)
{
  // A 4 × 8 m flat platform 1.5 m up from 14 m ahead (a truck's bed, a loading dock), nothing under it: the zones it
  // covers fit a flat, level plane that starts 1.5 m above the ground inside them.
  const auto g = [](double, double) { return 0.0; };
  std::vector<P> pts;
  for (const P& p : groundSurface(g, 720, 0.25))
    if (!(p.x >= 14.0f && p.x <= 18.0f && std::fabs(p.y) <= 4.0f)) pts.push_back(p);
  std::size_t platform = 0;
  for (float x = 14.0f; x <= 18.0f; x += 0.1f)
    for (float y = -4.0f; y <= 4.0f; y += 0.1f, ++platform) pts.push_back({ x, y, 1.5f });
  const ScanGridStats zones = buildStats("zones", pts);
  EXPECT_GE(zones.ground_fit.discontinuous, 1u);
  EXPECT_EQ(zones.obstacle, platform);
}

TEST(GroundModel, ConsensusLeavesAReturnTheModelsDisputeWithoutMass)
{
  // A flat road and an embankment rising at 15° from 8 m to its left: `planes` calls the embankment an obstacle
  // (steeper than its 5°), `zones` ground; with step ground consensus its returns are disputed: no occupied cell
  // and no free one on it, and the free space of their sectors still ends at them.
  const double rise = std::tan(15.0 * kPi / 180.0);
  const auto g = [rise](double, double y) { return y > 8.0 ? rise * (y - 8.0) : 0.0; };
  const std::vector<P> pts = groundSurface(g, 720, 0.25);
  ScanGridParams params = groundParams("planes");
  params.ground_consensus = false;
  ScanGridBuilder alone(params, Eigen::Isometry3d::Identity());
  params.ground_consensus = true;
  ScanGridBuilder both(params, Eigen::Isometry3d::Identity());
  ScanMassGrid ga, gb;
  ScanGridStats sa, sb;
  const auto view = PointCloudView::packed(pts.data(), pts.size(), sizeof(P));
  ASSERT_TRUE(alone.build(view, ga, &sa));
  ASSERT_TRUE(both.build(view, gb, &sb));
  EXPECT_EQ(sa.disputed, 0u);
  EXPECT_GT(sb.disputed, sa.obstacle / 2) << "most of what planes alone called obstacle is disputed";
  EXPECT_EQ(sb.obstacle + sb.disputed + sb.ground + sb.height_gap + sb.below_ground + sb.above_clearance +
                sb.low_relief + sb.rejected(),
            sb.points);
  EXPECT_LT(sb.occupied_cells, sa.occupied_cells / 2);
  // Free space never reaches past a disputed return: every cell free with consensus is free without it.
  const float* fa = ga.plane(FrameSG::kF);
  const float* fb = gb.plane(FrameSG::kF);
  std::size_t extra = 0;
  for (std::size_t i = 0; i < ga.numCells(); ++i) extra += fb[i] > 0.0f && fa[i] == 0.0f;
  EXPECT_EQ(extra, 0u);
}

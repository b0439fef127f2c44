// The tracker's parts tested alone (include/map_aided_fusion/core/tracking/): each against its definition.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include <Eigen/LU>

#include "map_aided_fusion/core/tracking/association.hpp"
#include "map_aided_fusion/core/tracking/clustering.hpp"
#include "map_aided_fusion/core/tracking/common_motion.hpp"
#include "map_aided_fusion/core/tracking/lifecycle.hpp"
#include "map_aided_fusion/core/tracking/measurement_model.hpp"
#include "map_aided_fusion/core/tracking/motion_decision.hpp"
#include "map_aided_fusion/core/tracking/motion_model.hpp"
#include "map_aided_fusion/core/tracking/shape_fit.hpp"

namespace map_aided_fusion {
namespace core {
namespace {

/// The clusters by definition: returns whose cells (floor(x / cell), floor(y / cell)) touch, sides or corners, are
/// joined, transitively (a breadth-first search over all pairs); the same order as connectedClusters().
std::vector<std::vector<int>> clustersByDefinition(const std::vector<Point2>& points, double cell)
{
  const int n = static_cast<int>(points.size());
  std::vector<int> label(n, -1);
  std::vector<std::vector<int>> out;
  auto cellOf = [&](int i) {
    return std::pair<long long, long long>(static_cast<long long>(std::floor(points[i].x / cell)),
                                           static_cast<long long>(std::floor(points[i].y / cell)));
  };
  for (int s = 0; s < n; ++s)
  {
    if (label[s] >= 0 || !std::isfinite(points[s].x) || !std::isfinite(points[s].y)) continue;
    const int c = static_cast<int>(out.size());
    std::vector<int> queue{ s }, members;
    label[s] = c;
    while (!queue.empty())
    {
      const int a = queue.back();
      queue.pop_back();
      members.push_back(a);
      for (int b = 0; b < n; ++b)
      {
        if (label[b] >= 0 || !std::isfinite(points[b].x) || !std::isfinite(points[b].y)) continue;
        const auto ca = cellOf(a), cb = cellOf(b);
        if (std::llabs(ca.first - cb.first) <= 1 && std::llabs(ca.second - cb.second) <= 1)
        {
          label[b] = c;
          queue.push_back(b);
        }
      }
    }
    std::sort(members.begin(), members.end());
    out.push_back(members);
  }
  return out;
}

TEST(Clustering, RandomReturnsGiveTheClustersOfTheDefinition)
{
  std::mt19937 rng(11);
  for (int trial = 0; trial < 20; ++trial)
  {
    std::uniform_real_distribution<double> u(-10.0, 10.0);
    std::vector<Point2> points(300);
    for (Point2& p : points) p = Point2{ u(rng), u(rng) };
    const double cell = 0.25 + 0.05 * trial;
    EXPECT_EQ(connectedClusters(points, cell), clustersByDefinition(points, cell)) << "trial " << trial;
  }
}

TEST(Clustering, CornersJoinAGapOfOneCellSeparatesAndBadReturnsAreLeftOut)
{
  const double nan = std::numeric_limits<double>::quiet_NaN();
  // Cells of 1 m: (0.5, 0.5) and (1.5, 1.5) touch by a corner; (3.5, 0.5) is one empty cell away from (1.5, 0.5).
  const std::vector<Point2> points{ { 0.5, 0.5 }, { 3.5, 0.5 }, { nan, 0.0 }, { 1.5, 1.5 }, { 1e20, 0.0 }, { 3.6, 0.6 } };
  const std::vector<std::vector<int>> c = connectedClusters(points, 1.0);
  EXPECT_EQ(c, (std::vector<std::vector<int>>{ { 0, 3 }, { 1, 5 } }));
  EXPECT_TRUE(connectedClusters({}, 1.0).empty());
  EXPECT_TRUE(connectedClusters({ { nan, nan } }, 1.0).empty());
  // Far outliers make the bounding box too large for the dense index: the hash map gives the same clusters.
  std::vector<Point2> far = points;
  far.push_back(Point2{ -5e5, 4e5 });
  std::vector<std::vector<int>> expected = c;
  expected.push_back({ 6 });
  EXPECT_EQ(connectedClusters(far, 1.0), expected);
}

/// The returns of a @p length × @p width rectangle's two sides nearest the origin (an L), turned by @p yaw about
/// (@p cx, @p cy), one every 0.1 m.
std::vector<Point2> lShape(double cx, double cy, double yaw, double length, double width)
{
  std::vector<Point2> out;
  const double c = std::cos(yaw), s = std::sin(yaw);
  auto add = [&](double u, double v) { out.push_back(Point2{ cx + c * u - s * v, cy + s * u + c * v }); };
  for (double u = -0.5 * length; u <= 0.5 * length + 1e-9; u += 0.1) add(u, -0.5 * width);
  for (double v = -0.5 * width + 0.1; v <= 0.5 * width + 1e-9; v += 0.1) add(-0.5 * length, v);
  return out;
}

std::vector<int> all(const std::vector<Point2>& points)
{
  std::vector<int> idx(points.size());
  for (std::size_t i = 0; i < idx.size(); ++i) idx[i] = static_cast<int>(i);
  return idx;
}

/// Angle between two axes, in [0, π/2].
double axisAngle(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return std::acos(std::min(1.0, std::abs(a.dot(b)))); }

TEST(ShapeFit, AnLShapedVehicleGetsItsOwnAxesAndExtents)
{
  BoxFitParams p;  // steps of 3°
  for (const double yaw_deg : { 0.0, 21.0, 30.0, 57.0, 84.0 })
  {
    const double yaw = yaw_deg * M_PI / 180.0;
    const std::vector<Point2> points = lShape(10.0, -4.0, yaw, 4.5, 1.8);
    const ClusterBox box = fitClusterBox(points, all(points), p);
    const Eigen::Vector2d truth(std::cos(yaw), std::sin(yaw));
    EXPECT_LE(axisAngle(box.major, truth), 0.5 * p.step_deg * M_PI / 180.0 + 1e-9) << yaw_deg << "°";
    EXPECT_NEAR(box.length(), 4.5, 0.15) << yaw_deg << "°";
    EXPECT_NEAR(box.width(), 1.8, 0.15) << yaw_deg << "°";
    EXPECT_NEAR(box.major.norm(), 1.0, 1e-12);
    // Every return inside the extents.
    const Eigen::Vector2d minor(-box.major.y(), box.major.x());
    for (const Point2& q : points)
    {
      const Eigen::Vector2d d = Eigen::Vector2d(q.x, q.y) - box.mean;
      EXPECT_GE(d.dot(box.major), box.lo_u - 1e-9);
      EXPECT_LE(d.dot(box.major), box.hi_u + 1e-9);
      EXPECT_GE(d.dot(minor), box.lo_v - 1e-9);
      EXPECT_LE(d.dot(minor), box.hi_v + 1e-9);
    }
  }
}

TEST(ShapeFit, ThePrincipalAxisWhenTheFitIsOffTooShortOrTooLong)
{
  const std::vector<Point2> points = lShape(0.0, 0.0, 0.5, 4.5, 1.8);
  BoxFitParams off;
  off.enabled = false;
  const ClusterBox principal = fitClusterBox(points, all(points), off);
  EXPECT_FALSE(principal.fitted);
  // The L's principal axis lies between its sides: not the vehicle's axis.
  EXPECT_GT(axisAngle(principal.major, Eigen::Vector2d(std::cos(0.5), std::sin(0.5))), 0.05);
  const ClusterBox fitted = fitClusterBox(points, all(points), BoxFitParams{});
  EXPECT_TRUE(fitted.fitted);
  EXPECT_EQ(fitted.major, fittedAxis(points, all(points), fitted.mean, principal.major, BoxFitParams{}));
  BoxFitParams short_only;
  short_only.min_length = 10.0;  // longer than the cluster
  EXPECT_EQ(fitClusterBox(points, all(points), short_only).major, principal.major);
  BoxFitParams long_only;
  long_only.max_length = 2.0;  // √2 · 2 m is shorter than the cluster
  EXPECT_EQ(fitClusterBox(points, all(points), long_only).major, principal.major);
  // One return: its own mean, no extent.
  const ClusterBox one = fitClusterBox(points, { 3 }, BoxFitParams{});
  EXPECT_EQ(one.mean, Eigen::Vector2d(points[3].x, points[3].y));
  EXPECT_EQ(one.length(), 0.0);
  EXPECT_EQ(one.width(), 0.0);
}

/// A random symmetric positive definite matrix: A Aᵀ + I·floor.
template <int N>
Eigen::Matrix<double, N, N> randomSpd(std::mt19937& rng, double floor)
{
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::Matrix<double, N, N> a;
  for (int i = 0; i < N; ++i)
    for (int j = 0; j < N; ++j) a(i, j) = u(rng);
  return a * a.transpose() + floor * Eigen::Matrix<double, N, N>::Identity();
}

TEST(MotionModel, PredictionMovesAtConstantVelocityAndAddsTheWhiteNoiseAccelerationCovariance)
{
  std::mt19937 rng(5);
  const Eigen::Matrix4d p0 = randomSpd<4>(rng, 0.1);
  Eigen::Vector4d x(1.0, 2.0, 3.0, -1.0);
  Eigen::Matrix4d p = p0;
  const double dt = 0.3, sa = 0.7;
  predictConstantVelocity(x, p, dt, sa);
  EXPECT_NEAR(x(0), 1.0 + 3.0 * dt, 1e-15);
  EXPECT_NEAR(x(1), 2.0 - 1.0 * dt, 1e-15);
  EXPECT_EQ(x(2), 3.0);
  EXPECT_EQ(x(3), -1.0);
  // Element by element: P'ij = Σ F_ik P_kl F_jl + Q_ij, F = I + dt (e₀e₂ᵀ + e₁e₃ᵀ).
  auto f = [dt](int i, int k) { return (i == k ? 1.0 : 0.0) + ((i == 0 && k == 2) || (i == 1 && k == 3) ? dt : 0.0); };
  const double q = sa * sa;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
    {
      double expected = 0.0;
      for (int k = 0; k < 4; ++k)
        for (int l = 0; l < 4; ++l) expected += f(i, k) * p0(k, l) * f(j, l);
      const bool pos_i = i < 2, pos_j = j < 2, same_axis = i % 2 == j % 2;
      if (same_axis)
        expected += pos_i && pos_j ? q * std::pow(dt, 4) / 4.0 : (pos_i || pos_j ? q * std::pow(dt, 3) / 2.0 : q * dt * dt);
      EXPECT_NEAR(p(i, j), expected, 1e-12) << i << "," << j;
    }
  // No time, no change.
  Eigen::Vector4d x0 = x;
  Eigen::Matrix4d p1 = p;
  predictConstantVelocity(x0, p1, 0.0, sa);
  EXPECT_EQ(x0, x);
  EXPECT_EQ(p1, p);
}

TEST(MotionModel, CorrectionEqualsTheInformationFormOfTheKalmanUpdate)
{
  std::mt19937 rng(6);
  Eigen::Matrix<double, 2, 4> h = Eigen::Matrix<double, 2, 4>::Zero();
  h(0, 0) = h(1, 1) = 1.0;
  for (int trial = 0; trial < 20; ++trial)
  {
    const Eigen::Matrix4d p0 = randomSpd<4>(rng, 0.05);
    const Eigen::Matrix2d r = randomSpd<2>(rng, 0.01);
    const Eigen::Vector4d x0 = Eigen::Vector4d::Random();
    const Eigen::Vector2d z = Eigen::Vector2d::Random();
    Eigen::Vector4d x = x0;
    Eigen::Matrix4d p = p0;
    correctPosition(x, p, z, r);
    // (P⁻¹ + Hᵀ R⁻¹ H)⁻¹ and P' (P⁻¹ x + Hᵀ R⁻¹ z).
    const Eigen::Matrix4d info = p0.inverse() + h.transpose() * r.inverse() * h;
    const Eigen::Matrix4d expected_p = info.inverse();
    const Eigen::Vector4d expected_x = expected_p * (p0.inverse() * x0 + h.transpose() * r.inverse() * z);
    EXPECT_LT((p - expected_p).cwiseAbs().maxCoeff(), 1e-9) << trial;
    EXPECT_LT((x - expected_x).cwiseAbs().maxCoeff(), 1e-9) << trial;
    EXPECT_LT((p - p.transpose()).cwiseAbs().maxCoeff(), 1e-12) << trial;
  }
}

TEST(MotionModel, AnExactMeasurementPinsThePositionAndAVagueOneChangesNothing)
{
  const Eigen::Vector4d x0(1.0, 1.0, 2.0, 0.0);
  const Eigen::Matrix4d p0 = Eigen::Matrix4d::Identity();
  const Eigen::Vector2d z(3.0, -2.0);
  Eigen::Vector4d x = x0;
  Eigen::Matrix4d p = p0;
  correctPosition(x, p, z, 1e-12 * Eigen::Matrix2d::Identity());
  EXPECT_NEAR(x(0), 3.0, 1e-9);
  EXPECT_NEAR(x(1), -2.0, 1e-9);
  EXPECT_NEAR(p(0, 0), 0.0, 1e-9);
  // Position and velocity uncorrelated in P: the velocity learns nothing.
  EXPECT_EQ(x(2), 2.0);
  EXPECT_EQ(x(3), 0.0);
  x = x0;
  p = p0;
  correctPosition(x, p, z, 1e12 * Eigen::Matrix2d::Identity());
  EXPECT_LT((x - x0).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((p - p0).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(MotionModel, TheSpeedSigmaIsAlongTheVelocityOrTheLargestWithoutOne)
{
  Eigen::Matrix4d p = Eigen::Matrix4d::Identity();
  p(2, 2) = 4.0;  // σ(vx) = 2
  p(3, 3) = 1.0;  // σ(vy) = 1
  EXPECT_DOUBLE_EQ(speedSigma(Eigen::Vector4d(0, 0, 5.0, 0.0), p), 2.0);
  EXPECT_DOUBLE_EQ(speedSigma(Eigen::Vector4d(0, 0, 0.0, -3.0), p), 1.0);
  EXPECT_NEAR(speedSigma(Eigen::Vector4d::Zero(), p), 2.0, 1e-12);
  // Along (1, 1)/√2: √((4 + 1 + 2·c) / 2) with the covariance c.
  p(2, 3) = p(3, 2) = 0.5;
  EXPECT_NEAR(speedSigma(Eigen::Vector4d(0, 0, 1.0, 1.0), p), std::sqrt(3.0), 1e-12);
  EXPECT_NEAR(velocitySigmaAlong(p, Eigen::Vector2d(1.0, -1.0).normalized()), std::sqrt(2.0), 1e-12);
}

TEST(MotionModel, ConstantAccelerationPredictionFollowsItsDefinition)
{
  ImmVector x;
  x << 1.0, 2.0, 10.0, -1.0, -4.0, 0.5;
  ImmMatrix p = ImmMatrix::Identity() * 0.5;
  const double dt = 0.1, sj = 3.0;
  predictConstantAcceleration(x, p, dt, sj);
  EXPECT_NEAR(x(0), 1.0 + 10.0 * dt - 0.5 * 4.0 * dt * dt, 1e-15);
  EXPECT_NEAR(x(1), 2.0 - 1.0 * dt + 0.5 * 0.5 * dt * dt, 1e-15);
  EXPECT_NEAR(x(2), 10.0 - 4.0 * dt, 1e-15);
  EXPECT_NEAR(x(3), -1.0 + 0.5 * dt, 1e-15);
  EXPECT_EQ(x(4), -4.0);
  EXPECT_EQ(x(5), 0.5);
  // From P = 0.5 I: P' = 0.5 F Fᵀ + Q; on one axis (indices 0, 2, 4) F = [1, dt, dt²/2; 0, 1, dt; 0, 0, 1].
  const double q = sj * sj, dt2 = dt * dt;
  const double f[3][3] = { { 1.0, dt, 0.5 * dt2 }, { 0.0, 1.0, dt }, { 0.0, 0.0, 1.0 } };
  const double qb[3][3] = { { std::pow(dt, 5) / 20.0, std::pow(dt, 4) / 8.0, std::pow(dt, 3) / 6.0 },
                            { std::pow(dt, 4) / 8.0, std::pow(dt, 3) / 3.0, dt2 / 2.0 },
                            { std::pow(dt, 3) / 6.0, dt2 / 2.0, dt } };
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
    {
      double ffT = 0.0;
      for (int k = 0; k < 3; ++k) ffT += f[i][k] * f[j][k];
      EXPECT_NEAR(p(2 * i, 2 * j), 0.5 * ffT + q * qb[i][j], 1e-12) << i << "," << j;
      EXPECT_NEAR(p(2 * i + 1, 2 * j + 1), p(2 * i, 2 * j), 1e-15);
      EXPECT_EQ(p(2 * i, 2 * j + 1), 0.0) << "the axes stay independent";
    }
}

/// A car at 10 m/s along x that brakes at 4 m/s² from t = 2 s to t = 4 s, then drives on at 2 m/s, its position
/// measured every 0.1 s with noise σ = 0.15 m (seeded); the mean |velocity error| (m/s) of the constant-velocity
/// filter (σa 2 m/s²) or of the IMM (with it and jerk σ 5 m/s³) over the braking and the 0.5 s after, and the IMM's
/// largest manoeuvre probability in that time and its last one at constant speed before it (through @p mu).
double brakingError(bool imm, double* mu_braking = nullptr, double* mu_quiet = nullptr)
{
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.15);
  const Eigen::Matrix2d r = 0.15 * 0.15 * Eigen::Matrix2d::Identity();
  const ManoeuvreModel model{ 2.0, 5.0, 0.5, 2.0 };
  Eigen::Vector4d x(0.0, 0.0, 10.0, 0.0);
  Eigen::Matrix4d p = Eigen::Matrix4d::Identity();
  ImmState s;
  s.reset(x, p, 4.0, model.stationaryManoeuvre());
  double error = 0.0, top = 0.0;
  int n = 0;
  for (int k = 1; k <= 60; ++k)
  {
    const double t = 0.1 * k, braking = std::clamp(t - 2.0, 0.0, 2.0);
    const double v = 10.0 - 4.0 * braking;
    const double pos = 10.0 * t - 2.0 * braking * braking - 8.0 * std::max(0.0, t - 4.0);
    const Eigen::Vector2d z(pos + noise(rng), noise(rng));
    if (imm)
    {
      predictImm(s, 0.1, model);
      correctImm(s, z, r);
      s.combine(x, p);
    }
    else
    {
      predictConstantVelocity(x, p, 0.1, 2.0);
      correctPosition(x, p, z, r);
    }
    if (imm)
    {
      EXPECT_NEAR(s.mu.sum(), 1.0, 1e-12);
      EXPECT_GE(s.mu.minCoeff(), 0.0);
    }
    if (k == 20 && mu_quiet) *mu_quiet = s.mu(1);
    if (t > 2.0 + 1e-9 && t <= 4.5 + 1e-9)
    {
      error += std::abs(x(2) - v);
      top = std::max(top, s.mu(1));
      ++n;
    }
  }
  if (mu_braking) *mu_braking = top;
  return error / n;
}

TEST(MotionModel, TheImmFollowsBrakingThatTheConstantVelocityFilterLags)
{
  double mu_braking = 0.0, mu_quiet = 1.0;
  const double cv = brakingError(false), imm = brakingError(true, &mu_braking, &mu_quiet);
  EXPECT_GT(cv, 0.5) << "the constant-velocity filter lags a 4 m/s² braking";
  EXPECT_LT(imm, 0.6 * cv) << "the IMM follows it";
  EXPECT_LT(mu_quiet, 0.2) << "at constant speed the quiet model explains the scans";
  EXPECT_GT(mu_braking, 0.5) << "while braking the manoeuvring one does";
}

TEST(MotionModel, TheImmOfAgreeingModelsIsThatModelAndItsShiftMovesEveryModel)
{
  ImmState s;
  Eigen::Vector4d x0(3.0, -2.0, 1.0, 0.5);
  Eigen::Matrix4d p0 = Eigen::Matrix4d::Identity();
  s.reset(x0, p0, 0.0, 0.3);
  Eigen::Vector4d x;
  Eigen::Matrix4d p;
  s.combine(x, p);
  EXPECT_EQ(x, x0);
  EXPECT_EQ(p, p0);
  s.shiftPosition(Eigen::Vector2d(0.5, -1.0));
  s.combine(x, p);
  EXPECT_EQ(x, Eigen::Vector4d(3.5, -3.0, 1.0, 0.5));
  // With the models apart, the mixture's covariance holds their spread: μ0 μ1 d dᵀ added.
  s.x[1](2) += 2.0;
  s.combine(x, p);
  EXPECT_NEAR(x(2), 1.0 + 0.3 * 2.0, 1e-15);
  EXPECT_NEAR(p(2, 2), 1.0 + 0.7 * 0.3 * 4.0, 1e-12);
}

/// The candidate pairs by definition: every (row, column) whose discs meet.
std::vector<std::pair<int, int>> meetingDiscs(const std::vector<GateDisc>& rows, const std::vector<GateDisc>& cols)
{
  std::vector<std::pair<int, int>> out;
  for (int i = 0; i < static_cast<int>(rows.size()); ++i)
    for (int j = 0; j < static_cast<int>(cols.size()); ++j)
      if (std::hypot(rows[i].centre.x - cols[j].centre.x, rows[i].centre.y - cols[j].centre.y) <=
          rows[i].radius + cols[j].radius)
        out.emplace_back(i, j);
  return out;
}

TEST(Association, TheSpatialGateFindsEveryPairOfMeetingDiscsOnce)
{
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> pos(-60.0, 60.0), rad(0.0, 4.0);
  for (int trial = 0; trial < 20; ++trial)
  {
    std::vector<GateDisc> rows(30), cols(40);
    for (GateDisc& d : rows) d = GateDisc{ Point2{ pos(rng), pos(rng) }, rad(rng) };
    for (GateDisc& d : cols) d = GateDisc{ Point2{ pos(rng), pos(rng) }, rad(rng) };
    if (trial % 4 == 1) cols[3].radius = 5000.0;  // wider than kMaxGateCells cells: met through the wide list
    if (trial % 4 == 2) rows[5].radius = std::numeric_limits<double>::infinity();
    if (trial % 4 == 3) cols[7].centre.x = std::numeric_limits<double>::quiet_NaN();
    const double cell = trial % 2 ? 2.0 : 0.5;
    std::vector<std::pair<int, int>> found = spatialGate(rows, cols, cell);
    EXPECT_TRUE(std::is_sorted(found.begin(), found.end(),
                               [](const auto& a, const auto& b) { return a.first < b.first; }));
    std::vector<std::pair<int, int>> sorted = found;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(std::adjacent_find(sorted.begin(), sorted.end()), sorted.end()) << "a pair twice";
    EXPECT_EQ(sorted, meetingDiscs(rows, cols)) << trial;
  }
  EXPECT_TRUE(spatialGate({}, { GateDisc{} }, 1.0).empty());
  EXPECT_TRUE(spatialGate({ GateDisc{} }, {}, 1.0).empty());
  EXPECT_TRUE(spatialGate({ GateDisc{} }, { GateDisc{} }, 0.0).empty());
  // Touching discs meet; a millimetre apart they do not.
  EXPECT_EQ(spatialGate({ GateDisc{ Point2{ 0.0, 0.0 }, 1.0 } }, { GateDisc{ Point2{ 2.0, 0.0 }, 1.0 } }, 1.0).size(), 1u);
  EXPECT_TRUE(spatialGate({ GateDisc{ Point2{ 0.0, 0.0 }, 1.0 } }, { GateDisc{ Point2{ 2.001, 0.0 }, 1.0 } }, 1.0).empty());
}

TEST(Association, TheStatisticalGateIsTheMahalanobisDistanceWithinBothGates)
{
  const Eigen::Vector2d y(3.0, 4.0);  // |y| = 5
  const Eigen::Matrix2d s = Eigen::Vector2d(4.0, 16.0).asDiagonal();
  const double d2 = 9.0 / 4.0 + 16.0 / 16.0;
  ASSERT_TRUE(mahalanobisGate(y, s, 10.0, 9.21).has_value());
  EXPECT_DOUBLE_EQ(*mahalanobisGate(y, s, 10.0, 9.21), d2);
  EXPECT_DOUBLE_EQ(*mahalanobisGate(y, s, 5.0, d2), d2);  // both limits inclusive
  EXPECT_FALSE(mahalanobisGate(y, s, 4.99, 9.21).has_value());
  EXPECT_FALSE(mahalanobisGate(y, s, 10.0, 3.0).has_value());
  // A covariance that lost its definiteness gives no pair.
  EXPECT_FALSE(mahalanobisGate(y, -s, 10.0, 9.21).has_value());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(mahalanobisGate(y, Eigen::Matrix2d::Constant(nan), 10.0, 9.21).has_value());
}

TEST(MotionDecision, MovingWhenTheSpeedClearsTheFloorByTheSigmas)
{
  const MotionDecisionParams p;  // moving 0.5 m/s, 1.5 σ; with free space 0.5 σ
  double still = -1.0;
  MotionEvidence e;
  e.speed = 2.0;
  e.speed_sigma = 0.5;  // 2 − 0.75 > 0.5
  EXPECT_EQ(decideMotion(e, 1.0, still, p), TrackMotion::kMoving);
  e.tentative = true;
  still = 0.25;
  EXPECT_EQ(decideMotion(e, 1.0, still, p), TrackMotion::kUnknown);
  EXPECT_EQ(still, 0.25) << "a tentative track's stillness is left as it is";
  e.tentative = false;
  e.speed = 0.5 + 1.5 * 0.5;  // exactly on the floor: not cleared
  EXPECT_EQ(decideMotion(e, 1.0, still, p), TrackMotion::kUnknown);
  // With the free-space check: fewer sigmas, but only once free space has shown the motion.
  e.speed = 1.0;  // 1 − 0.25 > 0.5, 1 − 0.75 < 0.5
  e.free_space_check = true;
  EXPECT_EQ(decideMotion(e, 1.0, still, p), TrackMotion::kUnknown);
  e.motion_seen = true;
  EXPECT_EQ(decideMotion(e, 1.0, still, p), TrackMotion::kMoving);
  e.free_space_check = false;
  EXPECT_EQ(decideMotion(e, 1.0, still, p), TrackMotion::kUnknown);
  EXPECT_TRUE(clearsSpeed(1.0, 0.25, 1.0, 0.5));
  EXPECT_FALSE(clearsSpeed(1.0, 0.5, 1.0, 0.5));
}

TEST(MotionDecision, StoppedOnlyAfterStandingStillForTheStoppedTime)
{
  const MotionDecisionParams p;  // stopped below 0.8 m/s at 1.5 σ for 1 s
  MotionEvidence slow;
  slow.speed = 0.1;
  slow.speed_sigma = 0.1;  // 0.1 + 0.15 < 0.8
  double still = -1.0;
  EXPECT_EQ(decideMotion(slow, 10.0, still, p), TrackMotion::kUnknown);
  EXPECT_EQ(still, 10.0);
  EXPECT_EQ(decideMotion(slow, 10.5, still, p), TrackMotion::kUnknown);
  EXPECT_EQ(decideMotion(slow, 11.0, still, p), TrackMotion::kStopped);
  EXPECT_EQ(still, 10.0);
  // Not confidently slow (its σ): stillness is over, and starts again from the next slow scan.
  MotionEvidence unsure = slow;
  unsure.speed_sigma = 0.5;  // 0.1 + 0.75 ≥ 0.8
  EXPECT_EQ(decideMotion(unsure, 11.1, still, p), TrackMotion::kUnknown);
  EXPECT_EQ(still, -1.0);
  EXPECT_EQ(decideMotion(slow, 11.2, still, p), TrackMotion::kUnknown);
  EXPECT_EQ(decideMotion(slow, 12.2, still, p), TrackMotion::kStopped);
}

TEST(Lifecycle, SpawnConfirmCoastAndPrune)
{
  const LifecycleParams p{ 3, 0.5 };
  EXPECT_EQ(bornState(p), TrackState::kTentative);
  EXPECT_EQ(bornState(LifecycleParams{ 1, 0.5 }), TrackState::kConfirmed);
  EXPECT_EQ(afterHit(TrackState::kTentative, 2, p), TrackState::kTentative);
  EXPECT_EQ(afterHit(TrackState::kTentative, 3, p), TrackState::kConfirmed);
  EXPECT_EQ(afterHit(TrackState::kConfirmed, 1, p), TrackState::kConfirmed);
  EXPECT_EQ(afterHit(TrackState::kCoasting, 1, p), TrackState::kConfirmed);
  EXPECT_EQ(afterMiss(TrackState::kConfirmed), TrackState::kCoasting);
  EXPECT_EQ(afterMiss(TrackState::kCoasting), TrackState::kCoasting);
  EXPECT_EQ(afterMiss(TrackState::kTentative), TrackState::kTentative);
  // A tentative track dies at its first miss; a coasting one after max_coast_time unseen; a confirmed one never.
  EXPECT_TRUE(expired(TrackState::kTentative, true, 0.1, p));
  EXPECT_FALSE(expired(TrackState::kTentative, false, 0.0, p));
  EXPECT_FALSE(expired(TrackState::kCoasting, true, 0.5, p));
  EXPECT_TRUE(expired(TrackState::kCoasting, true, 0.51, p));
  EXPECT_FALSE(expired(TrackState::kConfirmed, true, 10.0, p));
}

/// @p n tracks on a ring of radius 5–40 m around @p sensor moving with the rigid motion v0 + ω × (p − sensor).
std::vector<SeenTrack> rigidlyMoving(int n, Point2 sensor, Point2 v0, double omega, double sigma)
{
  std::vector<SeenTrack> seen;
  for (int i = 0; i < n; ++i)
  {
    const double a = 2.0 * M_PI * i / n, r = 5.0 + 35.0 * i / n;
    const Point2 p{ sensor.x + r * std::cos(a), sensor.y + r * std::sin(a) };
    seen.push_back(SeenTrack{ p, Point2{ v0.x - omega * (p.y - sensor.y), v0.y + omega * (p.x - sensor.x) }, sigma });
  }
  return seen;
}

TEST(CommonMotion, ASharedDriftIsFoundAndATurnAboutTheSensorIsFitted)
{
  const CommonMotionParams p;  // 20 tracks, more than half agreeing, ≤ 2 m/s, ≤ 0.05 rad/s
  const Point2 sensor{ 100.0, -20.0 };
  // The same velocity everywhere: the median; no turn.
  const CommonMotion drift = fitCommonMotion(rigidlyMoving(25, sensor, Point2{ 0.8, -0.4 }, 0.0, 0.2), &sensor, p);
  ASSERT_TRUE(drift.found);
  EXPECT_EQ(drift.velocity.x, 0.8);
  EXPECT_EQ(drift.velocity.y, -0.4);
  EXPECT_EQ(drift.turn_rate, 0.0);
  // A heading drift of 0.03 rad/s: v₀ and ω of the rigid motion.
  const std::vector<SeenTrack> turning = rigidlyMoving(25, sensor, Point2{ 0.3, 0.1 }, 0.03, 0.2);
  const CommonMotion turn = fitCommonMotion(turning, &sensor, p);
  ASSERT_TRUE(turn.found);
  EXPECT_NEAR(turn.turn_rate, 0.03, 1e-9);
  EXPECT_NEAR(turn.velocity.x, 0.3, 1e-9);
  EXPECT_NEAR(turn.velocity.y, 0.1, 1e-9);
  for (const SeenTrack& s : turning)
  {
    EXPECT_NEAR(turn.at(s.position).x, s.velocity.x, 1e-8);
    EXPECT_NEAR(turn.at(s.position).y, s.velocity.y, 1e-8);
  }
  // Without the sensor, or with the turn off, no turn: the median's few agree (far tracks move faster), not found.
  CommonMotionParams no_turn = p;
  no_turn.turn = false;
  EXPECT_FALSE(fitCommonMotion(turning, &sensor, no_turn).found);
  EXPECT_FALSE(fitCommonMotion(turning, nullptr, p).found);
  // Turning faster than max_turn_rate is not a drift.
  EXPECT_FALSE(fitCommonMotion(rigidlyMoving(25, sensor, Point2{ 0.3, 0.1 }, 0.2, 0.2), &sensor, p).found);
}

TEST(CommonMotion, TooFewTracksTrafficOrAMixIsNoCommonMotion)
{
  const CommonMotionParams p;
  const Point2 sensor{ 0.0, 0.0 };
  EXPECT_FALSE(fitCommonMotion(rigidlyMoving(19, sensor, Point2{ 0.5, 0.0 }, 0.0, 0.2), &sensor, p).found);
  EXPECT_TRUE(fitCommonMotion(rigidlyMoving(20, sensor, Point2{ 0.5, 0.0 }, 0.0, 0.2), &sensor, p).found);
  EXPECT_FALSE(fitCommonMotion({}, &sensor, p).found);
  // Faster than max_speed: traffic.
  EXPECT_FALSE(fitCommonMotion(rigidlyMoving(25, sensor, Point2{ 2.5, 0.0 }, 0.0, 0.2), &sensor, p).found);
  // Half one way, half the other: no motion shared by more than half.
  std::vector<SeenTrack> mix = rigidlyMoving(12, sensor, Point2{ 1.0, 0.0 }, 0.0, 0.1);
  for (const SeenTrack& s : rigidlyMoving(12, sensor, Point2{ -1.0, 0.0 }, 0.0, 0.1)) mix.push_back(s);
  const CommonMotion none = fitCommonMotion(mix, &sensor, p);
  EXPECT_FALSE(none.found);
  EXPECT_EQ(none.velocity.x, 0.0);
  EXPECT_EQ(none.turn_rate, 0.0);
}

TEST(MeasurementModel, AClusterCovarianceHasItsExtentGrownSigmaAlongEachBoxAxis)
{
  ClusterBox box;
  box.mean = Eigen::Vector2d(1.0, 2.0);
  box.major = Eigen::Vector2d(std::cos(0.5), std::sin(0.5));
  box.lo_u = -2.0;
  box.hi_u = 2.0;
  box.lo_v = -0.9;
  box.hi_v = 0.9;
  const MeasurementModelParams p;  // 0.15 m + 0.1 m per metre
  const Measurement m = measurementOf(box, { 4, 5, 6 }, p);
  EXPECT_EQ(m.points, 3);
  EXPECT_DOUBLE_EQ(m.length, 4.0);
  EXPECT_DOUBLE_EQ(m.width, 1.8);
  EXPECT_NEAR(m.yaw, 0.5, 1e-15);
  const Eigen::Vector2d minor(-box.major.y(), box.major.x());
  const double su = 0.15 + 0.1 * 4.0, sv = 0.15 + 0.1 * 1.8;
  EXPECT_LT((m.covariance * box.major - su * su * box.major).norm(), 1e-12);
  EXPECT_LT((m.covariance * minor - sv * sv * minor).norm(), 1e-12);
}

/// A cluster centred at (10, 0) along x, @p length long and 1.8 m wide, seen from the origin.
Measurement clusterAlongX(double length)
{
  Measurement m;
  m.centroid = Point2{ 10.0, 0.0 };
  m.yaw = 0.0;
  m.length = length;
  m.width = 1.8;
  m.lo_u = -0.5 * length;
  m.hi_u = 0.5 * length;
  m.lo_v = -0.9;
  m.hi_v = 0.9;
  const double su = 0.15 + 0.1 * length, sv = 0.15 + 0.1 * 1.8;
  m.covariance = Eigen::Vector2d(su * su, sv * sv).asDiagonal();
  m.has_sensor = true;
  m.sensor = Point2{ 0.0, 0.0 };
  return m;
}

TEST(MeasurementModel, TheAnchorIsTheBoxPlacedOnTheClustersAnchoringEnd)
{
  const TrackView car{ 0.0, 4.0, 1.8, 4.0, 1.8, false };  // a 4 × 1.8 m box along x
  // Its rear metre seen: the box placed on the end nearest the sensor (x = 9.5), its centre 2 m beyond.
  const Measurement rear = clusterAlongX(1.0);
  EXPECT_NEAR(anchorPoint(car, rear).x, 9.5 + 2.0, 1e-12);
  EXPECT_NEAR(anchorPoint(car, rear).y, 0.0, 1e-12);
  // Seen whole (within kAnchorTolerance): the middle of the cluster.
  EXPECT_NEAR(anchorPoint(car, clusterAlongX(3.8)).x, 10.0, 1e-12);
  // Its near end cut by an occluder and free space beyond its far end: placed on the far end (x = 10.5).
  Measurement cut = rear;
  cut.ends_seen = true;
  cut.occluded = Measurement::kLowU;
  cut.open = Measurement::kHighU;
  EXPECT_NEAR(anchorPoint(car, cut).x, 10.5 - 2.0, 1e-12);
  // Without the sensor, or a box: the centroid.
  Measurement blind = rear;
  blind.has_sensor = false;
  EXPECT_EQ(anchorPoint(car, blind).x, 10.0);
  EXPECT_EQ(anchorPoint(TrackView{}, rear).x, 10.0);
}

TEST(MeasurementModel, TheAnchorCovarianceGrowsWithTheChangeOfExtentAndTheHiddenOrOpenEnds)
{
  const MeasurementModelParams p;
  const TrackView car{ 0.0, 4.0, 1.8, 4.0, 1.8, false };
  const Measurement whole = clusterAlongX(4.0);
  EXPECT_EQ(anchorCovariance(car, whole, p), whole.covariance) << "the same extents: the cluster's own";
  // 2 m shorter than the last cluster: half of it, 1 m, of σ added along the major axis.
  const Measurement shorter = clusterAlongX(2.0);
  Eigen::Matrix2d expected = shorter.covariance;
  expected(0, 0) += 1.0;
  EXPECT_LT((anchorCovariance(car, shorter, p) - expected).norm(), 1e-12);
  // Both ends hidden, neither open: hidden_ends_sigma along the axis, for a track not yet moving only.
  Measurement gap = whole;
  gap.ends_seen = true;
  gap.occluded = Measurement::kLowU | Measurement::kHighU;
  EXPECT_TRUE(hiddenEnds(car, gap, p));
  expected = whole.covariance;
  expected(0, 0) += p.hidden_ends_sigma * p.hidden_ends_sigma;
  EXPECT_LT((anchorCovariance(car, gap, p) - expected).norm(), 1e-12);
  TrackView moving = car;
  moving.moving = true;
  EXPECT_FALSE(hiddenEnds(moving, gap, p));
  EXPECT_EQ(anchorCovariance(moving, gap, p), whole.covariance);
  // Its anchoring (near) end open, along the box's axes: a compact cluster's σ along the axis, no growth (far growth).
  Measurement open = shorter;
  open.ends_seen = true;
  open.open = Measurement::kLowU;
  EXPECT_TRUE(openAnchor(car, open, p));
  EXPECT_TRUE(farGrowth(car, open, p, true));
  const double sv = 0.15 + 0.1 * 1.8;
  EXPECT_LT((anchorCovariance(car, open, p) - Eigen::Vector2d(0.15 * 0.15, sv * sv).asDiagonal().toDenseMatrix()).norm(),
            1e-12);
  MeasurementModelParams no_far = p;
  no_far.far_growth = false;
  EXPECT_NEAR(anchorCovariance(car, open, no_far)(0, 0), 0.15 * 0.15 + 1.0, 1e-12) << "the growth stays";
}

}  // namespace
}  // namespace core
}  // namespace map_aided_fusion

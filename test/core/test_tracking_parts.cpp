// The tracker's parts tested alone (include/map_aided_fusion/core/tracking/): each against its definition.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "map_aided_fusion/core/tracking/clustering.hpp"
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

}  // namespace
}  // namespace core
}  // namespace map_aided_fusion

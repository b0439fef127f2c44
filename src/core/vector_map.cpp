#include "map_aided_fusion/core/vector_map.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace map_aided_fusion {
namespace core {

namespace {

/// Squared distance from p to the segment [a, b].
double segmentDistance2(const Point2& p, const Point2& a, const Point2& b)
{
  const double dx = b.x - a.x, dy = b.y - a.y;
  const double len2 = dx * dx + dy * dy;
  const double t = len2 > 0.0 ? std::clamp(((p.x - a.x) * dx + (p.y - a.y) * dy) / len2, 0.0, 1.0) : 0.0;
  const double ex = a.x + t * dx - p.x, ey = a.y + t * dy - p.y;
  return ex * ex + ey * ey;
}

void nearest(const std::vector<Point2>& pts, bool closed, const Point2& p, double& best2)
{
  const std::size_t n = pts.size();
  if (n == 1) best2 = std::min(best2, segmentDistance2(p, pts[0], pts[0]));
  for (std::size_t i = 0; i + 1 < n; ++i) best2 = std::min(best2, segmentDistance2(p, pts[i], pts[i + 1]));
  if (closed && n > 2) best2 = std::min(best2, segmentDistance2(p, pts[n - 1], pts[0]));
}

}  // namespace

double distanceToMapData(const VectorMap& map, const Point2& p)
{
  double best2 = std::numeric_limits<double>::infinity();
  const auto polygon = [&](const Polygon& poly) {
    nearest(poly.outer, true, p, best2);
    for (const auto& h : poly.holes) nearest(h, true, p, best2);
  };
  for (const Building& b : map.buildings) polygon(b.footprint);
  for (const Polygon& a : map.road_areas) polygon(a);
  for (const RoadLine& l : map.road_lines) nearest(l.points, false, p, best2);
  return std::sqrt(best2);
}

}  // namespace core
}  // namespace map_aided_fusion

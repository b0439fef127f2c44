#include "map_aided_fusion/sim/geometry.hpp"

#include <algorithm>
#include <cmath>

namespace map_aided_fusion {
namespace sim {

namespace {

constexpr double kParallelEpsilon = 1e-12;

/// Slab test on one axis of a box frame: the line o + s d within [-half, half].
bool slab(double o, double d, double half, double& lo, double& hi)
{
  if (std::abs(d) < kParallelEpsilon) return std::abs(o) <= half;
  double a = (-half - o) / d;
  double b = (half - o) / d;
  if (a > b) std::swap(a, b);
  lo = std::max(lo, a);
  hi = std::min(hi, b);
  return lo <= hi;
}

void appendRingCrossings(const core::Ring& ring, const Ray2& ray, std::vector<double>& out)
{
  const std::size_t n = ring.size();
  if (n < 3) return;
  const double ox = ray.origin.x, oy = ray.origin.y, dx = ray.dx, dy = ray.dy;
  // Signed distance of a vertex to the line and its abscissa along the ray.
  const core::Point2* prev = &ring[n - 1];
  double h_prev = dx * (prev->y - oy) - dy * (prev->x - ox);
  for (std::size_t i = 0; i < n; ++i)
  {
    const core::Point2& cur = ring[i];
    const double h_cur = dx * (cur.y - oy) - dy * (cur.x - ox);
    if ((h_prev > 0.0) != (h_cur > 0.0))
    {
      const double f = h_prev / (h_prev - h_cur);
      const double xa = (prev->x - ox) * dx + (prev->y - oy) * dy;
      const double xb = (cur.x - ox) * dx + (cur.y - oy) * dy;
      out.push_back(xa + f * (xb - xa));
    }
    prev = &cur;
    h_prev = h_cur;
  }
}

}  // namespace

bool spanOf(const OrientedBox& box, const Ray2& ray, Span& span)
{
  const double c = std::cos(box.yaw), s = std::sin(box.yaw);
  const double rx = ray.origin.x - box.cx, ry = ray.origin.y - box.cy;
  const double ox = c * rx + s * ry, oy = -s * rx + c * ry;
  const double dx = c * ray.dx + s * ray.dy, dy = -s * ray.dx + c * ray.dy;
  double lo = -kNoHit, hi = kNoHit;
  if (!slab(ox, dx, 0.5 * box.length, lo, hi) || !slab(oy, dy, 0.5 * box.width, lo, hi)) return false;
  span = Span{ lo, hi, box.z_min, box.z_max };
  return true;
}

bool spanOf(const Cylinder& cyl, const Ray2& ray, Span& span)
{
  const double rx = ray.origin.x - cyl.cx, ry = ray.origin.y - cyl.cy;
  const double b = rx * ray.dx + ry * ray.dy;
  const double disc = b * b - (rx * rx + ry * ry - cyl.radius * cyl.radius);
  if (disc < 0.0) return false;
  const double q = std::sqrt(disc);
  span = Span{ -b - q, -b + q, cyl.z_min, cyl.z_max };
  return true;
}

std::size_t appendSpans(const core::Polygon& polygon, double z_min, double z_max, const Ray2& ray,
                        std::vector<Span>& spans)
{
  thread_local std::vector<double> crossings;
  crossings.clear();
  appendRingCrossings(polygon.outer, ray, crossings);
  for (const auto& hole : polygon.holes) appendRingCrossings(hole, ray, crossings);
  std::sort(crossings.begin(), crossings.end());
  std::size_t added = 0;
  for (std::size_t i = 0; i + 1 < crossings.size(); i += 2)
  {
    spans.push_back(Span{ crossings[i], crossings[i + 1], z_min, z_max });
    ++added;
  }
  return added;
}

}  // namespace sim
}  // namespace map_aided_fusion

/**
 * @file geometry.hpp
 * @brief Exact ray casting against the solids of a simulated scene: vertical prisms (extruded polygons),
 *        oriented boxes, vertical cylinders and the ground plane z = 0.
 *
 * Every solid is vertical (its cross-section does not depend on z), so a 3D ray
 * `o + r (cos e cos a, cos e sin a, sin e)` is handled as a 2D ray `o_xy + s (cos a, sin a)` in the
 * horizontal distance `s = r cos e`, along which the ray's height is `z(s) = o_z + s tan e`. The 2D ray
 * crosses a solid's footprint over spans [s_in, s_out]; the 3D ray hits the solid at the first s of a
 * span where z(s) lies in [z_min, z_max]. This is exact for walls, roofs and undersides, and lets all the
 * beams of one azimuth share a single 2D traversal.
 */
#pragma once

#include <cstddef>
#include <limits>
#include <vector>

#include "map_aided_fusion/core/vector_map.hpp"

namespace map_aided_fusion {
namespace sim {

using core::Point2;

/// +∞, the "no hit" distance.
constexpr double kNoHit = std::numeric_limits<double>::infinity();

/// A 2D ray: origin and unit direction.
struct Ray2
{
  Point2 origin;
  double dx = 1.0;  ///< unit direction, x
  double dy = 0.0;  ///< unit direction, y
};

/// Where a 2D line lies inside a solid's footprint: horizontal distances along the ray (may be < 0
/// when the footprint contains the origin) and the solid's vertical extent.
struct Span
{
  double s_in = 0.0;
  double s_out = 0.0;
  double z_min = 0.0;
  double z_max = 0.0;
};

/// A box of given length (along its yaw), width and vertical extent [z_min, z_max].
struct OrientedBox
{
  double cx = 0.0;
  double cy = 0.0;
  double yaw = 0.0;     ///< rad, about +z
  double length = 1.0;  ///< m, along the yaw direction
  double width = 1.0;   ///< m
  double z_min = 0.0;   ///< m
  double z_max = 1.0;   ///< m
};

/// A vertical cylinder (pole, tree trunk, bin).
struct Cylinder
{
  double cx = 0.0;
  double cy = 0.0;
  double radius = 0.1;  ///< m
  double z_min = 0.0;   ///< m
  double z_max = 1.0;   ///< m
};

/// A polygon (with holes) extruded over [z_min, z_max].
struct Prism
{
  core::Polygon footprint;
  double z_min = 0.0;
  double z_max = 10.0;
};

/// The span of the 2D line of @p ray through a box footprint; false when the line misses it.
bool spanOf(const OrientedBox& box, const Ray2& ray, Span& span);

/// The span of the 2D line of @p ray through a cylinder footprint; false when the line misses it.
bool spanOf(const Cylinder& cyl, const Ray2& ray, Span& span);

/**
 * @brief Appends the spans of the 2D line of @p ray inside a polygon with holes (even-odd rule over all
 *        rings, half-open vertex rule so that a line through a vertex is counted once).
 * @return the number of spans appended.
 */
std::size_t appendSpans(const core::Polygon& polygon, double z_min, double z_max, const Ray2& ray,
                        std::vector<Span>& spans);

/**
 * @brief First horizontal distance s ≥ 0 at which a ray of height z(s) = z0 + slope·s is inside @p span
 *        (both in the footprint and within [z_min, z_max]); kNoHit when it never is.
 */
inline double hitDistance(const Span& span, double z0, double slope)
{
  double lo = -kNoHit;
  double hi = kNoHit;
  if (slope == 0.0)
  {
    if (z0 < span.z_min || z0 > span.z_max) return kNoHit;
  }
  else
  {
    const double a = (span.z_min - z0) / slope;
    const double b = (span.z_max - z0) / slope;
    lo = a < b ? a : b;
    hi = a < b ? b : a;
  }
  double s = span.s_in > lo ? span.s_in : lo;
  if (s < 0.0) s = 0.0;
  const double end = span.s_out < hi ? span.s_out : hi;
  return s <= end ? s : kNoHit;
}

/// Horizontal distance at which a ray from height z0 > 0 with the given slope (tan of its elevation)
/// meets the ground z = 0; kNoHit when it does not descend.
inline double groundHitDistance(double z0, double slope)
{
  if (slope >= 0.0 || z0 <= 0.0) return kNoHit;
  return -z0 / slope;
}

}  // namespace sim
}  // namespace map_aided_fusion

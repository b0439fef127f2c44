/**
 * @file ground_truth.hpp
 * @brief Ground-truth class rasters (core::CellClass codes) of the simulated world, and the marking of the
 *        cells that the rays of a scan traverse.
 */
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "map_aided_fusion/core/grid_geometry.hpp"
#include "map_aided_fusion/sim/scene.hpp"

namespace map_aided_fusion {
namespace sim {

/// Marks with @p value every cell of @p grid that overlaps the polygon (cell centre inside, or crossed by an
/// edge), keeping the larger code where one is already set.
void rasterizePolygon(const core::Polygon& polygon, const core::GridGeometry& grid, std::int8_t value,
                      std::vector<std::int8_t>& cells);

/// Same for the footprint of an object (oriented box or cylinder), with the object's class.
void rasterizeObject(const WorldObject& object, const core::GridGeometry& grid, std::vector<std::int8_t>& cells);

/**
 * @brief Calls @p visit(index) for every cell of @p grid that the 2D segment from @p origin along the unit
 *        direction (dx, dy) over [0, length] passes through, in order (Amanatides & Woo).
 */
template <class Visit>
void traverseCells(const core::GridGeometry& grid, core::Point2 origin, double dx, double dy, double length,
                   Visit&& visit);

/**
 * @brief Static classes of a world on a fixed lattice (cells at multiples of the resolution): mapped
 *        buildings C, unmapped ones N, the rest F. Windows cut from it are aligned with that lattice.
 */
class StaticClassRaster
{
public:
  StaticClassRaster(const std::vector<WorldBuilding>& buildings, double resolution);

  /// A window of size_x × size_y around (cx, cy), snapped to the lattice.
  core::GridGeometry window(double cx, double cy, double size_x, double size_y) const;

  /// Static classes of @p window, then the footprints of @p objects on top (the larger code wins).
  void classes(const core::GridGeometry& window, const std::vector<WorldObject>& objects,
               std::vector<std::int8_t>& out) const;

  const core::GridGeometry& geometry() const { return geometry_; }

private:
  core::GridGeometry geometry_;
  std::vector<std::int8_t> cells_;
};

// ------------------------------------------------------------------------------------------------------
template <class Visit>
void traverseCells(const core::GridGeometry& grid, core::Point2 origin, double dx, double dy, double length,
                   Visit&& visit)
{
  const double res = grid.resolution;
  double fx = (origin.x - grid.origin_x) / res, fy = (origin.y - grid.origin_y) / res;
  int ix = static_cast<int>(std::floor(fx)), iy = static_cast<int>(std::floor(fy));
  const int step_x = dx > 0.0 ? 1 : -1, step_y = dy > 0.0 ? 1 : -1;
  constexpr double kInf = 1e300;
  double t_max_x = dx != 0.0 ? ((ix + (dx > 0.0 ? 1 : 0)) - fx) * res / dx : kInf;
  double t_max_y = dy != 0.0 ? ((iy + (dy > 0.0 ? 1 : 0)) - fy) * res / dy : kInf;
  const double dt_x = dx != 0.0 ? res / std::abs(dx) : kInf;
  const double dt_y = dy != 0.0 ? res / std::abs(dy) : kInf;
  double t = 0.0;
  while (t <= length)
  {
    if (ix >= 0 && iy >= 0 && ix < grid.width && iy < grid.height)
      visit(static_cast<std::size_t>(iy) * static_cast<std::size_t>(grid.width) + static_cast<std::size_t>(ix));
    else if ((ix < 0 && step_x < 0) || (iy < 0 && step_y < 0) || (ix >= grid.width && step_x > 0) ||
             (iy >= grid.height && step_y > 0))
      return;  // outside and moving away
    if (t_max_x < t_max_y)
    {
      t = t_max_x;
      t_max_x += dt_x;
      ix += step_x;
    }
    else
    {
      t = t_max_y;
      t_max_y += dt_y;
      iy += step_y;
    }
  }
}

}  // namespace sim
}  // namespace map_aided_fusion

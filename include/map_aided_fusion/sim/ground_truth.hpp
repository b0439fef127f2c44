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
#include "map_aided_fusion/core/rasterizer.hpp"
#include "map_aided_fusion/sim/scene.hpp"

namespace map_aided_fusion {
namespace sim {

/// Marks with @p value every cell of @p grid that overlaps the polygon (cell centre inside, or crossed by an
/// edge), keeping the larger code where one is already set.
void rasterizePolygon(const core::Polygon& polygon, const core::GridGeometry& grid, std::int8_t value,
                      std::vector<std::int8_t>& cells);

/// Same for the footprint of an object (oriented box or cylinder), with the object's class.
void rasterizeObject(const WorldObject& object, const core::GridGeometry& grid, std::vector<std::int8_t>& cells);

using core::traverseCells;

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


}  // namespace sim
}  // namespace map_aided_fusion

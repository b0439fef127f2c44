/**
 * @file prior_grid.hpp
 * @brief The PriorGrid (paper section 2.2, equation 1): one PriorClass byte per cell, rasterised from a
 *        VectorMap, from which the masses of any window follow on request.
 *
 * Classes: inside a building polygon → kBuilding (m(B={C}) = β_B); on the road surface (road areas and road
 * centre lines buffered by half their width) → kRoad (m(R={F,S,V}) = β_R); elsewhere inside the grid →
 * kOther (m(T={F,N,S,V}) = β_T); outside the grid → kUnknown (vacuous, m(Ω) = 1). The test is made at each
 * cell's centre. Where buildings and roads overlap in real data (the paper assumes they never do), the
 * building wins. Holes of polygons (courtyards) keep the class underneath (kOther unless a road is there).
 */
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "map_aided_fusion/core/grid_geometry.hpp"
#include "map_aided_fusion/core/mass_grid.hpp"
#include "map_aided_fusion/core/prior.hpp"
#include "map_aided_fusion/core/vector_map.hpp"

namespace map_aided_fusion {
namespace core {

/// Counts from PriorGrid::build().
struct PriorBuildStats
{
  std::size_t buildings_rasterised = 0;  ///< buildings covering at least one cell centre
  std::size_t buildings_empty = 0;       ///< buildings covering no cell centre (smaller than a cell, or outside)
  std::size_t road_areas_rasterised = 0; ///< road areas covering at least one cell centre
  std::size_t road_lines_rasterised = 0; ///< road centre lines covering at least one cell centre
  std::size_t skipped_invalid = 0;       ///< polygons/lines with non-finite vertices or a non-positive width
};

/// Per-class cell counts, indexed by PriorClass.
using PriorClassCounts = std::array<std::size_t, kNumPriorClasses>;

/// A class label per cell over a GridGeometry.
class PriorGrid
{
public:
  PriorGrid() = default;

  /// All cells kUnknown over @p geometry. @throws ParameterError when the geometry is invalid.
  explicit PriorGrid(const GridGeometry& geometry);

  /**
   * @brief The bounding box of a map's geometry (buildings, road areas, road lines widened by half their width),
   *        grown by @p margin metres, with its origin snapped to a multiple of @p resolution so that grids of the
   *        same resolution share cell boundaries with the map frame.
   * @throws ParameterError when the resolution is not > 0 or the map is empty.
   */
  static GridGeometry extentOf(const VectorMap& map, double resolution, double margin = 0.0);

  /// Rasterises @p map over its extent (extentOf()) at @p resolution.
  static PriorGrid fromVectorMap(const VectorMap& map, double resolution, double margin = 0.0,
                                 PriorBuildStats* stats = nullptr);

  /**
   * @brief Rasterises @p map over @p geometry: every cell kOther, then road surfaces kRoad, then buildings
   *        kBuilding (buildings win). Invalid geometry is skipped and counted.
   */
  void build(const VectorMap& map, const GridGeometry& geometry, PriorBuildStats* stats = nullptr);

  const GridGeometry& geometry() const { return geometry_; }

  /// Class of a cell; kUnknown outside the grid.
  PriorClass label(CellIndex c) const
  {
    return geometry_.contains(c) ? labels_[geometry_.index(c)] : PriorClass::kUnknown;
  }
  /// Class at a point of the map frame; kUnknown outside the grid.
  PriorClass labelAt(Point2 p) const;
  /// Sets one cell's class (no-op outside the grid).
  void setLabel(CellIndex c, PriorClass v)
  {
    if (geometry_.contains(c)) labels_[geometry_.index(c)] = v;
  }

  /// Row-major labels (geometry().numCells() bytes).
  const std::vector<PriorClass>& labels() const { return labels_; }

  /// Number of cells of each class.
  PriorClassCounts classCounts() const;

  /// Bytes of cell storage (one per cell).
  std::size_t bytes() const { return labels_.size() * sizeof(PriorClass); }

  /**
   * @brief The masses m(B), m(R), m(T) (equation 1) of the cells of @p window; m(Ω) = 1 − their sum.
   *
   * Same resolution and an origin offset by a whole number of cells: copied by whole cells (row runs).
   * Otherwise each window cell takes the class at its centre. Outside this grid the prior is vacuous.
   * @p out is reset to @p window only when its geometry differs (no reallocation in steady state).
   */
  void fillWindow(const GridGeometry& window, const PriorConfidence& beta, PriorWindow& out) const;

  /// This grid cropped (or extended with kUnknown) to @p window, which must have the same resolution and an
  /// origin offset by a whole number of cells. @throws ParameterError otherwise.
  PriorGrid crop(const GridGeometry& window) const;

private:
  GridGeometry geometry_;
  std::vector<PriorClass> labels_;
};

}  // namespace core
}  // namespace map_aided_fusion

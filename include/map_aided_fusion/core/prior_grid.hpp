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
 *
 * PriorCellTest::kCoverage (not in the paper; doc/steps.md, "Cell coverage") also keeps, per cell, which of
 * kCoverageSamples sample points lie in a building and on a road, and whether a building outline crosses the
 * cell. Its masses: a cell an outline crosses → m(W = {F,C}) = β_B (what a lidar sees of a building is its
 * wall: occupied there is the building, the rest of the cell can be free); a cell inside buildings → m(B) = β_B;
 * otherwise the linear pool of equation 1 over the cell's area: m(R) = β_R·a_R, m(T) = β_T·(1 − a_R).
 */
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "map_aided_fusion/core/grid_geometry.hpp"
#include "map_aided_fusion/core/mass_grid.hpp"
#include "map_aided_fusion/core/prior.hpp"
#include "map_aided_fusion/core/vector_map.hpp"

namespace map_aided_fusion {
namespace core {

/// How a PriorGrid cell gets its context.
enum class PriorCellTest
{
  kCentre,    ///< the class at the cell's centre (equation 1, the paper)
  kCoverage,  ///< coverage of the cell by buildings and roads, and the outlines crossing it
};

/// "centre" or "coverage".
const char* toString(PriorCellTest t);
/// @throws ParameterError("cell_test", …) for another string.
PriorCellTest parsePriorCellTest(const std::string& s);

/// Sample points per cell side of the coverage test: 4 × 4 = 16 per cell, one bit each.
constexpr int kCoverageSamplesPerSide = 4;
/// Sample points per cell of the coverage test.
constexpr int kCoverageSamples = kCoverageSamplesPerSide * kCoverageSamplesPerSide;

/// How the PriorGrid is made from the map beyond equation 1's β (config/prior_grid.yaml).
struct PriorGridOptions
{
  /// Step "cell coverage" (not in the paper): kCoverage; kCentre is equation 1.
  PriorCellTest cell_test = PriorCellTest::kCoverage;
  /// Step "map accuracy" (not in the paper): positional σ of the map's buildings and of its roads, metres in
  /// [0, 5], by which the prior is softened (prior_uncertainty.hpp). 0: the map is taken as exact.
  double building_accuracy = 0.3;
  double road_accuracy = 0.3;
  /// @throws ParameterError naming building_accuracy or road_accuracy when out of range.
  void validate() const;
};

/// Counts from PriorGrid::build().
struct PriorBuildStats
{
  std::size_t buildings_rasterised = 0;  ///< buildings covering at least one cell centre
  std::size_t buildings_empty = 0;       ///< buildings over the grid covering no cell centre (smaller than a cell)
  std::size_t buildings_outside = 0;     ///< buildings whose bounding box misses the grid (e.g. a cropped window)
  std::size_t road_areas_rasterised = 0; ///< road areas covering at least one cell centre
  std::size_t road_lines_rasterised = 0; ///< road centre lines covering at least one cell centre
  std::size_t skipped_invalid = 0;       ///< polygons/lines with non-finite vertices or a non-positive width
  std::size_t outline_cells = 0;         ///< kCoverage: cells a building outline crosses (not inside other buildings)
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
                                 PriorBuildStats* stats = nullptr, PriorCellTest test = PriorCellTest::kCentre);

  /**
   * @brief Rasterises @p map over @p geometry: every cell kOther, then road surfaces kRoad, then buildings
   *        kBuilding (buildings win). Invalid geometry is skipped and counted. kCoverage also samples each cell
   *        kCoverageSamples times and walks every building edge through the cells; its outline cells are labelled
   *        kBuilding. A degenerate polygon (zero area, self-touching) marks at most the cells its edges cross.
   */
  void build(const VectorMap& map, const GridGeometry& geometry, PriorBuildStats* stats = nullptr,
             PriorCellTest test = PriorCellTest::kCentre);

  const GridGeometry& geometry() const { return geometry_; }
  PriorCellTest cellTest() const { return test_; }

  /// kCoverage: fraction of the cell inside buildings, in [0, 1] (0 for kCentre or outside the grid).
  double buildingCoverage(CellIndex c) const;
  /// kCoverage: fraction of the cell on the road surface and not inside a building (0 for kCentre).
  double roadCoverage(CellIndex c) const;
  /// kCoverage: true when a building outline crosses the cell and the cell is not wholly inside buildings.
  bool outline(CellIndex c) const;

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

  /// Bytes of cell storage (one per cell; 6 per cell with kCoverage).
  std::size_t bytes() const
  {
    return labels_.size() * sizeof(PriorClass) + (building_samples_.size() + road_samples_.size()) * 2 + outline_.size();
  }

  /**
   * @brief The masses m(B), m(R), m(T) (equation 1) of the cells of @p window; m(Ω) = 1 − their sum.
   *
   * Same resolution and an origin offset by a whole number of cells: copied by whole cells (row runs).
   * Otherwise each window cell takes the class at its centre. Outside this grid the prior is vacuous.
   * @p out is reset to @p window only when its geometry differs (no reallocation in steady state).
   */
  void fillWindow(const GridGeometry& window, const PriorConfidence& beta, PriorWindow& out) const;

  /// The prior masses of one cell of this grid (row-major index @p i; kCoverage or kCentre).
  void cellMasses(std::size_t i, const PriorConfidence& beta, float& building, float& road, float& other,
                  float& wall) const;

  /// This grid cropped (or extended with kUnknown) to @p window, which must have the same resolution and an
  /// origin offset by a whole number of cells. @throws ParameterError otherwise.
  PriorGrid crop(const GridGeometry& window) const;

private:
  void sampleCoverage(const VectorMap& map, PriorBuildStats& st);

  GridGeometry geometry_;
  PriorCellTest test_ = PriorCellTest::kCentre;
  std::vector<PriorClass> labels_;
  std::vector<std::uint16_t> building_samples_;  ///< kCoverage: bit k set when sample k is in a building
  std::vector<std::uint16_t> road_samples_;      ///< kCoverage: bit k set when sample k is on a road
  std::vector<std::uint8_t> outline_;            ///< kCoverage: 1 when an outline crosses the cell
};

}  // namespace core
}  // namespace map_aided_fusion

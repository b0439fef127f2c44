/**
 * @file mass_grid.hpp
 * @brief Evidential grids stored as structure-of-arrays: one contiguous float plane per subset of the
 *        frame (indexed by subset mask, ∅ included) plus a plane for the counter ζ.
 */
#pragma once

#include <algorithm>
#include <cstddef>

#include "map_aided_fusion/core/aligned_vector.hpp"
#include "map_aided_fusion/core/grid_geometry.hpp"
#include "map_aided_fusion/core/mass_function.hpp"

namespace map_aided_fusion {
namespace core {

/// Planes start on a cache line: their stride is a multiple of this many floats (64 bytes).
constexpr std::size_t kPlaneAlignmentFloats = 16;
/// Plane strides are a multiple of a page plus one cache line, so that the planes of one cell never
/// share a cache set (a page-multiple stride makes 33 streams fight over the same sets).
constexpr std::size_t kPlanePageFloats = 1024;

/**
 * @brief A grid of mass functions on @p Frame. Plane a (a = subset mask) holds m(a) for every cell,
 *        row-major; plane 2^N holds the counter ζ (used by the MapGrid, zero elsewhere).
 */
template <class Frame>
class MassGrid
{
public:
  static constexpr int kNumPlanes = Frame::kNumSubsets;

  MassGrid() = default;
  /// A vacuous grid (m(Ω) = 1, ζ = 0) of the given geometry.
  explicit MassGrid(const GridGeometry& geometry) { reset(geometry); }

  /// Reallocates for @p geometry and makes every cell vacuous with ζ = 0.
  void reset(const GridGeometry& geometry)
  {
    geometry_ = geometry;
    const std::size_t n = geometry.numCells();
    stride_ = (n + kPlanePageFloats - 1) / kPlanePageFloats * kPlanePageFloats + kPlaneAlignmentFloats;
    data_.assign(stride_ * (kNumPlanes + 1), 0.0f);
    fillVacuous();
  }

  /// Every cell vacuous, ζ = 0; geometry unchanged.
  void fillVacuous()
  {
    std::fill(data_.begin(), data_.end(), 0.0f);
    std::fill_n(plane(Frame::kOmega), stride_, 1.0f);
  }

  const GridGeometry& geometry() const { return geometry_; }
  /// Moves the grid in the world without touching the cells (see MapGrid for shifting contents).
  void setOrigin(double origin_x, double origin_y)
  {
    geometry_.origin_x = origin_x;
    geometry_.origin_y = origin_y;
  }
  std::size_t numCells() const { return geometry_.numCells(); }
  /// Distance in floats between two consecutive planes.
  std::size_t stride() const { return stride_; }

  float* plane(Subset a) { return data_.data() + stride_ * a; }
  const float* plane(Subset a) const { return data_.data() + stride_ * a; }
  float* counter() { return data_.data() + stride_ * kNumPlanes; }
  const float* counter() const { return data_.data() + stride_ * kNumPlanes; }

  /// The mass function of cell @p i, in double.
  MassFunction<Frame> cell(std::size_t i) const
  {
    typename MassFunction<Frame>::Values v;
    for (int a = 0; a < kNumPlanes; ++a) v[a] = plane(static_cast<Subset>(a))[i];
    return MassFunction<Frame>::fromValues(v);
  }

  void setCell(std::size_t i, const MassFunction<Frame>& m)
  {
    for (int a = 0; a < kNumPlanes; ++a) plane(static_cast<Subset>(a))[i] = static_cast<float>(m[a]);
  }

  /// Bytes of cell storage (all planes and the counter).
  std::size_t bytes() const { return data_.size() * sizeof(float); }

private:
  GridGeometry geometry_;
  std::size_t stride_ = 0;
  AlignedVector<float> data_;
};

using MapMassGrid = MassGrid<FrameMG>;
using ScanMassGrid = MassGrid<FrameSG>;

/**
 * @brief The prior masses of a window: m(B), m(R), m(T) (equation 1) and m(W = {F, C}) (a cell a building's
 *        outline crosses: occupied there is the wall, the rest of the cell may be free) per cell,
 *        m(Ω) = 1 − their sum. All zero means a vacuous prior.
 */
struct PriorWindow
{
  GridGeometry geometry;
  AlignedVector<float> building;  ///< m_PG(B = {C})
  AlignedVector<float> road;      ///< m_PG(R = {F,S,V})
  AlignedVector<float> other;     ///< m_PG(T = {F,N,S,V})
  AlignedVector<float> wall;      ///< m_PG(W = {F,C}); zero in the paper's prior

  PriorWindow() = default;
  /// A vacuous prior window of the given geometry.
  explicit PriorWindow(const GridGeometry& g) { reset(g); }
  void reset(const GridGeometry& g)
  {
    geometry = g;
    building.assign(g.numCells(), 0.0f);
    road.assign(g.numCells(), 0.0f);
    other.assign(g.numCells(), 0.0f);
    wall.assign(g.numCells(), 0.0f);
  }
  /// True when some cell carries mass on W.
  bool hasWall() const;
  /// The prior mass function of cell @p i.
  MassMG cell(std::size_t i) const
  {
    return MassMG{ { FrameMG::kBuilding, building[i] },
                   { FrameMG::kRoad, road[i] },
                   { FrameMG::kOther, other[i] },
                   { FrameMG::kWall, wall[i] },
                   { FrameMG::kOmega, 1.0 - double(building[i]) - double(road[i]) - double(other[i]) - double(wall[i]) } };
  }
};

}  // namespace core
}  // namespace map_aided_fusion

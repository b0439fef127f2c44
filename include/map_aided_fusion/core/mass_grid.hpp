/**
 * @file mass_grid.hpp
 * @brief Evidential grids: for every cell, a float per stored subset of the frame and one for the counter ζ. A
 *        ScanGrid stores its four subsets as planes (one contiguous array per subset); the MapGrid stores only the
 *        29 focal sets its pipeline can reach (PlaneLayout), interleaved in blocks of eight cells.
 */
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <stdexcept>
#include <string>

#include "map_aided_fusion/core/aligned_vector.hpp"
#include "map_aided_fusion/core/grid_geometry.hpp"
#include "map_aided_fusion/core/mass_function.hpp"

namespace map_aided_fusion {
namespace core {

/// Planes start on a cache line: their stride is a multiple of this many floats (64 bytes).
constexpr std::size_t kPlaneAlignmentFloats = 16;
/// Plane strides are a multiple of a page plus one cache line, so that the planes of one cell never
/// share a cache set (a page-multiple stride makes some 40 streams fight over the same sets).
constexpr std::size_t kPlanePageFloats = 1024;

/// Which subsets of @p Frame a MassGrid stores (every one, by default) and how: kBlockCells = 0 is one plane per
/// subset; kBlockCells = k interleaves the grid in blocks of k consecutive cells, each block holding, slot after slot,
/// the k values of every stored subset and then ζ.
template <class Frame>
struct PlaneLayout
{
  static constexpr bool stored(Subset) { return true; }
  static constexpr std::size_t kBlockCells = 0;
};

/**
 * @brief The MapGrid's layout: the 29 focal sets the per-scan pipeline can reach from the scan, the prior,
 *        discounting, ⊛, specialisation and motion spreading. Not stored (always zero): ∅ (⊛ and the other rules leave
 *        no mass on it), {C, V} and {F, C, V} (contexts add {C, N} or {S, V} whole, and every set of r(m_SG) ⊕ m_PG
 *        holding C holds N, S and V or neither S nor V). The closure is enumerated by test ReachableFocalSets.
 */
template <>
struct PlaneLayout<FrameMG>
{
  static constexpr bool stored(Subset a)
  {
    return a != 0 && a != (FrameMG::kC | FrameMG::kV) && a != (FrameMG::kF | FrameMG::kC | FrameMG::kV);
  }
  /// Blocks of eight cells (one AVX vector per subset): the per-scan step reads and writes one contiguous stream
  /// instead of 30 planes, which hardware prefetchers follow and which needs one address register, not 30.
  static constexpr std::size_t kBlockCells = 8;
};

/**
 * @brief A grid of mass functions on @p Frame, cells row-major. Each stored subset a has a slot (slot(a)); the slot
 *        after the last holds the counter ζ (used by the MapGrid, zero elsewhere). A subset that is not stored has
 *        mass 0 in every cell. The value of slot s of cell i is planes()[blockOffset(i) + s · stride()]: planar
 *        layouts (blockOffset(i) = i, stride() = the plane length) also give each slot as a plane (plane(), counter());
 *        interleaved ones (PlaneLayout::kBlockCells) are read and written through at(), zeta() and value().
 */
template <class Frame>
class MassGrid
{
  static constexpr std::array<int, Frame::kNumSubsets> makeSlots()
  {
    std::array<int, Frame::kNumSubsets> t{};
    int next = 0;
    for (int a = 0; a < Frame::kNumSubsets; ++a) t[a] = PlaneLayout<Frame>::stored(static_cast<Subset>(a)) ? next++ : -1;
    return t;
  }

public:
  /// slot(a) for every subset a, −1 where a is not stored.
  static constexpr std::array<int, Frame::kNumSubsets> kSlots = makeSlots();
  /// Number of mass planes (stored subsets); the counter ζ is one more plane.
  static constexpr int kNumPlanes = [] {
    int n = 0;
    for (const int s : kSlots) n += s >= 0;
    return n;
  }();
  static constexpr bool stored(Subset a) { return PlaneLayout<Frame>::stored(a); }
  /// The plane index of a stored subset.
  static constexpr int slot(Subset a) { return kSlots[a]; }
  /// Cells per interleaved block; 0 for a planar grid.
  static constexpr std::size_t kBlockCells = PlaneLayout<Frame>::kBlockCells;
  static constexpr bool kInterleaved = kBlockCells > 0;
  /// Floats of one interleaved block: kBlockCells values of every slot and of ζ.
  static constexpr std::size_t kBlockFloats = kBlockCells * (kNumPlanes + 1);
  /// Where cell @p i of an interleaved grid starts (its slot s is kBlockCells · s further).
  static constexpr std::size_t blockOffset(std::size_t i)
  {
    return kInterleaved ? i / kBlockCells * kBlockFloats + i % kBlockCells : i;
  }

  MassGrid() = default;
  /// A vacuous grid (m(Ω) = 1, ζ = 0) of the given geometry.
  explicit MassGrid(const GridGeometry& geometry) { reset(geometry); }

  /// Reallocates for @p geometry and makes every cell vacuous with ζ = 0.
  void reset(const GridGeometry& geometry)
  {
    geometry_ = geometry;
    const std::size_t n = geometry.numCells();
    if (kInterleaved)
    {
      stride_ = kBlockCells;
      data_.assign((n + kBlockCells - 1) / kBlockCells * kBlockFloats, 0.0f);
    }
    else
    {
      stride_ = (n + kPlanePageFloats - 1) / kPlanePageFloats * kPlanePageFloats + kPlaneAlignmentFloats;
      data_.assign(stride_ * (kNumPlanes + 1), 0.0f);
    }
    fillVacuous();
  }

  /// Every cell vacuous, ζ = 0; geometry unchanged.
  void fillVacuous()
  {
    std::fill(data_.begin(), data_.end(), 0.0f);
    const std::size_t omega = stride_ * static_cast<std::size_t>(checkedSlot(Frame::kOmega));
    if (kInterleaved)
      for (std::size_t b = 0; b < data_.size(); b += kBlockFloats) std::fill_n(data_.data() + b + omega, kBlockCells, 1.0f);
    else
      std::fill_n(data_.data() + omega, stride_, 1.0f);
  }

  const GridGeometry& geometry() const { return geometry_; }
  /// Moves the grid in the world without touching the cells (see MapGrid for shifting contents).
  void setOrigin(double origin_x, double origin_y)
  {
    geometry_.origin_x = origin_x;
    geometry_.origin_y = origin_y;
  }
  std::size_t numCells() const { return geometry_.numCells(); }
  /// Distance in floats between two consecutive slots of one cell: the plane length of a planar grid,
  /// kBlockCells of an interleaved one.
  std::size_t stride() const { return stride_; }

  /// The plane of subset @p a (planar layouts only). @throws std::out_of_range when @p a is not stored.
  float* plane(Subset a)
  {
    static_assert(!kInterleaved, "an interleaved grid has no planes: use at() or value()");
    return data_.data() + stride_ * checkedSlot(a);
  }
  const float* plane(Subset a) const
  {
    static_assert(!kInterleaved, "an interleaved grid has no planes: use at() or value()");
    return data_.data() + stride_ * checkedSlot(a);
  }
  /// The first float of the grid (see the class comment for the address of a value).
  float* planes() { return data_.data(); }
  const float* planes() const { return data_.data(); }
  /// ζ as a plane (planar layouts only).
  float* counter()
  {
    static_assert(!kInterleaved, "an interleaved grid has no planes: use zeta()");
    return data_.data() + stride_ * kNumPlanes;
  }
  const float* counter() const
  {
    static_assert(!kInterleaved, "an interleaved grid has no planes: use zeta()");
    return data_.data() + stride_ * kNumPlanes;
  }
  /// Slot @p s (kNumPlanes: ζ) of cell @p i.
  float& value(int s, std::size_t i) { return data_[blockOffset(i) + stride_ * static_cast<std::size_t>(s)]; }
  float value(int s, std::size_t i) const { return data_[blockOffset(i) + stride_ * static_cast<std::size_t>(s)]; }
  /// m(@p a) of cell @p i. @throws std::out_of_range when @p a is not stored.
  float& at(Subset a, std::size_t i) { return value(static_cast<int>(checkedSlot(a)), i); }
  float at(Subset a, std::size_t i) const { return value(static_cast<int>(checkedSlot(a)), i); }
  /// ζ of cell @p i.
  float& zeta(std::size_t i) { return value(kNumPlanes, i); }
  float zeta(std::size_t i) const { return value(kNumPlanes, i); }

  /// The mass function of cell @p i, in double.
  MassFunction<Frame> cell(std::size_t i) const
  {
    typename MassFunction<Frame>::Values v{};
    for (int a = 0; a < Frame::kNumSubsets; ++a)
      if (kSlots[a] >= 0) v[a] = value(kSlots[a], i);
    return MassFunction<Frame>::fromValues(v);
  }

  /// @throws std::invalid_argument when @p m has mass on a subset this grid does not store.
  void setCell(std::size_t i, const MassFunction<Frame>& m)
  {
    for (int a = 0; a < Frame::kNumSubsets; ++a)
      if (kSlots[a] < 0 && m[a] != 0.0)
        throw std::invalid_argument("MassGrid::setCell: mass on " + subsetName<Frame>(static_cast<Subset>(a)) +
                                    ", a subset this grid does not store");
    for (int a = 0; a < Frame::kNumSubsets; ++a)
      if (kSlots[a] >= 0) value(kSlots[a], i) = static_cast<float>(m[a]);
  }

  /// Bytes of cell storage (every slot and the counter).
  std::size_t bytes() const { return data_.size() * sizeof(float); }

private:
  static std::size_t checkedSlot(Subset a)
  {
    if (a >= Frame::kNumSubsets || kSlots[a] < 0)
      throw std::out_of_range("MassGrid: subset " + std::to_string(a) + " has no plane");
    return static_cast<std::size_t>(kSlots[a]);
  }

  GridGeometry geometry_;
  std::size_t stride_ = 0;
  AlignedVector<float> data_;
};

using MapMassGrid = MassGrid<FrameMG>;
using ScanMassGrid = MassGrid<FrameSG>;

/// True when some of the @p n floats from @p p is not zero (a NaN counts, −0 does not): an OR of the bit patterns
/// without their sign, which vectorises, unlike a search that stops at the first.
bool anyNonZero(const float* p, std::size_t n);

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

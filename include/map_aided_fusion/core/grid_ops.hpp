/**
 * @file grid_ops.hpp
 * @brief Whole-grid operations of the paper, one stage at a time (fusionStep() in fusion.hpp fuses
 *        them in one pass). Every function loops over cells, eight at a time (one block of the MapGrid, one
 *        plane segment of the ScanGrid and BetP), so that the compiler vectorises across cells.
 */
#pragma once

#include <array>

#include "map_aided_fusion/core/counter.hpp"
#include "map_aided_fusion/core/discounting.hpp"
#include "map_aided_fusion/core/mass_grid.hpp"
#include "map_aided_fusion/core/prior.hpp"

namespace map_aided_fusion {
namespace core {

/// r_SG on every cell: @p out (same geometry, reset by the call) gets m(F), m(CNSV), m(Ω) (m_SG(∅), which the
/// fusion never reads, has no plane in a MapGrid).
void refineGrid(const ScanMassGrid& scan, MapMassGrid& out);

/**
 * @brief Dempster's rule with the prior on every cell, in place: m ← m ⊕ m_PG.
 *        A cell in total conflict becomes vacuous (see dempster()).
 */
void combineWithPriorGrid(MapMassGrid& grid, const PriorWindow& prior);

/// Contextual discounting on every cell, in place.
void contextualDiscountGrid(MapMassGrid& grid, const ContextualRates& rates);

/**
 * @brief The modified Yager rule ⊛ on every cell: out = map ⊛ scan (out may alias map). @p scan is the pipeline's
 *        r(m_SG) ⊕ m_PG: with two arbitrary operands, mass meeting in a set the MapGrid does not store ({C, V},
 *        {F, C, V}; see PlaneLayout) would not be kept.
 * @param conflict_free_occupied  per-cell ∅_FO (numCells floats), or nullptr
 * @param conflict_occupied_free  per-cell ∅_OF (numCells floats), or nullptr
 */
void modifiedYagerGrid(const MapMassGrid& map, const MapMassGrid& scan, MapMassGrid& out,
                       float* conflict_free_occupied, float* conflict_occupied_free);

/// Counter update (equation 3) then specialisation (equation 4) on every cell, in place.
void updateCounterAndSpecialiseGrid(MapMassGrid& grid, const float* conflict_free_occupied,
                                    const float* conflict_occupied_free, const CounterParams& params);

/// BetP planes, one per element of Ω_MG (order F, C, N, S, V), each numCells floats.
struct PignisticPlanes
{
  std::array<AlignedVector<float>, FrameMG::kSize> p;
  const AlignedVector<float>& operator[](int element) const { return p[element]; }
};

/// BetP of every cell.
void pignisticGrid(const MapMassGrid& grid, PignisticPlanes& out);

}  // namespace core
}  // namespace map_aided_fusion

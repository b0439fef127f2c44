// The fused per-cell loop of fusionStep(), in its own translation unit, which CMakeLists.txt compiles with
// -fno-signed-zeros -ffinite-math-only (the planes the MapGrid never stores are compile-time zeros: their products
// fold away; nothing is reassociated) and -fschedule-insns -fsched-pressure (register-pressure-aware scheduling).
// Nothing in it validates input: NaN checks stay out of this unit.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "map_aided_fusion/core/discounting.hpp"
#include "map_aided_fusion/core/fusion.hpp"
#include "map_aided_fusion/core/mass_grid.hpp"

namespace map_aided_fusion {
namespace core {
namespace kernels {

/// What a cell's decision needs besides BetP and m(Ω): the threshold and the step "motion margin" (MapGridParams).
struct DecisionRule
{
  float threshold = 0.0f;
  bool motion_margin = false;  ///< MapGridParams::motion_margin > 0
  float margin = 0.0f;
};

/// Everything the fused loop reads, hoisted out of it.
struct StepInputs
{
  float* base;  ///< the MapGrid's first float (interleaved blocks: masses and ζ of each cell)
  std::size_t cells;
  const float* sf;
  const float* so;
  const float* sw;
  const float* pb;
  const float* pr;
  const float* pt;
  const float* pw;
  float* eta;           ///< the map doubt η to update and discount the prior by (step map_conflict), or nullptr
  float conflict_gain;  ///< MapGridParams::map_conflict_gain
  float delta_inc, delta_dec, gamma_occupied, gamma_conflict, threshold;
  bool literal;
  int rule;
  bool contextual;
  float alpha_single;
  bool use_counter;
  bool moving_expiry;
  bool building_conflict;  ///< FusionParams::building_conflict
  float* betp[FrameMG::kSize];  ///< BetP planes to fill, or nullptr
  std::int8_t* decision;        ///< decisions to fill (with BetP only), or nullptr
  DecisionRule decision_rule;
  std::vector<std::size_t>* seeds;  ///< motion spreading's seeds to append (with BetP only), or nullptr
  std::size_t first;                ///< index of the first cell in the whole grid (what the seeds record)
  /// StepSkip's flags and kept prior, indexed from the whole grid's first cell (first + i), or nullptr.
  std::uint8_t* stable;
  float* kept[4];

  /// The same inputs for the cells [begin, begin + count): every per-cell pointer moved. @p begin must start a block
  /// of the MapGrid (a multiple of MapMassGrid::kBlockCells). The prior pointers are the caller's (rows of the prior).
  StepInputs offset(std::size_t begin, std::size_t count) const
  {
    StepInputs o = *this;
    auto move = [begin](auto*& p) {
      if (p) p += begin;
    };
    o.base += MapMassGrid::blockOffset(begin);
    move(o.sf);
    move(o.so);
    move(o.sw);
    move(o.eta);
    for (auto*& b : o.betp) move(b);
    move(o.decision);
    o.first += begin;
    o.cells = count;
    return o;
  }
};

/// The fused step on the cells of @p in (one run of cells of one prior row, or of a chunk without prior): masses, ζ, BetP and decisions in place, conflicts summed into
/// @p out.
void fusionChunk(const StepInputs& in, const ContextualDiscountWeights<float>& w, bool has_prior, bool wall, bool paper,
                 FusionStepStats& out);

}  // namespace kernels
}  // namespace core
}  // namespace map_aided_fusion

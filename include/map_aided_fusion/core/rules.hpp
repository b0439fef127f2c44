/**
 * @file rules.hpp
 * @brief Combination rules on mass functions: conjunctive, Dempster, disjunctive, Yager and the
 *        paper's modified Yager rule ⊛ (equation 5), plus the refining r_SG: 2^Ω_SG → 2^Ω_MG.
 *
 * These are the scalar reference implementations, written from the definitions (double sums over
 * pairs of focal sets). The grid operations in grid_ops.hpp compute the same values in bulk.
 */
#pragma once

#include "map_aided_fusion/core/mass_function.hpp"

namespace map_aided_fusion {
namespace core {

/**
 * @brief Below this normalisation factor 1 − K, Dempster's rule treats the sources as in total
 *        conflict (see dempster()). Below ~1e-10 the normalised result is rounding noise of the
 *        products (float kernels) that no longer sums to 1.
 */
constexpr double kTotalConflictThreshold = 1e-10;

/// Unnormalised conjunctive rule (m1 ∩ m2)(A) = Σ_{B∩C=A} m1(B) m2(C); m(∅) is the conflict and is kept.
template <class Frame>
MassFunction<Frame> conjunctive(const MassFunction<Frame>& m1, const MassFunction<Frame>& m2)
{
  typename MassFunction<Frame>::Values r{};
  for (int b = 0; b < Frame::kNumSubsets; ++b)
  {
    if (m1[b] == 0.0) continue;
    for (int c = 0; c < Frame::kNumSubsets; ++c) r[b & c] += m1[b] * m2[c];
  }
  return MassFunction<Frame>::fromValues(r);
}

/// Disjunctive rule (m1 ∪ m2)(A) = Σ_{B∪C=A} m1(B) m2(C).
template <class Frame>
MassFunction<Frame> disjunctive(const MassFunction<Frame>& m1, const MassFunction<Frame>& m2)
{
  typename MassFunction<Frame>::Values r{};
  for (int b = 0; b < Frame::kNumSubsets; ++b)
  {
    if (m1[b] == 0.0) continue;
    for (int c = 0; c < Frame::kNumSubsets; ++c) r[b | c] += m1[b] * m2[c];
  }
  return MassFunction<Frame>::fromValues(r);
}

/// What Dempster's rule met on the way.
struct DempsterReport
{
  double conflict = 0.0;        ///< K = (m1 ∩ m2)(∅)
  bool total_conflict = false;  ///< 1 − K < kTotalConflictThreshold: the result is vacuous
};

/**
 * @brief Dempster's rule: (m1 ⊕ m2)(A) = (m1 ∩ m2)(A) / (1 − K) for A ≠ ∅, and 0 on ∅.
 *
 * The normalisation divides by the sum of the non-empty conjunctive masses (1 − K without its rounding).
 * Total conflict (1 − K < kTotalConflictThreshold) has no Dempster combination; the defined outcome
 * is the vacuous mass function (m(Ω) = 1: the two sources cancel out), with report->total_conflict set.
 * Inputs with m(∅) > 0 are accepted; their ∅ mass counts as conflict.
 */
template <class Frame>
MassFunction<Frame> dempster(const MassFunction<Frame>& m1, const MassFunction<Frame>& m2,
                             DempsterReport* report = nullptr)
{
  auto r = conjunctive(m1, m2);
  const double k = r[0];
  r[0] = 0.0;
  double norm = 0.0;  // the non-empty masses: 1 − K up to rounding, never negative
  for (const auto v : r.values()) norm += v;
  if (report) *report = DempsterReport{ k, norm < kTotalConflictThreshold };
  if (norm < kTotalConflictThreshold) return MassFunction<Frame>::vacuous();
  for (auto& v : r.values()) v /= norm;
  return r;
}

/// Yager's rule: the conjunctive rule with the conflict m(∅) moved to Ω.
template <class Frame>
MassFunction<Frame> yager(const MassFunction<Frame>& m1, const MassFunction<Frame>& m2)
{
  auto r = conjunctive(m1, m2);
  r[Frame::kOmega] += r[0];
  r[0] = 0.0;
  return r;
}

/// The two kinds of conflict of the paper (section 2.4), for one cell.
struct ConflictMasses
{
  double free_occupied = 0.0;  ///< ∅_FO = m_MG(F)·m_SG(O): free then occupied, an object appeared
  double occupied_free = 0.0;  ///< ∅_OF = m_MG(O)·m_SG(F): occupied then free, an object left
  double other = 0.0;          ///< the rest of (m_MG ∩ m_SG)(∅), e.g. building vs stopped
  double total() const { return free_occupied + occupied_free + other; }
};

/**
 * @brief The paper's modified Yager rule ⊛ on Ω_MG (equation 5), m1 = MapGrid, m2 = ScanGrid.
 *
 * With ∅_FO = m1(F)·m2(O) and ∅_OF = m1(O)·m2(F), where m(O) is the mass on the non-empty subsets of
 * {C, N, S, V}: (m1 ⊛ m2)(V) = (m1 ∩ m2)(V) + ∅_FO and (m1 ⊛ m2)(Ω) = (m1 ∩ m2)(Ω) + ∅_OF. The paper
 * does not say where the remaining conflict (m1 ∩ m2)(∅) − ∅_FO − ∅_OF goes; as in Yager's rule it
 * goes to Ω. The result has m(∅) = 0.
 *
 * @p building_conflict (step "building conflict", not in the paper): the part of ∅_FO that m2 puts on {C},
 * m1(F)·m2({C}), goes to Ω instead of V. Occupied evidence that can only be the mapped building does not show an
 * object moving into a cell seen free: a building cannot move, so the pose or the map is off. The conflicts reported
 * are unchanged.
 */
MassMG modifiedYager(const MassMG& m1, const MassMG& m2, ConflictMasses* conflicts = nullptr,
                     bool building_conflict = false);

/// The refining r_SG: {F} → {F}, {O} → {C,N,S,V}, Ω_SG → Ω_MG, ∅ → ∅ (m^{Ω_MG}(r(A)) = m^{Ω_SG}(A)).
Subset refineSubset(Subset a_sg);

/// The refined mass function m_SG^{Ω_MG} of a ScanGrid mass function.
MassMG refine(const MassSG& m_sg);

}  // namespace core
}  // namespace map_aided_fusion

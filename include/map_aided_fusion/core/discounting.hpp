/**
 * @file discounting.hpp
 * @brief Classical discounting and the contextual discounting of Mercier et al. (2008) over the
 *        paper's coarsening Θ = {θ_static = {C,N}, θ_dynamic = {S,V}, θ_free = {F}} (section 2.5).
 */
#pragma once

#include <array>

#include "map_aided_fusion/core/mass_function.hpp"

namespace map_aided_fusion {
namespace core {

/**
 * @brief Classical discounting with rate α: ^α m(A) = (1 − α) m(A) for A ≠ Ω, ^α m(Ω) = (1 − α) m(Ω) + α.
 * @throws ParameterError when α ∉ [0, 1].
 */
template <class Frame>
MassFunction<Frame> discount(const MassFunction<Frame>& m, double alpha);

/// Discount rates per context of Θ, each in [0, 1] (per scan, or per second; see FusionParams).
struct ContextualRates
{
  double alpha_static = 0.02;   ///< θ_static = {C, N}: buildings and infrastructure change slowly
  double alpha_dynamic = 0.2;   ///< θ_dynamic = {S, V}: stopped and moving objects
  double alpha_free = 0.1;      ///< θ_free = {F}: free space
  /// @throws ParameterError naming alpha_static, alpha_dynamic or alpha_free when outside [0, 1].
  void validate() const;
  /// The rates equivalent to applying these @p k times in a row: 1 − (1 − α)^k for each context.
  ContextualRates compounded(double k) const;
};

/// The contexts of Θ, in the order used by ContextualDiscountWeights.
constexpr std::array<Subset, 3> kContexts{ FrameMG::kStatic, FrameMG::kDynamic, FrameMG::kFreeContext };

/// Bit mask of the contexts θ_l of Θ that are not contained in @p a (the ones discounting can add).
constexpr int openContexts(Subset a)
{
  int open = 0;
  for (int l = 0; l < 3; ++l)
    if (!isSubsetOf(kContexts[l], a)) open |= 1 << l;
  return open;
}

/// Union of the contexts selected by the bit mask @p s.
constexpr Subset contextUnion(int s)
{
  Subset u = 0;
  for (int l = 0; l < 3; ++l)
    if (s & (1 << l)) u = static_cast<Subset>(u | kContexts[l]);
  return u;
}

/**
 * @brief Closed form of the contextual discounting, precomputed for one set of rates.
 *
 * The disjunctive combination m ∪ m_static ∪ m_dynamic ∪ m_free with m_l(θ_l) = α_l, m_l(∅) = 1 − α_l
 * moves the mass m(A) to A ∪ ⋃_{l∈S} θ_l for each set S of contexts not already inside A, with weight
 * w(open(A), S) = Π_{l∈S} α_l · Π_{l∈open(A)∖S} (1 − α_l), where open(A) = {l : θ_l ⊄ A}
 * (contexts inside A add nothing, and their two weights sum to 1).
 * Equivalently, in implicability: b'(A) = b(A) · Π_{l: θ_l ⊄ A} (1 − α_l).
 */
template <typename T>
struct ContextualDiscountWeights
{
  T w[8][8] = {};  ///< w[open][S], zero unless S ⊆ open
  explicit ContextualDiscountWeights(const ContextualRates& rates);
};

/// Contextual discounting ^α m (closed form, see ContextualDiscountWeights).
MassMG contextualDiscount(const MassMG& m, const ContextualRates& rates);

}  // namespace core
}  // namespace map_aided_fusion

/**
 * @file counter.hpp
 * @brief The per-cell occupancy counter ζ and the specialisation of the MapGrid by ζ (section 2.4).
 */
#pragma once

#include "map_aided_fusion/core/mass_function.hpp"
#include "map_aided_fusion/core/rules.hpp"

namespace map_aided_fusion {
namespace core {

/**
 * @brief Where the specialisation sends ζ·m({V}): the paper's matrix sends ζ·m(A) to A ∖ {V} for every
 *        A ∋ V, which for A = {V} is ∅.
 */
enum class SpecialisationMode
{
  /// Default: ζ·m({V}) goes to {S}; a cell that stayed occupied without conflict holds a stopped object.
  kMovingToStopped,
  /// The paper's matrix to the letter: ζ·m({V}) goes to ∅, then the result is normalised (Dempster-style).
  /// If everything landed on ∅ the cell becomes vacuous.
  kLiteral
};

/// Parameters of the counter update (equation 3) and of the specialisation (equation 4).
struct CounterParams
{
  double delta_inc = 0.05;        ///< δ_inc ∈ [0,1]: increment of ζ per consistent occupied observation
  double delta_dec = 0.5;         ///< δ_dec ∈ [0,1]: decrement of ζ per conflicting observation
  double gamma_occupied = 0.6;    ///< γ_O ∈ [0,1]: m_MG(O) needed to count the cell as occupied
  double gamma_conflict = 0.1;    ///< γ_∅ ∈ [0,1]: ∅_FO + ∅_OF above this is a change
  SpecialisationMode mode = SpecialisationMode::kMovingToStopped;
  /// @throws ParameterError naming delta_inc, delta_dec, gamma_occupied or gamma_conflict when outside [0, 1].
  void validate() const;
};

/**
 * @brief Equation 3: ζ ← min(1, ζ + δ_inc) if m_MG(O) ≥ γ_O and ∅_FO + ∅_OF ≤ γ_∅;
 *        ζ ← max(0, ζ − δ_dec) if ∅_FO + ∅_OF > γ_∅; otherwise unchanged.
 * @param m_occupied m_MG,t(O), the mass on the non-empty subsets of {C,N,S,V} after the fusion.
 */
double updateCounter(double zeta, double m_occupied, const ConflictMasses& conflicts, const CounterParams& p);

/**
 * @brief Equation 4: m'(A) = Σ_B S(A,B) m(B) with S(A∖{V}, A) = ζ and S(A, A) = 1 − ζ for A ∋ V,
 *        S(A, A) = 1 otherwise; see SpecialisationMode for A = {V}.
 */
MassMG specialise(const MassMG& m, double zeta, SpecialisationMode mode = SpecialisationMode::kMovingToStopped);

}  // namespace core
}  // namespace map_aided_fusion

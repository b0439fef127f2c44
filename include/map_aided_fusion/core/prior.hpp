/**
 * @file prior.hpp
 * @brief The PriorGrid's per-cell context classes and their mass functions (equation 1).
 */
#pragma once

#include <cstdint>

#include "map_aided_fusion/core/frame.hpp"
#include "map_aided_fusion/core/mass_function.hpp"

namespace map_aided_fusion {
namespace core {

/// Context class of a PriorGrid cell, stored as one byte per cell.
enum class PriorClass : std::uint8_t
{
  kUnknown = 0,   ///< outside the map's extent: vacuous prior
  kBuilding = 1,  ///< inside a building polygon b_i: m(B = {C}) = β_B
  kRoad = 2,      ///< on the road surface r_i: m(R = {F,S,V}) = β_R
  kOther = 3,     ///< elsewhere in the map (pavements…): m(T = {F,N,S,V}) = β_T
};

/// Number of PriorClass values.
constexpr int kNumPriorClasses = 4;

/// Map confidences β of equation 1, each in [0, 1].
struct PriorConfidence
{
  double beta_building = 0.9;  ///< β_B
  double beta_road = 0.9;      ///< β_R
  double beta_other = 0.8;     ///< β_T
  /// @throws ParameterError naming beta_building, beta_road or beta_other when outside [0, 1].
  void validate() const;
  /// β of a class (0 for kUnknown).
  double beta(PriorClass c) const;
};

/// The focal set of a class (B, R, T; Ω for kUnknown).
Subset priorFocalSet(PriorClass c);

/// Equation 1 for one cell: m(focal set of c) = β_c, m(Ω) = 1 − β_c.
MassMG priorMass(PriorClass c, const PriorConfidence& beta);

}  // namespace core
}  // namespace map_aided_fusion

/**
 * @file pignistic.hpp
 * @brief The pignistic transform BetP (Smets 2005), used to visualise and decide on the MapGrid.
 */
#pragma once

#include <array>

#include "map_aided_fusion/core/mass_function.hpp"

namespace map_aided_fusion {
namespace core {

/**
 * @brief BetP(ω) = Σ_{A ∋ ω} m(A) / (|A| (1 − m(∅))) for each element ω of the frame.
 *
 * When m(∅) = 1 nothing is known: the result is uniform (1/N each).
 */
template <class Frame>
std::array<double, Frame::kSize> pignistic(const MassFunction<Frame>& m)
{
  std::array<double, Frame::kSize> p{};
  const double norm = 1.0 - m[0];
  if (norm <= 0.0)
  {
    p.fill(1.0 / Frame::kSize);
    return p;
  }
  for (int a = 1; a < Frame::kNumSubsets; ++a)
  {
    if (m[a] == 0.0) continue;
    const double share = m[a] / (cardinality(static_cast<Subset>(a)) * norm);
    for (int i = 0; i < Frame::kSize; ++i)
      if (a & (1 << i)) p[i] += share;
  }
  return p;
}

}  // namespace core
}  // namespace map_aided_fusion

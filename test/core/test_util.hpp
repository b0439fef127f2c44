// Helpers shared by the core tests: random mass functions and comparisons.
#pragma once

#include <gtest/gtest.h>

#include <random>

#include "map_aided_fusion/core/mass_function.hpp"
#include "map_aided_fusion/core/mass_grid.hpp"

namespace maf_test {

using map_aided_fusion::core::MassFunction;
using map_aided_fusion::core::Subset;

/// A random mass function with 1..max_focal focal sets drawn among the subsets of the frame
/// (∅ excluded unless allow_empty; with only_stored, only the subsets a MassGrid of the frame stores).
template <class Frame>
MassFunction<Frame> randomMass(std::mt19937& rng, int max_focal = 6, bool allow_empty = false, bool only_stored = false)
{
  std::uniform_int_distribution<int> count(1, max_focal);
  std::uniform_int_distribution<int> subset(allow_empty ? 0 : 1, Frame::kNumSubsets - 1);
  std::uniform_real_distribution<double> weight(0.01, 1.0);
  typename MassFunction<Frame>::Values v{};
  const int k = count(rng);
  double total = 0.0;
  for (int i = 0; i < k; ++i)
  {
    const double w = weight(rng);
    int a = subset(rng);
    while (only_stored && !map_aided_fusion::core::MassGrid<Frame>::stored(static_cast<Subset>(a))) a = subset(rng);
    v[a] += w;
    total += w;
  }
  for (auto& x : v) x /= total;
  return MassFunction<Frame>::fromValues(v);
}

/// Every mass ≥ −tol and the sum is 1 within tol.
template <class Frame>
::testing::AssertionResult isValidMass(const MassFunction<Frame>& m, double tol = 1e-9)
{
  double s = 0.0;
  for (int a = 0; a < Frame::kNumSubsets; ++a)
  {
    if (!(m[a] >= -tol)) return ::testing::AssertionFailure() << "m(" << a << ") = " << m[a] << " < 0";
    s += m[a];
  }
  if (std::abs(s - 1.0) > tol) return ::testing::AssertionFailure() << "sum = " << s;
  return ::testing::AssertionSuccess();
}

/// Every subset's mass equal within tol.
template <class Frame>
::testing::AssertionResult massNear(const MassFunction<Frame>& a, const MassFunction<Frame>& b, double tol = 1e-9)
{
  for (int s = 0; s < Frame::kNumSubsets; ++s)
    if (std::abs(a[s] - b[s]) > tol)
      return ::testing::AssertionFailure()
             << "m(" << map_aided_fusion::core::subsetName<Frame>(static_cast<Subset>(s)) << "): " << a[s] << " vs "
             << b[s];
  return ::testing::AssertionSuccess();
}

}  // namespace maf_test

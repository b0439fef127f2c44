/**
 * @file mass_function.hpp
 * @brief Mass functions (basic belief assignments) on a finite frame, with validation and the
 *        Möbius transforms to and from commonality, implicability, belief and plausibility.
 */
#pragma once

#include <array>
#include <cmath>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <utility>

#include "map_aided_fusion/core/frame.hpp"

namespace map_aided_fusion {
namespace core {

/// Default tolerance on |Σ m − 1| used by MassFunction::validate().
constexpr double kMassSumTolerance = 1e-6;

/// Thrown when a mass function is not a valid basic belief assignment.
class InvalidMassFunction : public std::invalid_argument
{
public:
  using std::invalid_argument::invalid_argument;
};

/**
 * @brief A mass function m: 2^Ω → [0, 1] on the frame @p Frame, stored densely by subset mask.
 *
 * m(∅) is allowed (unnormalised results of the conjunctive rule keep it).
 */
template <class Frame>
class MassFunction
{
public:
  static constexpr int kNumSubsets = Frame::kNumSubsets;
  using Values = std::array<double, kNumSubsets>;

  /// All mass on ∅ is not a default: the default is the vacuous mass function m(Ω) = 1.
  MassFunction() { m_.fill(0.0); m_[Frame::kOmega] = 1.0; }

  /// From explicit (subset, mass) pairs; unspecified subsets get 0. Not validated.
  MassFunction(std::initializer_list<std::pair<Subset, double>> focal)
  {
    m_.fill(0.0);
    for (const auto& f : focal) m_[f.first] += f.second;
  }

  /// From a dense array indexed by subset mask. Not validated.
  static MassFunction fromValues(const Values& v)
  {
    MassFunction r;
    r.m_ = v;
    return r;
  }

  static MassFunction vacuous() { return MassFunction(); }

  double operator[](Subset a) const { return m_[a]; }
  double& operator[](Subset a) { return m_[a]; }
  const Values& values() const { return m_; }
  Values& values() { return m_; }

  double sum() const
  {
    double s = 0.0;
    for (double v : m_) s += v;
    return s;
  }

  /**
   * @brief Checks that every mass is finite and ≥ 0 and that they sum to 1 within @p tolerance.
   * @throws InvalidMassFunction saying which condition fails and for which subset.
   */
  void validate(double tolerance = kMassSumTolerance) const
  {
    for (int a = 0; a < kNumSubsets; ++a)
    {
      const double v = m_[a];
      const std::string where = "m(" + subsetName<Frame>(static_cast<Subset>(a)) + ")";
      if (!std::isfinite(v)) throw InvalidMassFunction("mass function: " + where + " is not finite");
      if (v < 0.0) throw InvalidMassFunction("mass function: " + where + " = " + std::to_string(v) + " is negative");
    }
    const double s = sum();
    if (std::abs(s - 1.0) > tolerance)
      throw InvalidMassFunction("mass function: masses sum to " + std::to_string(s) + ", not 1 (tolerance " +
                                std::to_string(tolerance) + ")");
  }

  /// True when validate() would not throw.
  bool isValid(double tolerance = kMassSumTolerance) const
  {
    try
    {
      validate(tolerance);
      return true;
    }
    catch (const InvalidMassFunction&)
    {
      return false;
    }
  }

  /// Mass on the non-empty subsets of @p a (for Ω_MG and a = {C,N,S,V}: the paper's m(O)).
  double massInside(Subset a) const
  {
    double s = 0.0;
    for (int b = 1; b < kNumSubsets; ++b)
      if (isSubsetOf(static_cast<Subset>(b), a)) s += m_[b];
    return s;
  }

private:
  Values m_;
};

using MassMG = MassFunction<FrameMG>;
using MassSG = MassFunction<FrameSG>;

/// @name Fast Möbius transforms (N·2^(N−1) additions each)
/// @{

/// Commonality q(A) = Σ_{B ⊇ A} m(B).
template <class Frame>
typename MassFunction<Frame>::Values commonality(const MassFunction<Frame>& m)
{
  auto q = m.values();
  for (int bit = 1; bit < Frame::kNumSubsets; bit <<= 1)
    for (int a = 0; a < Frame::kNumSubsets; ++a)
      if (!(a & bit)) q[a] += q[a | bit];
  return q;
}

/// Inverse of commonality(): m(A) = Σ_{B ⊇ A} (−1)^{|B∖A|} q(B).
template <class Frame>
MassFunction<Frame> fromCommonality(typename MassFunction<Frame>::Values q)
{
  for (int bit = 1; bit < Frame::kNumSubsets; bit <<= 1)
    for (int a = 0; a < Frame::kNumSubsets; ++a)
      if (!(a & bit)) q[a] -= q[a | bit];
  return MassFunction<Frame>::fromValues(q);
}

/// Implicability b(A) = Σ_{B ⊆ A} m(B) (m(∅) included).
template <class Frame>
typename MassFunction<Frame>::Values implicability(const MassFunction<Frame>& m)
{
  auto b = m.values();
  for (int bit = 1; bit < Frame::kNumSubsets; bit <<= 1)
    for (int a = 0; a < Frame::kNumSubsets; ++a)
      if (a & bit) b[a] += b[a ^ bit];
  return b;
}

/// Inverse of implicability(): m(A) = Σ_{B ⊆ A} (−1)^{|A∖B|} b(B).
template <class Frame>
MassFunction<Frame> fromImplicability(typename MassFunction<Frame>::Values b)
{
  for (int bit = 1; bit < Frame::kNumSubsets; bit <<= 1)
    for (int a = 0; a < Frame::kNumSubsets; ++a)
      if (a & bit) b[a] -= b[a ^ bit];
  return MassFunction<Frame>::fromValues(b);
}

/// Belief bel(A) = Σ_{∅ ≠ B ⊆ A} m(B) = b(A) − m(∅).
template <class Frame>
typename MassFunction<Frame>::Values belief(const MassFunction<Frame>& m)
{
  auto b = implicability(m);
  const double empty = m[0];
  for (auto& v : b) v -= empty;
  return b;
}

/// Inverse of belief() for a mass function with m(∅) = @p empty_mass.
template <class Frame>
MassFunction<Frame> fromBelief(typename MassFunction<Frame>::Values bel, double empty_mass = 0.0)
{
  for (auto& v : bel) v += empty_mass;
  return fromImplicability<Frame>(bel);
}

/// Plausibility pl(A) = Σ_{B ∩ A ≠ ∅} m(B) = 1 − b(Ā) for a mass function summing to 1.
template <class Frame>
typename MassFunction<Frame>::Values plausibility(const MassFunction<Frame>& m)
{
  const auto b = implicability(m);
  const double total = m.sum();
  typename MassFunction<Frame>::Values pl;
  for (int a = 0; a < Frame::kNumSubsets; ++a) pl[a] = total - b[Frame::kOmega & ~a];
  return pl;
}

/// Inverse of plausibility() for a mass function summing to @p total.
template <class Frame>
MassFunction<Frame> fromPlausibility(const typename MassFunction<Frame>::Values& pl, double total = 1.0)
{
  typename MassFunction<Frame>::Values b;
  for (int a = 0; a < Frame::kNumSubsets; ++a) b[a] = total - pl[Frame::kOmega & ~a];
  return fromImplicability<Frame>(b);
}
/// @}

}  // namespace core
}  // namespace map_aided_fusion

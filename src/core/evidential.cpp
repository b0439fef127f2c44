#include <cmath>

#include "cell_kernels.hpp"
#include "map_aided_fusion/core/counter.hpp"
#include "map_aided_fusion/core/discounting.hpp"
#include "map_aided_fusion/core/grid_geometry.hpp"
#include "map_aided_fusion/core/parameters.hpp"
#include "map_aided_fusion/core/prior.hpp"
#include "map_aided_fusion/core/rules.hpp"

namespace map_aided_fusion {
namespace core {

MassMG modifiedYager(const MassMG& m1, const MassMG& m2, ConflictMasses* conflicts, bool building_conflict)
{
  auto r = conjunctive(m1, m2);
  const double fo = m1[FrameMG::kF] * m2.massInside(FrameMG::kO);
  const double of = m1.massInside(FrameMG::kO) * m2[FrameMG::kF];
  if (conflicts) *conflicts = ConflictMasses{ fo, of, r[0] - fo - of };
  const double to_v = building_conflict ? m1[FrameMG::kF] * (m2.massInside(FrameMG::kO) - m2[FrameMG::kC]) : fo;
  r[FrameMG::kV] += to_v;
  r[FrameMG::kOmega] += r[0] - to_v;  // ∅_OF, the remaining conflict (and ∅_FO met by {C}, step building conflict)
  r[0] = 0.0;
  return r;
}

Subset refineSubset(Subset a_sg)
{
  Subset r = 0;
  if (a_sg & FrameSG::kF) r = static_cast<Subset>(r | FrameMG::kF);
  if (a_sg & FrameSG::kO) r = static_cast<Subset>(r | FrameMG::kO);
  return r;
}

MassMG refine(const MassSG& m_sg)
{
  MassMG::Values v{};
  for (int a = 0; a < FrameSG::kNumSubsets; ++a) v[refineSubset(static_cast<Subset>(a))] += m_sg[a];
  return MassMG::fromValues(v);
}

template <class Frame>
MassFunction<Frame> discount(const MassFunction<Frame>& m, double alpha)
{
  requireUnit("alpha", alpha);
  auto r = m;
  for (auto& v : r.values()) v *= 1.0 - alpha;
  r[Frame::kOmega] += alpha * m.sum();
  return r;
}
template MassMG discount(const MassMG&, double);
template MassSG discount(const MassSG&, double);

void ContextualRates::validate() const
{
  requireUnit("alpha_static", alpha_static);
  requireUnit("alpha_dynamic", alpha_dynamic);
  requireUnit("alpha_free", alpha_free);
}

ContextualRates ContextualRates::compounded(double k) const
{
  auto c = [k](double a) { return 1.0 - std::pow(1.0 - a, k); };
  return ContextualRates{ c(alpha_static), c(alpha_dynamic), c(alpha_free) };
}

template <typename T>
ContextualDiscountWeights<T>::ContextualDiscountWeights(const ContextualRates& rates)
{
  rates.validate();
  const double alpha[3] = { rates.alpha_static, rates.alpha_dynamic, rates.alpha_free };
  for (int open = 0; open < 8; ++open)
    for (int s = 0; s < 8; ++s)
    {
      if (s & ~open) continue;
      double w = 1.0;
      for (int l = 0; l < 3; ++l)
        if (open & (1 << l)) w *= (s & (1 << l)) ? alpha[l] : 1.0 - alpha[l];
      this->w[open][s] = static_cast<T>(w);
    }
}
template struct ContextualDiscountWeights<float>;
template struct ContextualDiscountWeights<double>;

MassMG contextualDiscount(const MassMG& m, const ContextualRates& rates)
{
  const ContextualDiscountWeights<double> w(rates);
  double v[FrameMG::kNumSubsets];
  for (int a = 0; a < FrameMG::kNumSubsets; ++a) v[a] = m[a];
  kernels::contextualDiscount(v, w);
  MassMG::Values out;
  for (int a = 0; a < FrameMG::kNumSubsets; ++a) out[a] = v[a];
  return MassMG::fromValues(out);
}

void CounterParams::validate() const
{
  requireUnit("delta_inc", delta_inc);
  requireUnit("delta_dec", delta_dec);
  requireUnit("gamma_occupied", gamma_occupied);
  requireUnit("gamma_conflict", gamma_conflict);
}

double updateCounter(double zeta, double m_occupied, const ConflictMasses& c, const CounterParams& p)
{
  const double conflict = c.free_occupied + c.occupied_free;
  if (conflict > p.gamma_conflict) return std::max(0.0, zeta - p.delta_dec);
  if (m_occupied >= p.gamma_occupied) return std::min(1.0, zeta + p.delta_inc);
  return zeta;
}

MassMG specialise(const MassMG& m, double zeta, SpecialisationMode mode)
{
  MassMG::Values r{};
  for (int a = 0; a < FrameMG::kNumSubsets; ++a)
  {
    if (a & FrameMG::kV)
    {
      Subset target = static_cast<Subset>(a & ~FrameMG::kV);
      if (target == 0 && mode == SpecialisationMode::kMovingToStopped) target = FrameMG::kS;
      r[target] += zeta * m[a];
      r[a] += (1.0 - zeta) * m[a];
    }
    else
    {
      r[a] += m[a];
    }
  }
  if (mode == SpecialisationMode::kLiteral)
  {
    const double norm = 1.0 - r[0];
    if (norm <= 0.0) return MassMG::vacuous();
    r[0] = 0.0;
    for (auto& v : r) v /= norm;
  }
  return MassMG::fromValues(r);
}

void PriorConfidence::validate() const
{
  requireUnit("beta_building", beta_building);
  requireUnit("beta_road", beta_road);
  requireUnit("beta_other", beta_other);
}

double PriorConfidence::beta(PriorClass c) const
{
  switch (c)
  {
    case PriorClass::kBuilding:
      return beta_building;
    case PriorClass::kRoad:
      return beta_road;
    case PriorClass::kOther:
      return beta_other;
    case PriorClass::kUnknown:
      break;
  }
  return 0.0;
}

Subset priorFocalSet(PriorClass c)
{
  switch (c)
  {
    case PriorClass::kBuilding:
      return FrameMG::kBuilding;
    case PriorClass::kRoad:
      return FrameMG::kRoad;
    case PriorClass::kOther:
      return FrameMG::kOther;
    case PriorClass::kUnknown:
      break;
  }
  return FrameMG::kOmega;
}

MassMG priorMass(PriorClass c, const PriorConfidence& beta)
{
  const double b = beta.beta(c);
  MassMG m{ { FrameMG::kOmega, 1.0 - b } };
  m[priorFocalSet(c)] += b;
  return m;
}

void GridGeometry::validate() const
{
  requirePositive("resolution", resolution);
  if (width < 1) throw ParameterError("width", "must be at least 1 cell, got " + std::to_string(width));
  if (height < 1) throw ParameterError("height", "must be at least 1 cell, got " + std::to_string(height));
  if (!std::isfinite(origin_x)) throw ParameterError("origin_x", "must be finite");
  if (!std::isfinite(origin_y)) throw ParameterError("origin_y", "must be finite");
}

}  // namespace core
}  // namespace map_aided_fusion

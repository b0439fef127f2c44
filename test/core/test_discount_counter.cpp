#include <gtest/gtest.h>

#include "map_aided_fusion/core/counter.hpp"
#include "map_aided_fusion/core/discounting.hpp"
#include "map_aided_fusion/core/fusion.hpp"
#include "map_aided_fusion/core/parameters.hpp"
#include "map_aided_fusion/core/pignistic.hpp"
#include "map_aided_fusion/core/prior.hpp"
#include "test_util.hpp"

using namespace map_aided_fusion::core;
using maf_test::isValidMass;
using maf_test::massNear;
using maf_test::randomMass;

constexpr Subset F = FrameMG::kF, C = FrameMG::kC, N = FrameMG::kN, S = FrameMG::kS, V = FrameMG::kV;
constexpr Subset O = FrameMG::kO, W = FrameMG::kOmega;

namespace {

/// The definition: m ∪ m_static ∪ m_dynamic ∪ m_free with m_l(θ_l) = α_l, m_l(∅) = 1 − α_l.
MassMG contextualByDefinition(const MassMG& m, const ContextualRates& r)
{
  const MassMG ms{ { FrameMG::kStatic, r.alpha_static }, { 0, 1.0 - r.alpha_static } };
  const MassMG md{ { FrameMG::kDynamic, r.alpha_dynamic }, { 0, 1.0 - r.alpha_dynamic } };
  const MassMG mf{ { FrameMG::kFreeContext, r.alpha_free }, { 0, 1.0 - r.alpha_free } };
  return disjunctive(disjunctive(disjunctive(m, ms), md), mf);
}

template <class Fn>
std::string parameterNameOf(Fn fn)
{
  try
  {
    fn();
  }
  catch (const ParameterError& e)
  {
    EXPECT_EQ(std::string(e.what()).rfind(e.parameter(), 0), 0u) << "message does not start with the name";
    return e.parameter();
  }
  return "";
}

}  // namespace

TEST(Discount, ClassicalHandComputed)
{
  const MassMG m{ { F, 0.6 }, { S | V, 0.4 } };
  const auto r = discount(m, 0.25);
  EXPECT_NEAR(r[F], 0.45, 1e-12);
  EXPECT_NEAR(r[S | V], 0.3, 1e-12);
  EXPECT_NEAR(r[W], 0.25, 1e-12);
  EXPECT_EQ(parameterNameOf([&] { discount(m, 1.5); }), "alpha");
}

TEST(ContextualDiscount, HandComputed)
{
  // m({V}) = 1, α = (static 0, dynamic 0.3, free 0.1): V stays with 0.7·0.9, goes to SV with 0.3·0.9,
  // to FV with 0.7·0.1 and to FSV with 0.3·0.1.
  const MassMG m{ { V, 1.0 } };
  const auto r = contextualDiscount(m, ContextualRates{ 0.0, 0.3, 0.1 });
  EXPECT_NEAR(r[V], 0.63, 1e-12);
  EXPECT_NEAR(r[S | V], 0.27, 1e-12);
  EXPECT_NEAR(r[F | V], 0.07, 1e-12);
  EXPECT_NEAR(r[F | S | V], 0.03, 1e-12);
  EXPECT_TRUE(isValidMass(r));
}

TEST(ContextualDiscount, ClosedFormEqualsThreeDisjunctiveCombinations)
{
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 3000; ++trial)
  {
    const auto m = randomMass<FrameMG>(rng, 8, trial % 4 == 0);
    const ContextualRates r{ u(rng), u(rng), u(rng) };
    ASSERT_TRUE(massNear(contextualDiscount(m, r), contextualByDefinition(m, r), 1e-12)) << "trial " << trial;
  }
}

TEST(ContextualDiscount, ImplicabilityIsScaledPerContext)
{
  std::mt19937 rng(12);
  const ContextualRates r{ 0.1, 0.4, 0.25 };
  const double keep[3] = { 0.9, 0.6, 0.75 };
  for (int trial = 0; trial < 200; ++trial)
  {
    const auto m = randomMass<FrameMG>(rng);
    const auto b = implicability(m);
    const auto bd = implicability(contextualDiscount(m, r));
    for (int a = 0; a < FrameMG::kNumSubsets; ++a)
    {
      double factor = 1.0;
      for (int l = 0; l < 3; ++l)
        if (!isSubsetOf(kContexts[l], static_cast<Subset>(a))) factor *= keep[l];
      ASSERT_NEAR(bd[a], b[a] * factor, 1e-12);
    }
  }
}

TEST(ContextualDiscount, ZeroIsIdentityOneIsVacuous)
{
  std::mt19937 rng(13);
  for (int trial = 0; trial < 200; ++trial)
  {
    const auto m = randomMass<FrameMG>(rng);
    EXPECT_TRUE(massNear(contextualDiscount(m, ContextualRates{ 0, 0, 0 }), m, 1e-15));
    EXPECT_TRUE(massNear(contextualDiscount(m, ContextualRates{ 1, 1, 1 }), MassMG::vacuous(), 1e-15));
    // α_l = 1 alone makes context l vacuous: every focal set then contains θ_l.
    const ContextualRates only[3] = { { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } };
    for (int l = 0; l < 3; ++l)
    {
      const auto r = contextualDiscount(m, only[l]);
      for (int a = 0; a < FrameMG::kNumSubsets; ++a)
      {
        if (!isSubsetOf(kContexts[l], static_cast<Subset>(a))) { ASSERT_EQ(r[a], 0.0); }
      }
      EXPECT_TRUE(isValidMass(r));
    }
  }
}

TEST(ContextualDiscount, TwiceEqualsOnceWithCompoundedRate)
{
  std::mt19937 rng(14);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 500; ++trial)
  {
    const auto m = randomMass<FrameMG>(rng);
    const ContextualRates r{ u(rng), u(rng), u(rng) };
    const ContextualRates twice{ 1 - (1 - r.alpha_static) * (1 - r.alpha_static),
                                 1 - (1 - r.alpha_dynamic) * (1 - r.alpha_dynamic),
                                 1 - (1 - r.alpha_free) * (1 - r.alpha_free) };
    EXPECT_TRUE(massNear(contextualDiscount(contextualDiscount(m, r), r), contextualDiscount(m, twice), 1e-12));
    auto k_times = m;
    for (int k = 0; k < 5; ++k) k_times = contextualDiscount(k_times, r);
    EXPECT_TRUE(massNear(k_times, contextualDiscount(m, r.compounded(5)), 1e-12));
  }
}

TEST(ContextualDiscount, RatesOutsideUnitIntervalNameTheParameter)
{
  EXPECT_EQ(parameterNameOf([] { ContextualRates{ -0.1, 0.2, 0.2 }.validate(); }), "alpha_static");
  EXPECT_EQ(parameterNameOf([] { ContextualRates{ 0.1, 1.2, 0.2 }.validate(); }), "alpha_dynamic");
  EXPECT_EQ(parameterNameOf([] { ContextualRates{ 0.1, 0.2, std::nan("") }.validate(); }), "alpha_free");
  EXPECT_EQ(parameterNameOf([] { contextualDiscount(MassMG(), ContextualRates{ 0.1, 0.2, 2.0 }); }), "alpha_free");
}

TEST(Counter, Equation3)
{
  CounterParams p;
  p.delta_inc = 0.25;
  p.delta_dec = 0.5;
  p.gamma_occupied = 0.6;
  p.gamma_conflict = 0.1;
  const ConflictMasses none{ 0.0, 0.0, 0.3 };  // "other" conflict does not count
  const ConflictMasses some{ 0.08, 0.05, 0.0 };
  EXPECT_DOUBLE_EQ(updateCounter(0.5, 0.7, none, p), 0.75);   // occupied, consistent
  EXPECT_DOUBLE_EQ(updateCounter(0.9, 0.6, none, p), 1.0);    // clamped at 1; γ_O reached exactly
  EXPECT_DOUBLE_EQ(updateCounter(0.5, 0.59, none, p), 0.5);   // not occupied enough: unchanged
  EXPECT_DOUBLE_EQ(updateCounter(0.75, 0.9, some, p), 0.25);  // ∅_FO + ∅_OF = 0.13 > γ_∅
  EXPECT_DOUBLE_EQ(updateCounter(0.25, 0.9, some, p), 0.0);   // clamped at 0
  const ConflictMasses edge{ 0.05, 0.05, 0.0 };
  EXPECT_DOUBLE_EQ(updateCounter(0.5, 0.9, edge, p), 0.75);   // = γ_∅ is not above it
}

TEST(Counter, ParametersOutsideUnitIntervalNameTheParameter)
{
  EXPECT_EQ(parameterNameOf([] { CounterParams p; p.delta_inc = 1.5; p.validate(); }), "delta_inc");
  EXPECT_EQ(parameterNameOf([] { CounterParams p; p.delta_dec = -1; p.validate(); }), "delta_dec");
  EXPECT_EQ(parameterNameOf([] { CounterParams p; p.gamma_occupied = 2; p.validate(); }), "gamma_occupied");
  EXPECT_EQ(parameterNameOf([] { CounterParams p; p.gamma_conflict = -0.5; p.validate(); }), "gamma_conflict");
  EXPECT_EQ(parameterNameOf([] { PriorConfidence b; b.beta_road = 1.1; b.validate(); }), "beta_road");
}

TEST(Specialisation, Equation4WithMovingToStopped)
{
  const MassMG m{ { V, 0.5 }, { S | V, 0.2 }, { F | V, 0.1 }, { W, 0.2 } };
  const auto r = specialise(m, 0.4, SpecialisationMode::kMovingToStopped);
  EXPECT_NEAR(r[V], 0.3, 1e-12);
  EXPECT_NEAR(r[S], 0.2 + 0.08, 1e-12);  // ζ·m(V) and ζ·m(SV)
  EXPECT_NEAR(r[S | V], 0.12, 1e-12);
  EXPECT_NEAR(r[F | V], 0.06, 1e-12);
  EXPECT_NEAR(r[F], 0.04, 1e-12);
  EXPECT_NEAR(r[W], 0.12, 1e-12);
  EXPECT_NEAR(r[F | C | N | S], 0.08, 1e-12);
  EXPECT_EQ(r[0], 0.0);
  EXPECT_TRUE(isValidMass(r));
}

TEST(Specialisation, LiteralSendsVToEmptyThenNormalises)
{
  const MassMG m{ { V, 0.5 }, { S | V, 0.2 }, { F | V, 0.1 }, { W, 0.2 } };
  const auto r = specialise(m, 0.4, SpecialisationMode::kLiteral);
  const double norm = 1.0 - 0.2;
  EXPECT_NEAR(r[V], 0.3 / norm, 1e-12);
  EXPECT_NEAR(r[S], 0.08 / norm, 1e-12);
  EXPECT_NEAR(r[W], 0.12 / norm, 1e-12);
  EXPECT_EQ(r[0], 0.0);
  EXPECT_TRUE(isValidMass(r));
  // Everything on V with ζ = 1: nothing is left, the cell becomes vacuous.
  EXPECT_TRUE(massNear(specialise(MassMG{ { V, 1.0 } }, 1.0, SpecialisationMode::kLiteral), MassMG::vacuous(), 0.0));
}

TEST(Specialisation, ZetaZeroIsIdentity)
{
  std::mt19937 rng(15);
  for (int trial = 0; trial < 200; ++trial)
  {
    const auto m = randomMass<FrameMG>(rng);
    EXPECT_TRUE(massNear(specialise(m, 0.0), m, 0.0));
    EXPECT_TRUE(isValidMass(specialise(m, 0.7)));
    EXPECT_TRUE(isValidMass(specialise(m, 0.7, SpecialisationMode::kLiteral)));
    // ζ = 1 leaves no mass on any set containing V.
    const auto r = specialise(m, 1.0);
    for (int a = 0; a < 32; ++a)
    {
      if (a & V) { EXPECT_EQ(r[a], 0.0); }
    }
  }
}

TEST(Pignistic, HandComputed)
{
  const MassMG m{ { F, 0.5 }, { S | V, 0.3 }, { W, 0.2 } };
  const auto p = pignistic(m);
  EXPECT_NEAR(p[0], 0.54, 1e-12);
  EXPECT_NEAR(p[1], 0.04, 1e-12);
  EXPECT_NEAR(p[2], 0.04, 1e-12);
  EXPECT_NEAR(p[3], 0.19, 1e-12);
  EXPECT_NEAR(p[4], 0.19, 1e-12);
  // Normalised by 1 − m(∅).
  const MassMG e{ { 0, 0.5 }, { F, 0.25 }, { C | N, 0.25 } };
  const auto q = pignistic(e);
  EXPECT_NEAR(q[0], 0.5, 1e-12);
  EXPECT_NEAR(q[1], 0.25, 1e-12);
  EXPECT_NEAR(q[2], 0.25, 1e-12);
}

TEST(Pignistic, SumsToOne)
{
  std::mt19937 rng(16);
  for (int trial = 0; trial < 1000; ++trial)
  {
    const auto p = pignistic(randomMass<FrameMG>(rng, 8, true));
    double s = 0;
    for (double v : p)
    {
      EXPECT_GE(v, 0.0);
      s += v;
    }
    EXPECT_NEAR(s, 1.0, 1e-12);
  }
}

TEST(Prior, Equation1)
{
  const PriorConfidence beta{ 0.9, 0.8, 0.7 };
  const auto b = priorMass(PriorClass::kBuilding, beta);
  EXPECT_NEAR(b[C], 0.9, 1e-15);
  EXPECT_NEAR(b[W], 0.1, 1e-15);
  const auto r = priorMass(PriorClass::kRoad, beta);
  EXPECT_NEAR(r[F | S | V], 0.8, 1e-15);
  EXPECT_NEAR(r[W], 0.2, 1e-15);
  const auto t = priorMass(PriorClass::kOther, beta);
  EXPECT_NEAR(t[F | N | S | V], 0.7, 1e-15);
  EXPECT_NEAR(t[W], 0.3, 1e-15);
  EXPECT_TRUE(massNear(priorMass(PriorClass::kUnknown, beta), MassMG::vacuous(), 0.0));
}

// The paper's story on one cell: free for several scans, then occupied → mass on {V}; then occupied
// and consistent for many scans → ζ grows and the V mass leaves for S.
TEST(FusionStory, FreeThenOccupiedIsMovingThenStopped)
{
  FusionParams params;
  const MassSG free_scan{ { FrameSG::kF, 0.7 }, { FrameSG::kOmega, 0.3 } };
  const MassSG occupied_scan{ { FrameSG::kO, 0.8 }, { FrameSG::kOmega, 0.2 } };
  const MassMG road = priorMass(PriorClass::kRoad, PriorConfidence{});
  MassMG m;
  double zeta = 0.0;
  for (int t = 0; t < 10; ++t)
  {
    const auto r = fuseCell(m, zeta, free_scan, road, params);
    m = r.mass;
    zeta = r.zeta;
    ASSERT_TRUE(isValidMass(m, 1e-9));
  }
  EXPECT_GT(pignistic(m)[0], 0.8);
  EXPECT_EQ(zeta, 0.0);

  auto first = fuseCell(m, zeta, occupied_scan, road, params);
  EXPECT_GT(first.conflicts.free_occupied, params.counter.gamma_conflict);
  int argmax = 1;
  for (int a = 2; a < 32; ++a)
    if (first.mass[a] > first.mass[argmax]) argmax = a;
  EXPECT_EQ(argmax, V) << "largest focal set is " << subsetName<FrameMG>(static_cast<Subset>(argmax));
  const auto bet_first = pignistic(first.mass);
  EXPECT_GT(bet_first[4], bet_first[3]);  // moving above stopped

  m = first.mass;
  zeta = first.zeta;
  double previous_zeta = zeta;
  bool zeta_grew = false;
  for (int t = 0; t < 60; ++t)
  {
    const auto r = fuseCell(m, zeta, occupied_scan, road, params);
    m = r.mass;
    zeta = r.zeta;
    zeta_grew = zeta_grew || zeta > previous_zeta;
    EXPECT_GE(zeta, previous_zeta - 1e-12) << "ζ fell while the cell stayed occupied, at scan " << t;
    previous_zeta = zeta;
    ASSERT_TRUE(isValidMass(m, 1e-9));
  }
  EXPECT_TRUE(zeta_grew);
  EXPECT_DOUBLE_EQ(zeta, 1.0);
  const auto bet = pignistic(m);
  EXPECT_GT(bet[3], 0.5) << "stopped";
  EXPECT_LT(bet[4], 0.1) << "moving";
}

#include <gtest/gtest.h>

#include "map_aided_fusion/core/rules.hpp"
#include "test_util.hpp"

using namespace map_aided_fusion::core;
using maf_test::isValidMass;
using maf_test::massNear;
using maf_test::randomMass;

constexpr Subset F = FrameMG::kF, C = FrameMG::kC, N = FrameMG::kN, S = FrameMG::kS, V = FrameMG::kV;
constexpr Subset O = FrameMG::kO, W = FrameMG::kOmega;

TEST(Conjunctive, HandComputed)
{
  const MassMG m1{ { F, 0.6 }, { W, 0.4 } };
  const MassMG m2{ { O, 0.7 }, { W, 0.3 } };
  const auto r = conjunctive(m1, m2);
  EXPECT_NEAR(r[0], 0.42, 1e-12);
  EXPECT_NEAR(r[F], 0.18, 1e-12);
  EXPECT_NEAR(r[O], 0.28, 1e-12);
  EXPECT_NEAR(r[W], 0.12, 1e-12);
  EXPECT_TRUE(isValidMass(r));
}

TEST(Conjunctive, CommonalityProductEqualsDoubleSumOn10000RandomPairs)
{
  std::mt19937 rng(42);
  for (int trial = 0; trial < 10000; ++trial)
  {
    const auto m1 = randomMass<FrameMG>(rng, 8, trial % 5 == 0);
    const auto m2 = randomMass<FrameMG>(rng, 8);
    const auto q1 = commonality(m1);
    const auto q2 = commonality(m2);
    MassMG::Values q{};
    for (int a = 0; a < FrameMG::kNumSubsets; ++a) q[a] = q1[a] * q2[a];
    ASSERT_TRUE(massNear(fromCommonality<FrameMG>(q), conjunctive(m1, m2), 1e-12)) << "trial " << trial;
  }
}

TEST(Disjunctive, ImplicabilityProductEqualsDoubleSum)
{
  std::mt19937 rng(43);
  for (int trial = 0; trial < 2000; ++trial)
  {
    const auto m1 = randomMass<FrameMG>(rng, 8, true);
    const auto m2 = randomMass<FrameMG>(rng, 8, true);
    const auto b1 = implicability(m1);
    const auto b2 = implicability(m2);
    MassMG::Values b{};
    for (int a = 0; a < FrameMG::kNumSubsets; ++a) b[a] = b1[a] * b2[a];
    ASSERT_TRUE(massNear(fromImplicability<FrameMG>(b), disjunctive(m1, m2), 1e-12));
  }
}

TEST(Rules, CommutativeAndAssociative)
{
  std::mt19937 rng(44);
  for (int trial = 0; trial < 1000; ++trial)
  {
    const auto a = randomMass<FrameMG>(rng);
    const auto b = randomMass<FrameMG>(rng);
    const auto c = randomMass<FrameMG>(rng);
    EXPECT_TRUE(massNear(conjunctive(a, b), conjunctive(b, a), 1e-12));
    EXPECT_TRUE(massNear(disjunctive(a, b), disjunctive(b, a), 1e-12));
    EXPECT_TRUE(massNear(conjunctive(conjunctive(a, b), c), conjunctive(a, conjunctive(b, c)), 1e-12));
    EXPECT_TRUE(massNear(disjunctive(disjunctive(a, b), c), disjunctive(a, disjunctive(b, c)), 1e-12));
  }
}

TEST(Rules, NeutralElements)
{
  std::mt19937 rng(45);
  const MassMG vacuous;
  const MassMG empty_certain{ { 0, 1.0 } };
  for (int trial = 0; trial < 200; ++trial)
  {
    const auto m = randomMass<FrameMG>(rng);
    EXPECT_TRUE(massNear(conjunctive(m, vacuous), m, 1e-15));
    EXPECT_TRUE(massNear(dempster(m, vacuous), m, 1e-15));
    EXPECT_TRUE(massNear(yager(m, vacuous), m, 1e-15));
    EXPECT_TRUE(massNear(modifiedYager(m, vacuous), m, 1e-15));
    EXPECT_TRUE(massNear(disjunctive(m, empty_certain), m, 1e-15));
  }
}

TEST(Dempster, IsNormalisedConjunctive)
{
  std::mt19937 rng(46);
  for (int trial = 0; trial < 2000; ++trial)
  {
    const auto a = randomMass<FrameMG>(rng);
    const auto b = randomMass<FrameMG>(rng);
    const auto conj = conjunctive(a, b);
    DempsterReport report;
    const auto d = dempster(a, b, &report);
    EXPECT_NEAR(report.conflict, conj[0], 1e-15);
    if (report.total_conflict)
    {
      EXPECT_TRUE(massNear(d, MassMG::vacuous(), 0.0));
      continue;
    }
    EXPECT_EQ(d[0], 0.0);
    for (int s = 1; s < FrameMG::kNumSubsets; ++s) ASSERT_NEAR(d[s], conj[s] / (1.0 - conj[0]), 1e-12);
    EXPECT_TRUE(isValidMass(d));
  }
}

TEST(Dempster, TotalConflictIsVacuousNotADivisionByZero)
{
  const MassMG building{ { C, 1.0 } };
  const MassMG free_space{ { F, 1.0 } };
  DempsterReport report;
  const auto r = dempster(building, free_space, &report);
  EXPECT_TRUE(report.total_conflict);
  EXPECT_DOUBLE_EQ(report.conflict, 1.0);
  EXPECT_TRUE(massNear(r, MassMG::vacuous(), 0.0));
}

TEST(Dempster, HandComputedWithConflict)
{
  // r(m_SG) = {F: 0.7, Ω: 0.3} with a building prior {C: 0.9, Ω: 0.1}: K = 0.63.
  const MassMG scan{ { F, 0.7 }, { W, 0.3 } };
  const MassMG prior{ { C, 0.9 }, { W, 0.1 } };
  DempsterReport report;
  const auto r = dempster(scan, prior, &report);
  EXPECT_NEAR(report.conflict, 0.63, 1e-12);
  EXPECT_NEAR(r[F], 0.07 / 0.37, 1e-12);
  EXPECT_NEAR(r[C], 0.27 / 0.37, 1e-12);
  EXPECT_NEAR(r[W], 0.03 / 0.37, 1e-12);
}

TEST(Yager, ConflictGoesToOmega)
{
  const MassMG m1{ { F, 0.6 }, { W, 0.4 } };
  const MassMG m2{ { O, 0.7 }, { W, 0.3 } };
  const auto r = yager(m1, m2);
  EXPECT_EQ(r[0], 0.0);
  EXPECT_NEAR(r[W], 0.12 + 0.42, 1e-12);
  EXPECT_NEAR(r[F], 0.18, 1e-12);
  EXPECT_NEAR(r[O], 0.28, 1e-12);
}

TEST(ModifiedYager, FreeThenOccupiedGoesToMoving)
{
  const MassMG map{ { F, 0.6 }, { W, 0.4 } };
  const MassMG scan{ { O, 0.7 }, { W, 0.3 } };
  ConflictMasses c;
  const auto r = modifiedYager(map, scan, &c);
  EXPECT_NEAR(c.free_occupied, 0.42, 1e-12);
  EXPECT_NEAR(c.occupied_free, 0.0, 1e-12);
  EXPECT_NEAR(c.other, 0.0, 1e-12);
  EXPECT_NEAR(r[V], 0.42, 1e-12);
  EXPECT_NEAR(r[F], 0.18, 1e-12);
  EXPECT_NEAR(r[O], 0.28, 1e-12);
  EXPECT_NEAR(r[W], 0.12, 1e-12);
  EXPECT_EQ(r[0], 0.0);
}

TEST(ModifiedYager, BuildingConflictSendsFreeThenBuildingToOmega)
{
  // Seen free, now occupied evidence of which 0.5 can only be the mapped building ({C}) and 0.3 is on the road
  // ({S, V}): ∅_FO = 0.6 · 0.8 = 0.48 either way.
  const MassMG map{ { F, 0.6 }, { W, 0.4 } };
  const MassMG scan_prior{ { C, 0.5 }, { S | V, 0.3 }, { W, 0.2 } };
  ConflictMasses paper, step;
  const auto p = modifiedYager(map, scan_prior, &paper);
  const auto r = modifiedYager(map, scan_prior, &step, true);
  EXPECT_NEAR(paper.free_occupied, 0.48, 1e-12);
  EXPECT_NEAR(step.free_occupied, 0.48, 1e-12) << "the conflicts reported are the paper's";
  EXPECT_NEAR(step.occupied_free, paper.occupied_free, 1e-15);
  EXPECT_NEAR(step.other, paper.other, 1e-15);
  EXPECT_NEAR(p[V], 0.48, 1e-12);
  // The step: only the road's part, 0.6 · 0.3, is V; the building's, 0.6 · 0.5, goes to Ω.
  EXPECT_NEAR(r[V], 0.18, 1e-12);
  EXPECT_NEAR(r[W], p[W] + 0.30, 1e-12);
  for (int a = 1; a < FrameMG::kNumSubsets; ++a)
  {
    if (a != V && a != W)
    {
      EXPECT_NEAR(r[a], p[a], 1e-15) << "set " << a;
    }
  }
  EXPECT_TRUE(isValidMass(r));
  // Without {C} in the evidence the step changes nothing.
  const MassMG road{ { S | V, 0.7 }, { W, 0.3 } };
  EXPECT_TRUE(massNear(modifiedYager(map, road, nullptr, true), modifiedYager(map, road), 1e-15));
}

TEST(ModifiedYager, OccupiedThenFreeGoesToOmega)
{
  const MassMG map{ { S | V, 0.5 }, { W, 0.5 } };
  const MassMG scan{ { F, 0.8 }, { W, 0.2 } };
  ConflictMasses c;
  const auto r = modifiedYager(map, scan, &c);
  EXPECT_NEAR(c.occupied_free, 0.4, 1e-12);
  EXPECT_NEAR(c.free_occupied, 0.0, 1e-12);
  EXPECT_NEAR(r[S | V], 0.1, 1e-12);
  EXPECT_NEAR(r[F], 0.4, 1e-12);
  EXPECT_NEAR(r[W], 0.1 + 0.4, 1e-12);
  EXPECT_NEAR(r[V], 0.0, 1e-12);
}

TEST(ModifiedYager, OtherConflictGoesToOmegaAsInYager)
{
  // A building cell meeting a stopped object: conflict, but neither F→O nor O→F.
  const MassMG map{ { C, 0.8 }, { W, 0.2 } };
  const MassMG scan{ { S | V, 0.5 }, { W, 0.5 } };
  ConflictMasses c;
  const auto r = modifiedYager(map, scan, &c);
  EXPECT_NEAR(c.other, 0.4, 1e-12);
  EXPECT_NEAR(c.total(), 0.4, 1e-12);
  EXPECT_NEAR(r[W], 0.1 + 0.4, 1e-12);
  EXPECT_NEAR(r[C], 0.4, 1e-12);
  EXPECT_NEAR(r[S | V], 0.1, 1e-12);
}

TEST(ModifiedYager, ConflictsFollowThePapersDefinitionOnRandomInputs)
{
  std::mt19937 rng(47);
  for (int trial = 0; trial < 3000; ++trial)
  {
    const auto a = randomMass<FrameMG>(rng);
    const auto b = randomMass<FrameMG>(rng);
    ConflictMasses c;
    const auto r = modifiedYager(a, b, &c);
    double a_o = 0, b_o = 0;
    for (int s = 1; s < 32; ++s)
      if (isSubsetOf(static_cast<Subset>(s), O))
      {
        a_o += a[s];
        b_o += b[s];
      }
    EXPECT_NEAR(c.free_occupied, a[F] * b_o, 1e-12);
    EXPECT_NEAR(c.occupied_free, a_o * b[F], 1e-12);
    EXPECT_GE(c.other, -1e-12);
    EXPECT_NEAR(c.total(), conjunctive(a, b)[0], 1e-12);
    const auto conj = conjunctive(a, b);
    EXPECT_NEAR(r[V], conj[V] + c.free_occupied, 1e-12);
    EXPECT_NEAR(r[W], conj[W] + c.occupied_free + c.other, 1e-12);
    EXPECT_TRUE(isValidMass(r, 1e-12));
  }
}

TEST(Refining, MapsScanFrameIntoMapFrame)
{
  EXPECT_EQ(refineSubset(FrameSG::kF), F);
  EXPECT_EQ(refineSubset(FrameSG::kO), C | N | S | V);
  EXPECT_EQ(refineSubset(FrameSG::kOmega), W);
  EXPECT_EQ(refineSubset(0), 0);
  const MassSG m{ { FrameSG::kF, 0.2 }, { FrameSG::kO, 0.5 }, { FrameSG::kOmega, 0.3 } };
  const auto r = refine(m);
  EXPECT_NEAR(r[F], 0.2, 1e-15);
  EXPECT_NEAR(r[O], 0.5, 1e-15);
  EXPECT_NEAR(r[W], 0.3, 1e-15);
  EXPECT_TRUE(isValidMass(r));
}

TEST(Rules, KeepMassesNonNegativeAndSummingToOne)
{
  std::mt19937 rng(48);
  for (int trial = 0; trial < 2000; ++trial)
  {
    const auto a = randomMass<FrameMG>(rng);
    const auto b = randomMass<FrameMG>(rng);
    EXPECT_TRUE(isValidMass(conjunctive(a, b)));
    EXPECT_TRUE(isValidMass(disjunctive(a, b)));
    EXPECT_TRUE(isValidMass(dempster(a, b)));
    EXPECT_TRUE(isValidMass(yager(a, b)));
    EXPECT_TRUE(isValidMass(modifiedYager(a, b)));
  }
}

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "map_aided_fusion/core/frame.hpp"
#include "map_aided_fusion/core/mass_function.hpp"
#include "test_util.hpp"

using namespace map_aided_fusion::core;
using maf_test::massNear;
using maf_test::randomMass;

TEST(Frame, NamesOfSubsets)
{
  EXPECT_EQ(subsetName<FrameMG>(FrameMG::kF), "F");
  EXPECT_EQ(subsetName<FrameMG>(FrameMG::kS | FrameMG::kV), "SV");
  EXPECT_EQ(subsetName<FrameMG>(FrameMG::kRoad), "FSV");
  EXPECT_EQ(subsetName<FrameMG>(FrameMG::kOther), "FNSV");
  EXPECT_EQ(subsetName<FrameMG>(FrameMG::kO), "CNSV");
  EXPECT_EQ(subsetName<FrameMG>(FrameMG::kOmega), "Ω");
  EXPECT_EQ(subsetName<FrameMG>(0), "∅");
  EXPECT_EQ(subsetName<FrameSG>(FrameSG::kO), "O");
  EXPECT_EQ(subsetName<FrameSG>(FrameSG::kOmega), "Ω");
}

TEST(Frame, ParseRoundTripsEverySubset)
{
  for (int a = 0; a < FrameMG::kNumSubsets; ++a)
    EXPECT_EQ(parseSubset<FrameMG>(subsetName<FrameMG>(static_cast<Subset>(a))), a);
  EXPECT_EQ(parseSubset<FrameMG>("Omega"), FrameMG::kOmega);
  EXPECT_EQ(parseSubset<FrameMG>("VS"), FrameMG::kS | FrameMG::kV);
  EXPECT_THROW(parseSubset<FrameMG>("FX"), std::invalid_argument);
}

TEST(Frame, Constants)
{
  EXPECT_EQ(FrameMG::kNumSubsets, 32);
  EXPECT_EQ(FrameMG::kO, 0b11110);
  EXPECT_EQ(FrameMG::kStatic | FrameMG::kDynamic | FrameMG::kFreeContext, FrameMG::kOmega);
  EXPECT_EQ(FrameMG::kStatic & FrameMG::kDynamic, 0);
  EXPECT_EQ(cardinality(FrameMG::kOther), 4);
  EXPECT_TRUE(isSubsetOf(FrameMG::kRoad, FrameMG::kOther));
  EXPECT_FALSE(isSubsetOf(FrameMG::kOther, FrameMG::kRoad));
}

TEST(MassFunction, DefaultIsVacuous)
{
  MassMG m;
  EXPECT_EQ(m[FrameMG::kOmega], 1.0);
  EXPECT_EQ(m.sum(), 1.0);
  EXPECT_NO_THROW(m.validate());
}

TEST(MassFunction, RejectsNegativeNaNAndBadSumSayingWhich)
{
  MassMG neg{ { FrameMG::kF, -0.2 }, { FrameMG::kOmega, 1.2 } };
  try
  {
    neg.validate();
    FAIL() << "negative mass accepted";
  }
  catch (const InvalidMassFunction& e)
  {
    EXPECT_NE(std::string(e.what()).find("m(F)"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("negative"), std::string::npos) << e.what();
  }
  MassMG nan{ { FrameMG::kS, std::numeric_limits<double>::quiet_NaN() }, { FrameMG::kOmega, 1.0 } };
  try
  {
    nan.validate();
    FAIL() << "NaN accepted";
  }
  catch (const InvalidMassFunction& e)
  {
    EXPECT_NE(std::string(e.what()).find("m(S)"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("not finite"), std::string::npos) << e.what();
  }
  MassSG sum{ { FrameSG::kF, 0.5 }, { FrameSG::kO, 0.4 } };
  try
  {
    sum.validate();
    FAIL() << "sum 0.9 accepted";
  }
  catch (const InvalidMassFunction& e)
  {
    EXPECT_NE(std::string(e.what()).find("sum"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(sum.isValid());
  EXPECT_TRUE(sum.isValid(0.2));
}

TEST(Transforms, HandComputedOnOmegaSG)
{
  // m(F) = 0.2, m(O) = 0.5, m(Ω) = 0.3
  MassSG m{ { FrameSG::kF, 0.2 }, { FrameSG::kO, 0.5 }, { FrameSG::kOmega, 0.3 } };
  const auto q = commonality(m);
  EXPECT_NEAR(q[0], 1.0, 1e-12);
  EXPECT_NEAR(q[FrameSG::kF], 0.5, 1e-12);
  EXPECT_NEAR(q[FrameSG::kO], 0.8, 1e-12);
  EXPECT_NEAR(q[FrameSG::kOmega], 0.3, 1e-12);
  const auto bel = belief(m);
  EXPECT_NEAR(bel[0], 0.0, 1e-12);
  EXPECT_NEAR(bel[FrameSG::kF], 0.2, 1e-12);
  EXPECT_NEAR(bel[FrameSG::kO], 0.5, 1e-12);
  EXPECT_NEAR(bel[FrameSG::kOmega], 1.0, 1e-12);
  const auto pl = plausibility(m);
  EXPECT_NEAR(pl[0], 0.0, 1e-12);
  EXPECT_NEAR(pl[FrameSG::kF], 0.5, 1e-12);
  EXPECT_NEAR(pl[FrameSG::kO], 0.8, 1e-12);
  EXPECT_NEAR(pl[FrameSG::kOmega], 1.0, 1e-12);
}

TEST(Transforms, MatchDefinitionsAndRoundTrip)
{
  std::mt19937 rng(7);
  for (int trial = 0; trial < 500; ++trial)
  {
    const auto m = randomMass<FrameMG>(rng, 8, trial % 3 == 0);
    const auto q = commonality(m);
    const auto b = implicability(m);
    const auto bel = belief(m);
    const auto pl = plausibility(m);
    for (int a = 0; a < FrameMG::kNumSubsets; ++a)
    {
      double q_def = 0, b_def = 0, bel_def = 0, pl_def = 0;
      for (int c = 0; c < FrameMG::kNumSubsets; ++c)
      {
        if (isSubsetOf(static_cast<Subset>(a), static_cast<Subset>(c))) q_def += m[c];
        if (isSubsetOf(static_cast<Subset>(c), static_cast<Subset>(a))) b_def += m[c];
        if (c != 0 && isSubsetOf(static_cast<Subset>(c), static_cast<Subset>(a))) bel_def += m[c];
        if ((c & a) != 0) pl_def += m[c];
      }
      ASSERT_NEAR(q[a], q_def, 1e-12);
      ASSERT_NEAR(b[a], b_def, 1e-12);
      ASSERT_NEAR(bel[a], bel_def, 1e-12);
      ASSERT_NEAR(pl[a], pl_def, 1e-12);
    }
    EXPECT_TRUE(massNear(fromCommonality<FrameMG>(q), m, 1e-12));
    EXPECT_TRUE(massNear(fromImplicability<FrameMG>(b), m, 1e-12));
    EXPECT_TRUE(massNear(fromBelief<FrameMG>(bel, m[0]), m, 1e-12));
    EXPECT_TRUE(massNear(fromPlausibility<FrameMG>(pl), m, 1e-12));
  }
}

TEST(MassFunction, MassInsideIsThePapersMO)
{
  MassMG m{ { FrameMG::kF, 0.1 }, { FrameMG::kC, 0.2 }, { FrameMG::kS | FrameMG::kV, 0.3 }, { FrameMG::kRoad, 0.15 },
            { FrameMG::kOmega, 0.25 } };
  EXPECT_NEAR(m.massInside(FrameMG::kO), 0.5, 1e-12);  // C and SV; FSV and Ω contain F
}

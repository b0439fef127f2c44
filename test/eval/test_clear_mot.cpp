#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "map_aided_fusion/eval/clear_mot.hpp"

using namespace map_aided_fusion;
using namespace map_aided_fusion::eval;

namespace {

MotObject obj(std::uint32_t id, double x, double y, bool judged = true)
{
  MotObject o;
  o.id = id;
  o.position = core::Point2{ x, y };
  o.judged = judged;
  return o;
}

MotHypothesis hyp(std::uint32_t id, double x, double y)
{
  MotHypothesis h;
  h.id = id;
  h.position = core::Point2{ x, y };
  return h;
}

}  // namespace

// Two objects, four frames, T = 2 m. By the CLEAR-MOT definitions:
//  f1: o1-h1 (0.5), o2-h2 (1.0);  f2: o1-h1 (0.5), o2 missed, h3 a false positive;
//  f3: the hypotheses swap: o1-h2 (1.0), o2-h1 (0.5): two identity switches (o2's last pair was h2, in f1);
//  f4: o2 gone, o1-h2 (0): kept, no switch.
// GT 7, matches 6, misses 1, FP 1, IDSW 2: MOTA = 1 - 4/7 = 3/7; MOTP = 3.5 / 6 m; o2 is interrupted in f2 and resumed
// in f3: one fragmentation.
TEST(ClearMot, ScriptedSequenceGivesTheHandCountedScores)
{
  ClearMot mot(2.0);
  mot.addFrame({ obj(1, 0, 0), obj(2, 10, 0) }, { hyp(1, 0.5, 0), hyp(2, 10, 1) });
  mot.addFrame({ obj(1, 1, 0), obj(2, 11, 0) }, { hyp(1, 1, 0.5), hyp(3, 30, 0) });
  mot.addFrame({ obj(1, 2, 0), obj(2, 12, 0) }, { hyp(1, 12.5, 0), hyp(2, 2, 1) });
  mot.addFrame({ obj(1, 3, 0) }, { hyp(2, 3, 0) });
  EXPECT_EQ(mot.frames(), 4u);
  EXPECT_EQ(mot.objects(), 7u);
  EXPECT_EQ(mot.matches(), 6u);
  EXPECT_EQ(mot.misses(), 1u);
  EXPECT_EQ(mot.falsePositives(), 1u);
  EXPECT_EQ(mot.idSwitches(), 2u);
  EXPECT_EQ(mot.fragmentations(), 1u);
  EXPECT_DOUBLE_EQ(mot.mota(), 3.0 / 7.0);
  EXPECT_DOUBLE_EQ(mot.motp(), 3.5 / 6.0);
  const auto r = mot.records();
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0].frames, 4u);
  EXPECT_DOUBLE_EQ(r[0].identity_share, 0.5);  // h1 twice, h2 twice
  EXPECT_EQ(r[0].id_switches, 1u);
  EXPECT_EQ(r[1].frames, 3u);
  EXPECT_EQ(r[1].tracked_frames, 2u);
  EXPECT_DOUBLE_EQ(r[1].identity_share, 1.0 / 3.0);
  EXPECT_EQ(r[1].fragmentations, 1u);
  const auto s = mot.summary();
  EXPECT_DOUBLE_EQ(s.at("mota"), 3.0 / 7.0);
  EXPECT_DOUBLE_EQ(s.at("id_switches"), 2.0);
}

TEST(ClearMot, AKeptCorrespondenceWinsOverACloserNewHypothesis)
{
  ClearMot mot(2.0);
  mot.addFrame({ obj(1, 0, 0) }, { hyp(7, 1, 0) });
  // h7 is still within 2 m: the pair is kept although h8 is closer; h8 is a false positive, no switch.
  mot.addFrame({ obj(1, 0, 0) }, { hyp(7, 1.5, 0), hyp(8, 0.1, 0) });
  EXPECT_EQ(mot.idSwitches(), 0u);
  EXPECT_EQ(mot.falsePositives(), 1u);
  EXPECT_DOUBLE_EQ(mot.motp(), 2.5 / 2.0);
  EXPECT_DOUBLE_EQ(mot.mota(), 1.0 - 1.0 / 2.0);
  // Beyond the match distance the pair breaks and the closer hypothesis takes over: a switch.
  mot.addFrame({ obj(1, 0, 0) }, { hyp(7, 2.5, 0), hyp(8, 0.1, 0) });
  EXPECT_EQ(mot.idSwitches(), 1u);
  EXPECT_EQ(mot.falsePositives(), 2u);
}

TEST(ClearMot, HypothesesOnObjectsNotJudgedAreLeftOut)
{
  ClearMot mot(2.0);
  // A parked car (not judged) with a track on it, a mover tracked, a track on nothing.
  mot.addFrame({ obj(1, 0, 0), obj(2, 20, 0, false) }, { hyp(1, 0.2, 0), hyp(2, 20.5, 0), hyp(3, 50, 0) });
  EXPECT_EQ(mot.objects(), 1u);
  EXPECT_EQ(mot.matches(), 1u);
  EXPECT_EQ(mot.falsePositives(), 1u);
  EXPECT_DOUBLE_EQ(mot.mota(), 0.0);
}

// A 12 m bus along +y, not judged (a mover not seen by the scoring, or parked). A track on its
// near end, 4 m from its centre, lies in its footprint and is left out; 1.9 m beside its side too; 2.1 m beyond its
// end, or 3 m from a point object, is a false positive. The footprint is rotated with the object's yaw.
TEST(ClearMot, HypothesesWithinTheMatchDistanceOfTheFootprintOfAnObjectNotJudgedAreLeftOut)
{
  MotObject bus = obj(1, 10, 5, false);
  bus.length = 12.0;
  bus.width = 2.5;
  bus.yaw = 0.5 * M_PI;  // along +y: its ends at y = -1 and y = 11, its sides at x = 8.75 and 11.25
  {
    ClearMot mot(2.0);
    mot.addFrame({ bus }, { hyp(1, 10, 9), hyp(2, 11.25 + 1.9, 5), hyp(3, 10, 11 + 2.1), hyp(4, 8.75 - 2.1, 5) });
    EXPECT_EQ(mot.falsePositives(), 2u);  // h3 and h4
    EXPECT_EQ(mot.objects(), 0u);
  }
  {
    // Without its footprint (0 x 0: a point), only a hypothesis within 2 m of its centre is left out.
    MotObject point = bus;
    point.length = point.width = 0.0;
    ClearMot mot(2.0);
    mot.addFrame({ point }, { hyp(1, 10, 9), hyp(2, 10, 6.9) });
    EXPECT_EQ(mot.falsePositives(), 1u);  // h1, 4 m away
  }
  {
    // A judged object is still paired by its centre: a track on the bus's end, 4 m from its centre, is a false
    // positive and the bus a miss.
    MotObject judged = bus;
    judged.judged = true;
    ClearMot mot(2.0);
    mot.addFrame({ judged }, { hyp(1, 10, 9) });
    EXPECT_EQ(mot.falsePositives(), 1u);
    EXPECT_EQ(mot.misses(), 1u);
  }
}

TEST(ClearMot, GlobalAssignmentPairsBothObjects)
{
  // Greedy nearest-first would pair o1 with h2 (0.5) and leave o2 (1.8 from h2 only... and 2.5 from h1) unpaired;
  // the assignment pairs o1-h1 (1.5) and o2-h2 (1.8).
  ClearMot mot(2.0);
  mot.addFrame({ obj(1, 0, 0), obj(2, 2.3, 0) }, { hyp(1, -1.5, 0), hyp(2, 0.5, 0) });
  EXPECT_EQ(mot.matches(), 2u);
  EXPECT_DOUBLE_EQ(mot.motp(), (1.5 + 1.8) / 2.0);
}

TEST(ClearMot, VelocityErrorsOverPairsWithBothVelocities)
{
  ClearMot mot(2.0);
  auto vo = [](std::uint32_t id, double x, double vx) {
    MotObject o = obj(id, x, 0);
    o.has_velocity = true;
    o.velocity = core::Point2{ vx, 0 };
    return o;
  };
  auto vh = [](std::uint32_t id, double x, double vx, double vy) {
    MotHypothesis h = hyp(id, x, 0);
    h.has_velocity = true;
    h.velocity = core::Point2{ vx, vy };
    return h;
  };
  mot.addFrame({ vo(1, 0, 5.0), vo(2, 10, 1.0) }, { vh(1, 0, 5.3, 0), vh(2, 10, 1.0, 0.4) });
  mot.addFrame({ vo(1, 0, 5.0), obj(3, 20, 0) }, { vh(1, 0, 3.8, 0), vh(3, 20, 0, 0) });
  EXPECT_EQ(mot.velocityPairs(), 3u);
  EXPECT_NEAR(mot.velocityRmse(), std::sqrt((0.09 + 0.16 + 1.44) / 3.0), 1e-12);
  EXPECT_NEAR(mot.velocityMedian(), 0.4, 1e-12);
  // Per object: o1 has errors 0.3 and 1.2, o2 0.4, o3 no velocity; shares of 0.09 + 0.16 + 1.44 = 1.69.
  const auto r = mot.records();
  ASSERT_EQ(r.size(), 3u);
  EXPECT_EQ(r[0].velocity_pairs, 2u);
  EXPECT_NEAR(r[0].velocity_rmse, std::sqrt((0.09 + 1.44) / 2.0), 1e-12);
  EXPECT_NEAR(r[0].velocity_median, 0.75, 1e-12);
  EXPECT_NEAR(r[0].velocity_error_share, 1.53 / 1.69, 1e-12);
  EXPECT_EQ(r[1].velocity_pairs, 1u);
  EXPECT_NEAR(r[1].velocity_rmse, 0.4, 1e-12);
  EXPECT_NEAR(r[1].velocity_error_share, 0.16 / 1.69, 1e-12);
  EXPECT_EQ(r[2].velocity_pairs, 0u);
  EXPECT_TRUE(std::isnan(r[2].velocity_rmse) && std::isnan(r[2].velocity_median));
  EXPECT_DOUBLE_EQ(r[2].velocity_error_share, 0.0);
  double shares = 0.0;
  for (const MotObjectRecord& x : r) shares += x.velocity_error_share;
  EXPECT_NEAR(shares, 1.0, 1e-12) << "the objects' shares make the whole squared error";
}

TEST(ClearMot, EmptyAndInvalid)
{
  EXPECT_THROW(ClearMot(0.0), std::invalid_argument);
  EXPECT_THROW(ClearMot(std::nan("")), std::invalid_argument);
  ClearMot mot;
  EXPECT_DOUBLE_EQ(mot.mota(), 1.0);
  EXPECT_TRUE(std::isnan(mot.motp()));
  mot.addFrame({}, { hyp(1, 0, 0) });
  EXPECT_DOUBLE_EQ(mot.mota(), 0.0);
}

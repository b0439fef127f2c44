// Input health (blind clouds, lost inputs) and the stamp guard's time-jump rule, ROS-free.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "map_aided_fusion/core/input_health.hpp"
#include "map_aided_fusion/core/parameters.hpp"
#include "map_aided_fusion/core/stamp_guard.hpp"

namespace map_aided_fusion {
namespace core {
namespace {

TEST(InputHealth, BlindReasonsByCount)
{
  InputHealthParams p;
  p.min_valid_returns = 50;
  EXPECT_EQ(judgeReturns(0, 0, p), BlindReason::kEmpty);
  EXPECT_EQ(judgeReturns(120000, 0, p), BlindReason::kNonFinite);
  EXPECT_EQ(judgeReturns(120000, 49, p), BlindReason::kTooFewValid);
  EXPECT_EQ(judgeReturns(120000, 50, p), BlindReason::kNone);
  p.min_valid_returns = 0;  // off
  EXPECT_EQ(judgeReturns(0, 0, p), BlindReason::kNone);
  EXPECT_STREQ(toString(BlindReason::kNonFinite), "blind_non_finite");
}

TEST(InputHealth, ParametersAreValidatedByName)
{
  InputHealthParams p;
  EXPECT_NO_THROW(p.validate());
  p.min_valid_returns = -1;
  try
  {
    p.validate();
    FAIL() << "accepted min_valid_returns -1";
  }
  catch (const ParameterError& e)
  {
    EXPECT_NE(std::string(e.what()).find("min_valid_returns"), std::string::npos) << e.what();
  }
  p = InputHealthParams{};
  p.input_period = std::nan("");
  EXPECT_THROW(p.validate(), ParameterError);
  p.input_period = 11.0;
  EXPECT_THROW(p.validate(), ParameterError);
}

TEST(InputHealth, BlindSpellLastsFromTheFirstBlindCloudToTheNextSightedOne)
{
  BlindSpell s;
  EXPECT_FALSE(s.active());
  EXPECT_EQ(s.duration(10.0), 0.0);
  s.blind(10.0);
  s.blind(10.1);
  s.blind(10.2);
  EXPECT_TRUE(s.active());
  EXPECT_EQ(s.clouds(), 3u);
  EXPECT_DOUBLE_EQ(s.duration(14.0), 4.0);
  s.sighted();
  EXPECT_FALSE(s.active());
  EXPECT_EQ(s.clouds(), 0u);
}

TEST(InputHealth, LostInputsCountedFromStampGapsWithALearntPeriod)
{
  InputGapCounter c;
  double t = 100.0;
  EXPECT_EQ(c.observe(t), 0u);
  for (int k = 0; k < 5; ++k) EXPECT_EQ(c.observe(t += 0.1), 0u);  // learns 0.1 s
  EXPECT_NEAR(c.period(), 0.1, 1e-9);
  EXPECT_EQ(c.observe(t += 0.3), 2u);   // two missing
  EXPECT_EQ(c.observe(t += 0.12), 0u);  // jitter below 1.5 periods
  EXPECT_EQ(c.observe(t += 0.16), 1u);  // 1.6 periods: one missing
  EXPECT_EQ(c.lost(), 3u);
  // Stamps that do not advance restart without judging; an outage of minutes is not counted as losses.
  EXPECT_EQ(c.observe(t - 5.0), 0u);
  EXPECT_EQ(c.observe(t - 5.0 + 600.0), 0u);
  EXPECT_EQ(c.observe(std::numeric_limits<double>::quiet_NaN()), 0u);
  EXPECT_EQ(c.lost(), 3u);
  EXPECT_NEAR(c.period(), 0.1, 1e-9) << "the outage must not become the period";
}

TEST(InputHealth, AStampOutOfOrderMidStreamMissesNothing)
{
  // 10 Hz; one cloud stamped 0.5 s back between two on time (a second source, a late cloud): no gap is invented
  // after it, and the stream goes on from the newest stamp.
  InputGapCounter c(0.1);
  double t = 10.0;
  EXPECT_EQ(c.observe(t), 0u);
  EXPECT_EQ(c.observe(t += 0.1), 0u);
  EXPECT_EQ(c.observe(t - 0.5), 0u);
  EXPECT_EQ(c.observe(t += 0.1), 0u);
  EXPECT_EQ(c.observe(t), 0u);  // a duplicate
  EXPECT_EQ(c.observe(t += 0.1), 0u);
  EXPECT_EQ(c.lost(), 0u);
  // A real gap after it still counts; a loop far back (more than 100 periods) restarts from its stamp.
  EXPECT_EQ(c.observe(t += 0.3), 2u);
  EXPECT_EQ(c.observe(t - 60.0), 0u);
  EXPECT_EQ(c.observe(t - 60.0 + 0.1), 0u);
  EXPECT_EQ(c.lost(), 2u);
}

TEST(InputHealth, LostInputsWithAConfiguredPeriod)
{
  InputGapCounter c(0.05);  // 20 Hz
  EXPECT_EQ(c.observe(1.0), 0u);
  EXPECT_EQ(c.observe(1.2), 3u);  // the first gap is judged too
  EXPECT_EQ(c.lost(), 3u);
}

TEST(InputHealth, SummaryTellsBlindThenErrorAndOverload)
{
  StreamHealthParams p;  // stale_error 3 s
  HealthSummary ok{ HealthLevel::kOk, "50 clouds published in the last 5 s" };
  InputFindings f;
  EXPECT_EQ(inputHealth(ok, p, f).level, HealthLevel::kOk);
  EXPECT_EQ(inputHealth(ok, p, f).message, ok.message);
  f.blind = true;
  f.blind_for = 1.0;
  f.blind_clouds = 10;
  f.blind_reason = "blind_non_finite";
  HealthSummary h = inputHealth(ok, p, f);
  EXPECT_EQ(h.level, HealthLevel::kWarn);
  EXPECT_NE(h.message.find("lidar blind for 1.0 s"), std::string::npos) << h.message;
  EXPECT_NE(h.message.find("blind_non_finite"), std::string::npos) << h.message;
  f.blind_for = 3.5;
  EXPECT_EQ(inputHealth(ok, p, f).level, HealthLevel::kError);
  f = InputFindings{};
  f.lost = 7;
  h = inputHealth(ok, p, f);
  EXPECT_EQ(h.level, HealthLevel::kWarn);
  EXPECT_NE(h.message.find("7 inputs lost in the input queue"), std::string::npos) << h.message;
  // Never better than the stream's own level.
  HealthSummary stale{ HealthLevel::kError, "no clouds published for 4.0 s" };
  EXPECT_EQ(inputHealth(stale, p, f).level, HealthLevel::kError);
}

TEST(StampGuard, OlderByMoreThanTheThresholdIsLateUnderAWatchedClockAndAJumpWithout)
{
  TimeGuardParams p;  // threshold 1 s
  StampGuard g(p);
  EXPECT_EQ(g.check(100.0), StampVerdict::kFuse);
  g.accept(100.0);
  EXPECT_EQ(g.check(100.0), StampVerdict::kDuplicate);
  EXPECT_EQ(g.check(99.5), StampVerdict::kOutOfOrder);
  EXPECT_EQ(g.check(0.0), StampVerdict::kZeroStamp);
  EXPECT_EQ(g.check(std::nan("")), StampVerdict::kZeroStamp);
  // Released 3 s late after a tf gap under a watched clock (which resets the guard when it goes back): not a jump.
  EXPECT_EQ(g.check(97.0, true), StampVerdict::kLate);
  EXPECT_EQ(g.check(99.5, true), StampVerdict::kOutOfOrder);
  EXPECT_EQ(g.check(100.5, true), StampVerdict::kFuse);
  // Without a clock, the stamps alone decide (offline replays, a bag that loops).
  EXPECT_EQ(g.check(97.0), StampVerdict::kTimeJump);
  EXPECT_EQ(g.check(50.0, false), StampVerdict::kTimeJump);
  g.reset();  // what the clock watch does when the clock goes back
  EXPECT_EQ(g.check(50.0, true), StampVerdict::kFuse);
}

TEST(StampGuard, LateScansThatKeepComingAreTheSourcesTimeGoingBack)
{
  StampGuard g;  // threshold 1 s
  g.accept(100.0);
  // A tf queue released newest first: a burst of late scans within milliseconds, then fused scans again.
  EXPECT_FALSE(g.lateRun(5000.000));
  EXPECT_FALSE(g.lateRun(5000.002));
  g.accept(100.1);
  EXPECT_FALSE(g.lateRun(5003.0)) << "a fused scan ends the run";
  // A bag looping on wall time: late for longer than the threshold, nothing fused.
  EXPECT_FALSE(g.lateRun(5003.5));
  EXPECT_TRUE(g.lateRun(5004.1));
  g.reset();
  EXPECT_FALSE(g.lateRun(5010.0));
  EXPECT_STREQ(toString(StampVerdict::kLate), "released late");
}

}  // namespace
}  // namespace core
}  // namespace map_aided_fusion

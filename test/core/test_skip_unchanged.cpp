// MapGridParams::skip_unchanged: a drive with the skip and the same drive without it give the same bytes after every
// scan (masses, ζ, BetP, map doubt, decisions, conflict sums), for the default and the paper profiles, with and
// without a prior, across recentring, a prior that arrives late, tracked motion written between scans and masses
// changed through mutableMasses(); and the skip does skip (most of the window once the unseen cells reach their fixed
// point), nothing with alpha_per_second or when it is off.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "map_aided_fusion/core/map_grid.hpp"
#include "map_aided_fusion/core/prior.hpp"
#include "map_aided_fusion/core/profiles.hpp"

using namespace map_aided_fusion::core;

namespace {

constexpr int kScans = 60;
constexpr double kWindow = 48.0;       // m
constexpr double kResolution = 0.25;   // m: 192 × 192 cells, several chunks of the step
constexpr double kSeenRadius = 9.0;    // m around the vehicle the scan observes

/// Everything a MapGrid holds after a scan, as raw bytes.
struct Snapshot
{
  std::vector<float> planes, betp, doubt;
  std::vector<std::int8_t> decision;
  std::vector<double> conflicts;
  bool operator==(const Snapshot& o) const
  {
    auto same = [](const auto& a, const auto& b) {
      return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(a[0])) == 0;
    };
    return same(planes, o.planes) && same(betp, o.betp) && same(doubt, o.doubt) && same(decision, o.decision) &&
           same(conflicts, o.conflicts);
  }
};

Snapshot snapshot(const MapGrid& grid, const FusionStepStats& s)
{
  Snapshot r;
  const MapMassGrid& m = grid.masses();
  r.planes.assign(m.planes(), m.planes() + m.bytes() / sizeof(float));
  for (int e = 0; e < FrameMG::kSize; ++e)
    r.betp.insert(r.betp.end(), grid.pignistic()[e].begin(), grid.pignistic()[e].end());
  r.doubt.assign(grid.mapDoubt().begin(), grid.mapDoubt().end());
  r.decision = grid.decisions();
  r.conflicts = { s.sum_conflict_free_occupied, s.sum_conflict_occupied_free, s.sum_conflict_other };
  return r;
}

/// A 200 m prior whose cells are road, other, building or wall (0.8) at random.
PriorWindow randomPrior(unsigned seed)
{
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> kind(0, 99);
  PriorWindow prior(GridGeometry::centred(200.0, 200.0, kResolution));
  for (std::size_t i = 0; i < prior.building.size(); ++i)
  {
    const int k = kind(rng);
    (k < 40 ? prior.road : k < 70 ? prior.other : k < 90 ? prior.building : prior.wall)[i] = 0.8f;
  }
  return prior;
}

enum class PriorKind
{
  kNone,
  kAlways,
  kFromScan20
};

struct Drive
{
  std::vector<Snapshot> after;      ///< after each scan
  std::vector<double> skipped;      ///< MapGrid::skippedShare() after each scan
  std::vector<bool> recentred;      ///< whether the window moved in each scan
  std::vector<bool> moved_ahead;    ///< whether MapGrid::follow() moved it before the scan's update (ahead)
};

/// A drive whose scans see a disc around the vehicle (free, with a few occupied cells that move), the vehicle
/// driving, stopping, then driving again (so that the window recentres), tracked motion written on unseen cells and
/// one write through mutableMasses(). With @p ahead, the window is moved by MapGrid::follow() before each update, as
/// the fusion node's shift_ahead does. The vehicle moves by @p velocity (m per scan) while it drives.
Drive drive(MapGridParams params, bool skip, PriorKind prior_kind, bool ahead = false, Point2 velocity = { 0.6, 0.0 })
{
  params.size_x = params.size_y = kWindow;
  params.resolution = kResolution;
  params.recentre_distance = 3.0;
  params.skip_unchanged = skip;
  MapGrid grid(params);
  const PriorWindow prior = randomPrior(7);
  const GridGeometry sg = GridGeometry::centred(kWindow, kWindow, kResolution);
  Drive d;
  Pose2 pose;
  for (int step = 0; step < kScans; ++step)
  {
    const bool moving = step < 15 || step >= 45;
    if (moving)
    {
      pose.x += velocity.x;
      pose.y += velocity.y;
    }
    ScanMassGrid scan(sg);
    for (std::size_t i = 0; i < scan.numCells(); ++i)
    {
      const Point2 c = sg.cellCentre(sg.cellOf(i));
      if (c.x * c.x + c.y * c.y > kSeenRadius * kSeenRadius) continue;
      const bool object = std::abs(c.y - 3.0) < 0.8 && std::abs(c.x - 4.0 + 0.3 * (step % 10)) < 1.5;
      scan.setCell(i, object ? MassSG{ { FrameSG::kO, 0.8 }, { FrameSG::kOmega, 0.2 } } :
                               MassSG{ { FrameSG::kF, 0.7 }, { FrameSG::kOmega, 0.3 } });
    }
    const bool with_prior = prior_kind == PriorKind::kAlways || (prior_kind == PriorKind::kFromScan20 && step >= 20);
    const double origin_x = grid.geometry().origin_x, origin_y = grid.geometry().origin_y;
    d.moved_ahead.push_back(ahead && grid.follow(Point2{ pose.x, pose.y }));
    const double before_update = grid.geometry().origin_x, before_update_y = grid.geometry().origin_y;
    const FusionStepStats s = grid.update(scan, pose, 0.1 * step, with_prior ? &prior : nullptr);
    d.recentred.push_back(step > 0 &&
                          (grid.geometry().origin_x != origin_x || grid.geometry().origin_y != origin_y));
    if (ahead && step > 0)  // the first update places the window
    {
      EXPECT_EQ(grid.geometry().origin_x, before_update) << "scan " << step << ": update() moved the window again";
      EXPECT_EQ(grid.geometry().origin_y, before_update_y) << "scan " << step << ": update() moved the window again";
    }
    if (step == 30)
    {
      // Tracked motion on cells far from the vehicle (stable by now), then a write through mutableMasses().
      std::vector<CellMotion> cells;
      for (std::size_t i = 0; i < 200; ++i)
        cells.push_back(CellMotion{ i * 37 % grid.masses().numCells(), i % 3 ? CellClass::kMoving : CellClass::kStopped,
                                    0.5f });
      grid.applyTrackedMotion(cells);
    }
    if (step == 40) grid.mutableMasses().setCell(5, MassMG{ { FrameMG::kC, 0.5 }, { FrameMG::kOmega, 0.5 } });
    d.after.push_back(snapshot(grid, s));
    d.skipped.push_back(grid.skippedShare());
  }
  return d;
}

void expectSameDrives(const MapGridParams& params, PriorKind prior, const std::string& what)
{
  const Drive off = drive(params, false, prior), on = drive(params, true, prior);
  ASSERT_EQ(off.after.size(), on.after.size());
  for (std::size_t k = 0; k < on.after.size(); ++k)
  {
    EXPECT_TRUE(on.after[k] == off.after[k]) << what << ": scan " << k << " differs with skip_unchanged";
    EXPECT_EQ(off.skipped[k], 0.0) << what;
  }
  // Most of the window is unseen: once its cells reach their fixed point (some 25 scans after the prior comes), the
  // step skips them until the window moves.
  EXPECT_GT(*std::max_element(on.skipped.begin(), on.skipped.end()), 0.5) << what;
  EXPECT_EQ(on.skipped[0], 0.0) << what << ": nothing is known to be stable before the first step";
  // The flags move with the window: a scan that recentres still skips what stayed stable.
  int recentred = 0;
  for (std::size_t k = 1; k < on.skipped.size(); ++k)
    if (on.recentred[k] && on.skipped[k - 1] > 0.3)
    {
      ++recentred;
      EXPECT_GT(on.skipped[k], 0.5 * on.skipped[k - 1]) << what << ": scan " << k << " recentres";
    }
  EXPECT_GT(recentred, 0) << what << ": the drive recentres once the skip holds";
}

}  // namespace

TEST(SkipUnchanged, DefaultProfileGivesTheSameBytesAfterEveryScan)
{
  expectSameDrives(defaultProfile().map_grid, PriorKind::kAlways, "default, prior");
  expectSameDrives(defaultProfile().map_grid, PriorKind::kNone, "default, no prior");
  expectSameDrives(defaultProfile().map_grid, PriorKind::kFromScan20, "default, prior from scan 20");
}

TEST(SkipUnchanged, PaperProfileGivesTheSameBytesAfterEveryScan)
{
  expectSameDrives(paperProfile().map_grid, PriorKind::kAlways, "paper, prior");
  expectSameDrives(paperProfile().map_grid, PriorKind::kNone, "paper, no prior");
}

TEST(SkipUnchanged, TheWindowMovingEveryWayGivesTheSameBytesAfterEveryScan)
{
  // Left, up, down and diagonally (a row that reads itself from the right or the left, rows read from above or below),
  // with most of the window skipped when it moves.
  for (const Point2 step : { Point2{ -0.6, 0.0 }, Point2{ 0.0, 0.6 }, Point2{ 0.0, -0.6 }, Point2{ -0.45, 0.45 } })
  {
    const std::string what = "step (" + std::to_string(step.x) + ", " + std::to_string(step.y) + ")";
    const Drive off = drive(defaultProfile().map_grid, false, PriorKind::kAlways, false, step);
    const Drive on = drive(defaultProfile().map_grid, true, PriorKind::kAlways, false, step);
    int skipped_recentring = 0;
    for (std::size_t k = 0; k < on.after.size(); ++k)
    {
      EXPECT_TRUE(on.after[k] == off.after[k]) << what << ": scan " << k << " differs with skip_unchanged";
      skipped_recentring += on.recentred[k] && on.skipped[k] > 0.3;
    }
    EXPECT_GT(skipped_recentring, 0) << what << ": a recentring scan skips most of the window";
  }
}

TEST(SkipUnchanged, ShiftsAcrossAlternatingSkippedBlocksGiveTheSameBytes)
{
  // Blocks skipped and computed in turn along the rows (tracked motion written on one cell of every third block clears
  // its flag), then moves by whole blocks and by parts of blocks each way: what a skipped block keeps must come from
  // where its cells were, whatever the order in which the rows that read themselves are written (a row moved left by
  // two blocks reads, for a skipped block, cells that the skipped block one to its left is written over).
  MapGridParams params = defaultProfile().map_grid;
  params.size_x = params.size_y = kWindow;
  params.resolution = kResolution;
  params.recentre_distance = 0.5 * kWindow;  // the update leaves the window where the shift put it
  const PriorWindow prior = randomPrior(11);
  const ScanMassGrid vacuous(GridGeometry::centred(kWindow, kWindow, kResolution));
  for (const auto& [dx, dy] : { std::pair{ -16, 0 }, std::pair{ 16, 0 }, std::pair{ -20, 0 }, std::pair{ 20, 0 },
                                std::pair{ -5, 0 }, std::pair{ 5, 0 }, std::pair{ -16, 2 }, std::pair{ 9, -3 },
                                std::pair{ 0, 4 }, std::pair{ 0, -4 } })
  {
    Snapshot after[2];
    double skipped = 0.0;
    for (const bool skip : { false, true })
    {
      params.skip_unchanged = skip;
      MapGrid grid(params);
      for (int k = 0; k < 40; ++k) grid.update(vacuous, Pose2{}, 0.1 * k, &prior);
      const std::size_t w = static_cast<std::size_t>(grid.geometry().width);
      std::vector<CellMotion> cells;
      for (std::size_t y = 0; y < static_cast<std::size_t>(grid.geometry().height); ++y)
        for (std::size_t bx = y % 3; bx < w / MapMassGrid::kBlockCells; bx += 3)
          cells.push_back(CellMotion{ y * w + bx * MapMassGrid::kBlockCells + 3, CellClass::kMoving, 0.5f });
      grid.applyTrackedMotion(cells);
      grid.shift(dx, dy);
      after[skip] = snapshot(grid, grid.update(vacuous, Pose2{}, 4.0, &prior));
      skipped = grid.skippedShare();
    }
    EXPECT_TRUE(after[1] == after[0]) << "shift (" << dx << ", " << dy << ") differs with skip_unchanged";
    EXPECT_GT(skipped, 0.2) << "shift (" << dx << ", " << dy << "): the skipped blocks alternate";
  }
}

TEST(SkipUnchanged, AWindowMovedAheadGivesTheSameBytesAfterEveryScan)
{
  for (const auto& [params, what] : { std::pair{ defaultProfile().map_grid, "default" },
                                      std::pair{ paperProfile().map_grid, "paper" } })
    for (const bool skip : { true, false })
    {
      const Drive there = drive(params, skip, PriorKind::kAlways);
      const Drive ahead = drive(params, skip, PriorKind::kAlways, true);
      int moved = 0;
      for (std::size_t k = 0; k < there.after.size(); ++k)
      {
        EXPECT_TRUE(ahead.after[k] == there.after[k]) << what << ", skip " << skip << ": scan " << k << " differs";
        EXPECT_EQ(ahead.moved_ahead[k], there.recentred[k]) << what << ": scan " << k;
        EXPECT_EQ(ahead.skipped[k], there.skipped[k]) << what << ": scan " << k;
        moved += ahead.moved_ahead[k];
      }
      EXPECT_GE(moved, 3) << what << ": the drive recentres";
      EXPECT_FALSE(ahead.moved_ahead[0]) << what << ": nothing to follow before the first scan";
    }
}

TEST(SkipUnchanged, NothingIsSkippedWithRatesPerSecond)
{
  MapGridParams p = defaultProfile().map_grid;
  p.rates_per_second = true;
  const Drive on = drive(p, true, PriorKind::kAlways), off = drive(p, false, PriorKind::kAlways);
  for (std::size_t k = 0; k < on.after.size(); ++k)
  {
    EXPECT_EQ(on.skipped[k], 0.0);
    EXPECT_TRUE(on.after[k] == off.after[k]) << k;
  }
}

TEST(SkipUnchanged, TheSkippedShareCountsWholeBlocksOfUnseenCells)
{
  const Drive on = drive(defaultProfile().map_grid, true, PriorKind::kNone);
  const double seen = 3.14159 * kSeenRadius * kSeenRadius / (kWindow * kWindow);
  for (std::size_t k = 0; k < on.skipped.size(); ++k)
  {
    EXPECT_GE(on.skipped[k], 0.0);
    EXPECT_LE(on.skipped[k], 1.0 - seen + 0.01) << "a cell the scan sees is never skipped (scan " << k << ")";
  }
}

TEST(SkipUnchanged, CountsTheCellsOfTheBlocksTheScanObserves)
{
  // A scan that observes a disc, free: FusionStepStats::num_observed is every cell of each block holding a cell of
  // the disc, scan after scan; the rest is skipped or still changing.
  MapGridParams params = defaultProfile().map_grid;
  params.size_x = params.size_y = kWindow;
  params.resolution = kResolution;
  const GridGeometry sg = GridGeometry::centred(kWindow, kWindow, kResolution);
  ScanMassGrid scan(sg);
  std::size_t expected = 0;
  const std::size_t block = MapMassGrid::kBlockCells;
  for (std::size_t b = 0; b < scan.numCells() / block; ++b)
  {
    bool seen = false;
    for (std::size_t i = b * block; i < (b + 1) * block; ++i)
    {
      const Point2 c = sg.cellCentre(sg.cellOf(i));
      if (c.x * c.x + c.y * c.y > kSeenRadius * kSeenRadius) continue;
      scan.setCell(i, MassSG{ { FrameSG::kF, 0.7 }, { FrameSG::kOmega, 0.3 } });
      seen = true;
    }
    expected += seen ? block : 0;
  }
  ASSERT_GT(expected, 0u);
  const PriorWindow prior = randomPrior(3);
  for (const bool skip : { true, false })
  {
    params.skip_unchanged = skip;
    MapGrid grid(params);
    for (int k = 0; k < 30; ++k)
    {
      const FusionStepStats s = grid.update(scan, Pose2{}, 0.1 * k, &prior);
      ASSERT_TRUE(grid.geometry() == sg) << "the window is the scan's grid";
      EXPECT_EQ(s.num_observed, skip ? expected : 0u) << "skip " << skip << ", scan " << k;
      EXPECT_LE(s.num_observed + s.num_skipped, s.num_cells) << "scan " << k;
      if (skip)
      {
        EXPECT_DOUBLE_EQ(grid.changingShare(), 1.0 - grid.skippedShare() - grid.observedShare()) << "scan " << k;
      }
      else
      {
        EXPECT_TRUE(std::isnan(grid.changingShare())) << "no cells told apart without the skip";
      }
      if (skip && k == 29)
      {
        EXPECT_GT(s.num_skipped, 0u) << "the unseen cells reach their fixed point";
      }
    }
  }
}

// The scan projection planned once and filled run by run (ScanProjection), against projectScan() and the fused step
// on a projected ScanGrid.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "map_aided_fusion/core/map_grid.hpp"
#include "map_aided_fusion/core/scan_projection.hpp"

using namespace map_aided_fusion::core;

namespace {

constexpr double kWindowRes = 0.1;  // 360 x 280 cells: several chunks of kFusionChunkCells
constexpr double kScanRes = 0.2;

/// A scan of random free and occupied cells (a fifth of them occupied, a fifth vacuous) and one obstacle return per
/// occupied cell, off its centre.
struct RandomScan
{
  ScanMassGrid grid{ GridGeometry::centred(40.0, 30.0, kScanRes) };
  std::vector<float> xy;

  explicit RandomScan(unsigned seed)
  {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.05, 0.9);
    std::uniform_int_distribution<int> kind(0, 9);
    const GridGeometry& g = grid.geometry();
    for (std::size_t i = 0; i < grid.numCells(); ++i)
    {
      const double m = u(rng);
      const int k = kind(rng);
      if (k < 2)
      {
        grid.setCell(i, MassSG{ { FrameSG::kO, m }, { FrameSG::kOmega, 1.0 - m } });
        const Point2 c = g.cellCentre(g.cellOf(i));
        xy.push_back(static_cast<float>(c.x + 0.03));
        xy.push_back(static_cast<float>(c.y - 0.07));
      }
      else if (k < 8)
        grid.setCell(i, MassSG{ { FrameSG::kF, m }, { FrameSG::kOmega, 1.0 - m } });
    }
  }
  ObstaclePoints points() const { return ObstaclePoints{ xy.data(), xy.size() / 2 }; }
};

bool samePlane(const ScanMassGrid& a, const std::vector<float>& b, Subset s)
{
  return std::memcmp(a.plane(s), b.data(), b.size() * sizeof(float)) == 0;
}

}  // namespace

TEST(ScanProjection, AnyRunsOfCellsAreWhatProjectScanWrites)
{
  const RandomScan scan(3);
  const ObstaclePoints points = scan.points();
  const GridGeometry window = GridGeometry::centred(36.0, 28.0, kWindowRes);
  const std::size_t n = window.numCells();
  std::mt19937 rng(9);
  const Parallel two(2);
  ScanMassGrid whole;
  ScanProjection projection;
  for (const ObstaclePoints* obstacles : { static_cast<const ObstaclePoints*>(nullptr), &points })
    for (int clearance : { 0, 3 })
      for (const Pose2 pose : { Pose2{ 0.0, 0.0, 0.0 }, Pose2{ 1.1, -0.4, 0.6 }, Pose2{ -3.3, 2.05, -2.3 } })
      {
        projectScan(scan.grid, pose, window, whole, obstacles, clearance, &two);
        projection.plan(scan.grid, pose, window, obstacles, clearance, Parallel(1));
        // Runs that start and end anywhere: inside rows, across rows, across chunks of the fused step.
        std::vector<float> f(n), o(n), omega(n), empty(n);
        std::uniform_int_distribution<std::size_t> run(1, 3 * kFusionChunkCells / 2);
        for (std::size_t b = 0; b < n;)
        {
          const std::size_t e = std::min(n, b + run(rng));
          projection.fill(b, e, f.data() + b, o.data() + b, omega.data() + b, empty.data() + b);
          b = e;
        }
        const std::string what = std::string(obstacles ? "points" : "forward") + " clearance " +
                                 std::to_string(clearance) + " yaw " + std::to_string(pose.yaw);
        EXPECT_TRUE(samePlane(whole, f, FrameSG::kF)) << what;
        EXPECT_TRUE(samePlane(whole, o, FrameSG::kO)) << what;
        EXPECT_TRUE(samePlane(whole, omega, FrameSG::kOmega)) << what;
        EXPECT_TRUE(samePlane(whole, empty, FrameSG::kEmpty)) << what;
        std::size_t occupied = 0, wrong = 0, sampled = 0;
        for (std::size_t i = 0; i < n; ++i)
        {
          occupied += projection.occupied()[i] != 0;
          wrong += projection.occupied()[i] != (o[i] > 0.0f ? 1 : 0);
          sampled += omega[i] < 1.0f;
          ASSERT_GE(f[i], 0.0f);
          ASSERT_GE(o[i], 0.0f);
          ASSERT_GE(omega[i], 0.0f);
          ASSERT_NEAR(empty[i] + f[i] + o[i] + omega[i], 1.0f, 1e-6f) << i;
        }
        EXPECT_EQ(wrong, 0u) << what;
        EXPECT_GT(occupied, n / 50) << what;
        EXPECT_GT(sampled, clearance ? n / 20 : n / 2) << what;  // the clearance takes the free mass near obstacles
      }
}

TEST(ScanProjection, PointOccupancyIsTheLargestOccupiedMassOfTheReturnsInEachCell)
{
  // By definition: the window cell under a return in an occupied scan cell takes that cell's m(O) (the largest of its
  // returns'), with m(F) = 0 and m(Ω) = 1 − m(O); no other cell holds m(O). The returns come several to a cell, some
  // repeated in a row, some in free or vacuous cells, outside the scan grid or the window, or not finite.
  RandomScan scan(5);
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  std::vector<float> xy;
  for (std::size_t k = 0; k + 1 < scan.xy.size(); k += 2)
    for (int copy = 0; copy < 3; ++copy)
    {
      const double dx = copy == 1 ? 0.0 : jitter(rng) * kScanRes, dy = copy == 1 ? 0.0 : jitter(rng) * kScanRes;
      xy.push_back(static_cast<float>(scan.xy[k] + dx));
      xy.push_back(static_cast<float>(scan.xy[k + 1] + dy));
    }
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  for (const auto& [x, y] : { std::pair{ nan, 1.0f }, std::pair{ 1.0f, inf }, std::pair{ -inf, 0.0f },
                              std::pair{ 25.0f, 0.0f }, std::pair{ 0.0f, -18.0f }, std::pair{ 0.5f, 0.5f } })
  {
    xy.push_back(x);
    xy.push_back(y);
  }
  const ObstaclePoints points{ xy.data(), xy.size() / 2 };
  const GridGeometry& sg = scan.grid.geometry();
  const GridGeometry window = GridGeometry::centred(30.0, 24.0, kWindowRes);
  ScanMassGrid projected;
  for (const Pose2 pose : { Pose2{ 0.0, 0.0, 0.0 }, Pose2{ 1.1, -0.4, 0.6 }, Pose2{ -3.3, 2.05, -2.3 } })
    for (const int threads : { 1, 2 })
    {
      const Parallel parallel(threads);
      projectScan(scan.grid, pose, window, projected, &points, 0, &parallel);
      std::vector<float> expected(window.numCells(), 0.0f);
      const double c = std::cos(pose.yaw), s = std::sin(pose.yaw);
      std::size_t marked = 0;
      for (std::size_t k = 0; k < points.count; ++k)
      {
        const double vx = xy[2 * k], vy = xy[2 * k + 1];
        CellIndex sc, wc;
        if (!sg.worldToCell(Point2{ vx, vy }, sc)) continue;
        const float occupied = scan.grid.at(FrameSG::kO, sg.index(sc));
        if (!(occupied > 0.0f)) continue;
        if (!window.worldToCell(Point2{ pose.x + c * vx - s * vy, pose.y + s * vx + c * vy }, wc)) continue;
        float& e = expected[window.index(wc)];
        e = std::max(e, occupied);
        ++marked;
      }
      ASSERT_GT(marked, points.count / 4);
      std::size_t wrong = 0;
      for (std::size_t j = 0; j < window.numCells(); ++j)
      {
        wrong += projected.at(FrameSG::kO, j) != expected[j];
        if (expected[j] > 0.0f)
          wrong += projected.at(FrameSG::kF, j) != 0.0f || projected.at(FrameSG::kOmega, j) != 1.0f - expected[j];
      }
      EXPECT_EQ(wrong, 0u) << "yaw " << pose.yaw << ", " << threads << " threads";
    }
}

TEST(ScanProjection, FusedStepOnTheFilledChunksEqualsTheStepOnTheProjectedScanGrid)
{
  const RandomScan scan(4);
  const ObstaclePoints points = scan.points();
  const GridGeometry window = GridGeometry::centred(36.0, 28.0, kWindowRes);
  PriorWindow prior(window);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 0.9f);
  for (std::size_t i = 0; i < prior.building.size(); ++i)
    (i % 3 == 0 ? prior.building : i % 3 == 1 ? prior.road : prior.other)[i] = u(rng);
  AlignedVector<float> doubt_a(window.numCells(), 0.0f), doubt_b(window.numCells(), 0.0f);
  const FusionParams params;
  for (int threads : { 1, 2 })
  {
    const Parallel parallel(threads);
    MapMassGrid a(window), b(window);
    PignisticPlanes betp_a, betp_b;
    std::vector<std::int8_t> decision_a, decision_b;
    std::vector<std::vector<std::size_t>> seeds_a, seeds_b;
    StepDecisions da, db;
    da.out = &decision_a;
    db.out = &decision_b;
    da.motion_seeds = &seeds_a;
    db.motion_seeds = &seeds_b;
    da.motion_margin = db.motion_margin = 0.1;
    ScanMassGrid projected;
    ScanProjection projection;
    for (int step = 0; step < 4; ++step)
    {
      const Pose2 pose{ 0.3 * step, -0.2 * step, 0.4 * step };
      const ObstaclePoints* obstacles = step % 2 ? &points : nullptr;
      projectScan(scan.grid, pose, window, projected, obstacles, 2, &parallel);
      projection.plan(scan.grid, pose, window, obstacles, 2, parallel);
      StepPrior pa, pb;
      pa.grid = pb.grid = &prior;
      pa.row_stride = pb.row_stride = static_cast<std::size_t>(window.width);
      pa.doubt = doubt_a.data();
      pb.doubt = doubt_b.data();
      pa.conflict_gain = pb.conflict_gain = 0.2;
      FusionStepStats sa, sb;
      fusionStep(a, projected, pa, params, &sa, &betp_a, &parallel, &da);
      fusionStep(b, projection, pb, params, &sb, &betp_b, &parallel, &db);
      const std::size_t floats = a.stride() * (MapMassGrid::kNumPlanes + 1);
      EXPECT_EQ(std::memcmp(a.planes(), b.planes(), floats * sizeof(float)), 0) << threads << " step " << step;
      for (int e = 0; e < FrameMG::kSize; ++e) EXPECT_EQ(betp_a[e], betp_b[e]) << threads << " step " << step;
      EXPECT_EQ(decision_a, decision_b) << threads << " step " << step;
      EXPECT_EQ(seeds_a, seeds_b) << threads << " step " << step;
      EXPECT_EQ(std::memcmp(doubt_a.data(), doubt_b.data(), doubt_a.size() * sizeof(float)), 0) << threads;
      EXPECT_EQ(sa.sum_conflict_free_occupied, sb.sum_conflict_free_occupied) << threads << " step " << step;
      const double conflict = sa.sum_conflict_free_occupied + sa.sum_conflict_occupied_free;
      EXPECT_TRUE(step == 0 || conflict > 0.0) << threads << " step " << step;  // later scans disagree with the map
    }
  }
}

TEST(ScanProjection, RefusesAScanOfOtherCellsThanTheMap)
{
  const RandomScan scan(6);
  ScanProjection projection;
  projection.plan(scan.grid, Pose2{}, GridGeometry::centred(8.0, 8.0, kWindowRes), nullptr, 0, Parallel(1));
  MapMassGrid map(GridGeometry::centred(8.0, 8.2, kWindowRes));
  EXPECT_THROW(fusionStep(map, projection, StepPrior{}, FusionParams{}), std::invalid_argument);
}

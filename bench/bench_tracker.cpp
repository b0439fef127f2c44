// The tracker's cost per scan (core/tracker.hpp), one thread: association and filtering of 200 measurements against
// 200 established tracks, the clustering of the scan's obstacle returns into those measurements, and a whole scan
// (clustering, tracking and the free-space check on a 100 m ScanGrid), and the free space of one scan that the check
// reads (core/seen_free.hpp) on the windows of the MapGrid benchmarks.
#include <benchmark/benchmark.h>

#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "map_aided_fusion/core/seen_free.hpp"
#include "map_aided_fusion/core/tracker.hpp"
#include "window_params.hpp"

using namespace map_aided_fusion::core;

namespace {

constexpr double kScanPeriod = 0.1;  // s

/// @p n objects on a 10 m lattice moving at 1–10 m/s, measured with 5 cm noise, at scan @p k.
std::vector<Measurement> scene(int n, int k, std::mt19937& rng)
{
  std::normal_distribution<double> noise(0.0, 0.05);
  std::vector<Measurement> out;
  out.reserve(n);
  for (int i = 0; i < n; ++i)
  {
    const double speed = 1.0 + 9.0 * (i % 10) / 9.0, heading = 0.7 * i;
    Measurement m;
    m.centroid = Point2{ 10.0 * (i % 20) + speed * std::cos(heading) * kScanPeriod * k + noise(rng),
                         10.0 * (i / 20) + speed * std::sin(heading) * kScanPeriod * k + noise(rng) };
    m.covariance = Eigen::Matrix2d::Identity() * 0.04;
    m.length = 4.0;
    m.width = 1.8;
    m.points = 50;
    out.push_back(m);
  }
  return out;
}

void BM_TrackerUpdate(benchmark::State& state)
{
  const int n = static_cast<int>(state.range(0));
  std::mt19937 rng(1);
  Tracker tracker;
  int k = 0;
  for (; k < 10; ++k) tracker.update(kScanPeriod * k, scene(n, k, rng));
  std::vector<std::vector<Measurement>> scans;
  for (int j = 0; j < 64; ++j) scans.push_back(scene(n, k + j, rng));
  std::size_t j = 0;
  for (auto _ : state)
  {
    tracker.update(kScanPeriod * (k + static_cast<int>(j)), scans[j % scans.size()]);
    if (++j % scans.size() == 0) k += static_cast<int>(scans.size());
  }
  state.counters["tracks"] = static_cast<double>(tracker.tracks().size());
}

void BM_ClusterReturns(benchmark::State& state)
{
  const int n = static_cast<int>(state.range(0));
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  std::vector<Point2> points;
  for (int i = 0; i < n; ++i)
    for (int p = 0; p < 100; ++p)
      points.push_back(Point2{ 10.0 * (i % 20) + 4.0 * u(rng), 10.0 * (i / 20) + 1.8 * u(rng) });
  const TrackerParams params;
  for (auto _ : state) benchmark::DoNotOptimize(clusterReturns(points, params));
  state.counters["returns"] = static_cast<double>(points.size());
}

/// A 100 m ScanGrid at 0.5 m, free but where the returns @p xy (x, y pairs) are.
void freeButTheReturns(const std::vector<float>& xy, ScanMassGrid& grid)
{
  grid = ScanMassGrid(GridGeometry::centred(100.0, 100.0, 0.5));
  const GridGeometry& g = grid.geometry();
  for (std::size_t c = 0; c < g.numCells(); ++c) grid.setCell(c, MassSG{ { FrameSG::kF, 0.7 }, { FrameSG::kOmega, 0.3 } });
  for (std::size_t p = 0; p + 1 < xy.size(); p += 2)
  {
    CellIndex c;
    if (g.worldToCell(Point2{ xy[p], xy[p + 1] }, c))
      grid.setCell(g.index(c), MassSG{ { FrameSG::kO, 0.8 }, { FrameSG::kOmega, 0.2 } });
  }
}

/// Scan @p k of BM_TrackerScan: @p n objects of 4 × 1.8 m, 100 returns each (vehicle frame = map frame), and a
/// 100 m ScanGrid at 0.5 m, free but where the returns are.
void scanScene(int n, int k, std::mt19937& rng, std::vector<float>& xy, ScanMassGrid& grid)
{
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  xy.clear();
  for (int i = 0; i < n; ++i)
  {
    const double speed = 1.0 + 9.0 * (i % 10) / 9.0;
    const double cx = -45.0 + 4.5 * (i % 20) + speed * kScanPeriod * (k % 10), cy = -45.0 + 9.0 * (i / 20);
    for (int p = 0; p < 100; ++p)
    {
      xy.push_back(static_cast<float>(cx + 4.0 * u(rng)));
      xy.push_back(static_cast<float>(cy + 1.8 * u(rng)));
    }
  }
  freeButTheReturns(xy, grid);
}

void BM_TrackerScan(benchmark::State& state)
{
  const int n = static_cast<int>(state.range(0));
  std::mt19937 rng(3);
  constexpr int kScenes = 10;
  std::vector<std::vector<float>> xy(kScenes);
  std::vector<ScanMassGrid> grids(kScenes);
  for (int k = 0; k < kScenes; ++k) scanScene(n, k, rng, xy[k], grids[k]);
  TrackerParams params;
  params.steps.free_space_check = state.range(1) != 0;
  params.steps.open_ends = state.range(2) != 0;
  params.steps.duplicates = state.range(3) != 0;
  Tracker tracker(params);
  int k = 0;
  for (auto _ : state)
  {
    const std::vector<float>& r = xy[k % kScenes];
    tracker.update(kScanPeriod * k, Pose2{}, ObstaclePoints{ r.data(), r.size() / 2 }, nullptr, &grids[k % kScenes]);
    ++k;
  }
  state.counters["tracks"] = static_cast<double>(tracker.tracks().size());
}

/// Scan @p k of BM_TrackerClutter: @p n separate clusters of 20 returns within 0.3 m, on a lattice of 1.4 m (rain,
/// a flock of birds, hedges), each moved by up to 0.1 m per scan; the ScanGrid as scanScene()'s.
void clutterScene(int n, std::mt19937& rng, std::vector<float>& xy, ScanMassGrid& grid)
{
  constexpr int kReturns = 20;
  constexpr double kSpacing = 1.4, kSpread = 0.3, kJitter = 0.1;
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  const int side = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(n))));
  xy.clear();
  for (int i = 0; i < n; ++i)
  {
    const double cx = -49.0 + kSpacing * (i % side) + kJitter * u(rng);
    const double cy = -49.0 + kSpacing * (i / side) + kJitter * u(rng);
    for (int p = 0; p < kReturns; ++p)
    {
      xy.push_back(static_cast<float>(cx + kSpread * u(rng)));
      xy.push_back(static_cast<float>(cy + kSpread * u(rng)));
    }
  }
  freeButTheReturns(xy, grid);
}

/// Arg: n clusters of clutter (clutterScene()), the default parameters (bounds included). The time per return
/// (items) must not grow with n: the bounds and the association's grid keep the scan's cost linear.
void BM_TrackerClutter(benchmark::State& state)
{
  const int n = static_cast<int>(state.range(0));
  std::mt19937 rng(4);
  constexpr int kScenes = 10;
  std::vector<std::vector<float>> xy(kScenes);
  std::vector<ScanMassGrid> grids(kScenes);
  for (int k = 0; k < kScenes; ++k) clutterScene(n, rng, xy[k], grids[k]);
  Tracker tracker;
  int k = 0;
  for (; k < kScenes; ++k)  // the tracks of the clutter established, up to max_tracks
    tracker.update(kScanPeriod * k, Pose2{}, ObstaclePoints{ xy[k].data(), xy[k].size() / 2 }, nullptr, &grids[k]);
  for (auto _ : state)
  {
    const std::vector<float>& r = xy[k % kScenes];
    tracker.update(kScanPeriod * k, Pose2{}, ObstaclePoints{ r.data(), r.size() / 2 }, nullptr, &grids[k % kScenes]);
    ++k;
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(xy[0].size() / 2));
  state.counters["returns"] = static_cast<double>(xy[0].size() / 2);
  state.counters["tracks"] = static_cast<double>(tracker.tracks().size());
}

/// Arg: N (cells per side, at maf_bench::windowResolution(N)). A scan seen free up to 60 m around the sensor, with
/// 300 obstacles of 1 × 1 m to 3 × 2 m and nothing seen beyond; the default margins (0.5 m and 0 m).
void BM_SeenFree(benchmark::State& state)
{
  const int n = static_cast<int>(state.range(0));
  const double res = maf_bench::windowResolution(n);
  ScanMassGrid scan(GridGeometry::centred(n * res, n * res, res));
  const GridGeometry& g = scan.geometry();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> where(-60.0, 60.0), side(1.0, 3.0);
  std::vector<std::array<double, 4>> boxes(300);
  for (auto& b : boxes) b = { where(rng), where(rng), side(rng), side(rng) - 1.0 };
  for (std::size_t i = 0; i < g.numCells(); ++i)
  {
    const Point2 c = g.cellCentre(g.cellOf(i));
    bool obstacle = false;
    for (const auto& b : boxes)
      obstacle = obstacle || (std::abs(c.x - b[0]) <= 0.5 * b[2] && std::abs(c.y - b[1]) <= 0.5 * (1.0 + b[3]));
    if (obstacle)
      scan.setCell(i, MassSG{ { FrameSG::kO, 0.8 }, { FrameSG::kOmega, 0.2 } });
    else if (std::hypot(c.x, c.y) <= 60.0)
      scan.setCell(i, MassSG{ { FrameSG::kF, 0.7 }, { FrameSG::kOmega, 0.3 } });
  }
  const TrackerParams p;
  std::size_t clear = 0;
  for (auto _ : state)
  {
    const SeenFree seen(scan, Pose2{}, 0.0, p.free_space_margin, kSmallFreeSpaceMargin);
    clear = seen.clearCells();
    benchmark::DoNotOptimize(clear);
  }
  state.counters["clear_share"] = static_cast<double>(clear) / static_cast<double>(g.numCells());
}

}  // namespace

BENCHMARK(BM_SeenFree)->Arg(200)->Arg(800)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_TrackerScan)
    ->ArgNames({ "n", "free_space_check", "open_ends", "duplicates" })
    ->Args({ 200, 0, 0, 0 })
    ->Args({ 200, 1, 0, 0 })
    ->Args({ 200, 1, 1, 0 })
    ->Args({ 200, 1, 1, 1 })
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_TrackerClutter)->ArgName("clusters")->Arg(200)->Arg(5000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_TrackerUpdate)->Arg(200)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ClusterReturns)->Arg(200)->Unit(benchmark::kMicrosecond);

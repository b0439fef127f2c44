// The full per-scan fusion of the MapGrid: mapping the scan grid into the window, all the paper's steps and
// the BetP layers, for an N×N window: 800 (160 m at 0.2 m) and the paper's 200 (100 m at 0.5 m); the bytes it cannot
// avoid, streamed; and the scan projection alone.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <vector>

#include "map_aided_fusion/core/map_grid.hpp"
#include "window_params.hpp"

using namespace map_aided_fusion::core;

namespace {

/// An N × N ScanGrid at @p res like a real scan (BM_ScanGrid/130000 marks ~0.2 % of the cells occupied): 60 % free,
/// 0.5 % occupied.
ScanMassGrid benchScan(int n, double res)
{
  ScanMassGrid scan(GridGeometry::centred(n * res, n * res, res));
  std::mt19937 rng(2);
  std::uniform_int_distribution<int> kind(0, 999);
  for (std::size_t i = 0; i < scan.numCells(); ++i)
  {
    const int k = kind(rng);
    scan.setCell(i, k < 600 ? MassSG{ { FrameSG::kF, 0.7 }, { FrameSG::kOmega, 0.3 } }
                            : k < 605 ? MassSG{ { FrameSG::kO, 0.8 }, { FrameSG::kOmega, 0.2 } } : MassSG());
  }
  return scan;
}

/// MapGrid::update() on an N × N window (Args: N, threads) driving back and forth; with @p returns the scan comes with
/// obstacle returns, four per occupied scan cell (the step point occupancy, as the live nodelets run it).
void runUpdates(benchmark::State& state, bool returns)
{
  const int n = static_cast<int>(state.range(0));
  const double res = maf_bench::windowResolution(n);
  MapGrid grid(maf_bench::windowParams(n, static_cast<int>(state.range(1))));
  const ScanMassGrid scan = benchScan(n, res);
  std::vector<float> xy;
  for (std::size_t i = 0; returns && i < scan.numCells(); ++i)
    if (scan.plane(FrameSG::kO)[i] > 0.0f)
    {
      const Point2 c = scan.geometry().cellCentre(scan.geometry().cellOf(i));
      for (const double d : { -0.25 * res, 0.25 * res })
        for (const double e : { -0.25 * res, 0.25 * res })
        {
          xy.push_back(static_cast<float>(c.x + d));
          xy.push_back(static_cast<float>(c.y + e));
        }
    }
  const ObstaclePoints obstacles{ xy.data(), xy.size() / 2 };
  PriorWindow prior(GridGeometry::centred(2.0 * n * res, 2.0 * n * res, res));
  for (std::size_t i = 0; i < prior.building.size(); ++i) (i % 3 == 0 ? prior.road : prior.other)[i] = 0.9f;
  double t = 0.0;
  Pose2 pose;
  StageTimes sum;
  double step = 1.0;  // 10 m/s at 10 Hz: the window shifts every few scans (MapGridParams::recentre_distance)
  for (auto _ : state)
  {
    // Back and forth within a quarter window of the origin: the window stays inside the prior (twice its size)
    // however many iterations the benchmark runs.
    if (std::abs(pose.x + step) > 0.25 * n * res) step = -step;
    pose.x += step;
    pose.yaw += 0.01;
    StageTimes st;
    grid.update(scan, pose, t += 0.1, &prior, &st, returns ? &obstacles : nullptr);
    sum.shift += st.shift;
    sum.project_scan += st.project_scan;
    sum.prior_window += st.prior_window;
    sum.fusion += st.fusion;
    benchmark::ClobberMemory();
  }
  // Mean milliseconds per scan of each stage: project_ms is the projection's plan; the fusion stage includes the scan's
  // samples (written chunk by chunk by the fused step), BetP, the decisions and motion spreading.
  const double k = 1e3 / static_cast<double>(std::max<std::int64_t>(1, state.iterations()));
  state.counters["shift_ms"] = sum.shift * k;
  state.counters["project_ms"] = sum.project_scan * k;
  state.counters["prior_ms"] = sum.prior_window * k;
  state.counters["fusion_ms"] = sum.fusion * k;
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(n) * n);
}

/// The update with occupied evidence from the resampled scan cells (no returns). Args: N (cells per side), threads.
void BM_MapGridUpdate(benchmark::State& state) { runUpdates(state, false); }

/// The update as the live default runs it: with the scan's obstacle returns (point occupancy). Args: N, threads.
void BM_MapGridUpdateReturns(benchmark::State& state) { runUpdates(state, true); }

/// The bytes BM_MapGridUpdate cannot avoid, streamed once with no arithmetic, in the same chunks and threads: read and
/// write the MapGrid's blocks (29 stored masses and ζ per cell), read the scan's F, O and Ω (its planes at the window's
/// size, as BM_MapGridUpdate's scan) and the prior's four planes (the window's rows of a prior twice its size), read
/// and write the map doubt η, write BetP (5 planes) and the decision. What the update adds beyond this is arithmetic
/// and the passes it makes again (the shift, the projection's plan, motion spreading). Args: N, threads.
void BM_UpdateBaseline(benchmark::State& state)
{
  const int n = static_cast<int>(state.range(0));
  const double res = maf_bench::windowResolution(n);
  const Parallel parallel(static_cast<int>(state.range(1)));
  const GridGeometry window = GridGeometry::centred(n * res, n * res, res);
  MapMassGrid map(window);
  const ScanMassGrid scan = benchScan(n, res);
  PriorWindow prior(GridGeometry::centred(2.0 * n * res, 2.0 * n * res, res));
  AlignedVector<float> eta(window.numCells(), 0.0f);
  PignisticPlanes betp;
  for (auto& p : betp.p) p.assign(window.numCells(), 0.0f);
  std::vector<std::int8_t> decision(window.numCells());
  const std::size_t cells = window.numCells(), w = static_cast<std::size_t>(n);
  const std::size_t prior_w = static_cast<std::size_t>(prior.geometry.width);
  const std::size_t prior_first = (prior_w / 4) * prior_w + prior_w / 4;  // the window's cell (0, 0)
  constexpr std::size_t kBlock = MapMassGrid::kBlockCells;
  constexpr int kSlots = MapMassGrid::kNumPlanes + 1;
  const float* const in_scan[3] = { scan.plane(FrameSG::kF), scan.plane(FrameSG::kO), scan.plane(FrameSG::kOmega) };
  const float* const in_prior[4] = { prior.building.data(), prior.road.data(), prior.other.data(), prior.wall.data() };
  float* const out_betp[FrameMG::kSize] = { betp.p[0].data(), betp.p[1].data(), betp.p[2].data(), betp.p[3].data(),
                                            betp.p[4].data() };
  float* const eta_data = eta.data();
  std::int8_t* const decision_data = decision.data();
  for (auto _ : state)
  {
    float* const base = map.planes();
    parallel.forRange(cells, kFusionChunkCells, [&](std::size_t c0, std::size_t c1) {
      float add[kFusionChunkCells];  // per cell of the chunk: what it read
      const std::size_t len = c1 - c0;
      std::fill_n(add, len, 0.0f);
      for (const float* p : in_scan)
        for (std::size_t k = 0; k < len; ++k) add[k] += p[c0 + k];
      for (std::size_t i = c0; i < c1;)  // the prior's rows
      {
        const std::size_t row_end = std::min(c1, (i / w + 1) * w);
        const std::size_t at = prior_first + i / w * prior_w + i % w;
        for (const float* p : in_prior)
          for (std::size_t k = 0; k < row_end - i; ++k) add[i - c0 + k] += p[at + k];
        i = row_end;
      }
      float* __restrict const e = eta_data + c0;
      for (std::size_t k = 0; k < len; ++k) e[k] = e[k] * 0.5f + add[k];
      for (std::size_t i0 = c0; i0 < c1; i0 += kBlock)
      {
        float* __restrict const block = base + MapMassGrid::blockOffset(i0);
        for (int a = 0; a < kSlots; ++a)
          for (std::size_t k = 0; k < kBlock; ++k) block[a * kBlock + k] = block[a * kBlock + k] * 0.5f + add[i0 - c0 + k];
      }
      for (float* p : out_betp)
      {
        float* __restrict const q = p + c0;
        for (std::size_t k = 0; k < len; ++k) q[k] = add[k];
      }
      std::int8_t* __restrict const d = decision_data + c0;
      for (std::size_t k = 0; k < len; ++k) d[k] = static_cast<std::int8_t>(add[k] > 1.0f);
    });
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(n) * n);
}

/// projectScan() alone on an 800 × 800 window at 0.2 m, the scan rotated by 0.1 rad: the resampling and, with Arg
/// clearance > 0, the step "obstacle clearance" over that many cells. Args: clearance cells, threads.
void BM_ProjectScan(benchmark::State& state)
{
  constexpr int kN = 800;
  constexpr double kRes = 0.2;
  const Parallel parallel(static_cast<int>(state.range(1)));
  const ScanMassGrid scan = benchScan(kN, kRes);
  const GridGeometry window = GridGeometry::centred(kN * kRes, kN * kRes, kRes);
  ScanMassGrid out;
  const Pose2 pose{ 1.0, 0.4, 0.1 };
  for (auto _ : state)
  {
    projectScan(scan, pose, window, out, nullptr, static_cast<int>(state.range(0)), &parallel);
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(kN) * kN);
}

/// MapGrid::shift() of an 800 × 800 window at 0.2 m by 25 columns and 3 rows, then back (a recentring after 5 m):
/// the masses and ζ; with Arg skip, also the flags of skip_unchanged and what a skipped block keeps. Args: threads,
/// skip.
void BM_MapGridShift(benchmark::State& state)
{
  constexpr int kN = 800;
  constexpr int kColumns = 25, kRows = 3;
  MapGrid grid(maf_bench::windowParams(kN, static_cast<int>(state.range(0)), state.range(1) != 0));
  grid.update(benchScan(kN, maf_bench::windowResolution(kN)), Pose2{}, 0.0, nullptr);
  int sign = 1;
  for (auto _ : state)
  {
    grid.shift(sign * kColumns, sign * kRows);
    sign = -sign;
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(kN) * kN);
}

}  // namespace

BENCHMARK(BM_MapGridShift)->ArgsProduct({ { 1, 2 }, { 0, 1 } })->ArgNames({ "threads", "skip" })->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MapGridUpdate)->ArgsProduct({ { 200, 800 }, { 1, 2 } })->ArgNames({ "n", "threads" })->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MapGridUpdateReturns)->ArgsProduct({ { 200, 800 }, { 1, 2 } })->ArgNames({ "n", "threads" })->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_UpdateBaseline)->ArgsProduct({ { 200, 800 }, { 1, 2 } })->ArgNames({ "n", "threads" })->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ProjectScan)->ArgsProduct({ { 0, 5 }, { 1, 2 } })->ArgNames({ "clearance", "threads" })->UseRealTime()
    ->Unit(benchmark::kMillisecond);

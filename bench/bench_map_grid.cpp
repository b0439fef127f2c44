// The full per-scan fusion of the MapGrid: mapping the scan grid into the window, all the paper's steps and
// the BetP layers, for an N×N window: 800 (160 m at 0.2 m) and the paper's 200 (100 m at 0.5 m); and the scan
// projection alone.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>

#include "map_aided_fusion/core/map_grid.hpp"

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

/// Args: N (cells per side), threads (MapGridParams::threads).
void BM_MapGridUpdate(benchmark::State& state)
{
  const int n = static_cast<int>(state.range(0));
  const double res = n == 200 ? 0.5 : 0.2;
  MapGridParams params;
  params.threads = static_cast<int>(state.range(1));
  params.size_x = params.size_y = n * res;
  params.resolution = res;
  MapGrid grid(params);
  const ScanMassGrid scan = benchScan(n, res);
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
    grid.update(scan, pose, t += 0.1, &prior, &st);
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

}  // namespace

BENCHMARK(BM_MapGridUpdate)->ArgsProduct({ { 200, 800 }, { 1, 2 } })->ArgNames({ "n", "threads" })->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ProjectScan)->ArgsProduct({ { 0, 5 }, { 1, 2 } })->ArgNames({ "clearance", "threads" })->UseRealTime()
    ->Unit(benchmark::kMillisecond);

// The full per-scan fusion of the MapGrid: mapping the scan grid into the window, all the paper's steps and
// the BetP layers, for an N×N window: 800 (160 m at 0.2 m) and the paper's 200 (100 m at 0.5 m).
#include <benchmark/benchmark.h>

#include <random>

#include "map_aided_fusion/core/map_grid.hpp"

using namespace map_aided_fusion::core;

namespace {

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
  ScanMassGrid scan(GridGeometry::centred(n * res, n * res, res));
  std::mt19937 rng(2);
  // Like a real scan (BM_ScanGrid/130000 marks ~0.2 % of the cells occupied): 60 % free, 0.5 % occupied.
  std::uniform_int_distribution<int> kind(0, 999);
  for (std::size_t i = 0; i < scan.numCells(); ++i)
  {
    const int k = kind(rng);
    scan.setCell(i, k < 600 ? MassSG{ { FrameSG::kF, 0.7 }, { FrameSG::kOmega, 0.3 } }
                            : k < 605 ? MassSG{ { FrameSG::kO, 0.8 }, { FrameSG::kOmega, 0.2 } } : MassSG());
  }
  PriorWindow prior(GridGeometry::centred(2.0 * n * res, 2.0 * n * res, res));
  for (std::size_t i = 0; i < prior.building.size(); ++i) (i % 3 == 0 ? prior.road : prior.other)[i] = 0.9f;
  std::vector<std::int8_t> decision;
  double t = 0.0;
  Pose2 pose;
  for (auto _ : state)
  {
    pose.x += 1.0;  // 10 m/s at 10 Hz: the window shifts every scan
    pose.yaw += 0.01;
    grid.update(scan, pose, t += 0.1, &prior);
    decide(grid.masses(), grid.pignistic(), params.decision_threshold, decision, &grid.parallel());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(n) * n);
}

}  // namespace

BENCHMARK(BM_MapGridUpdate)->ArgsProduct({ { 200, 800 }, { 1, 2 } })->ArgNames({ "n", "threads" })->UseRealTime()
    ->Unit(benchmark::kMillisecond);

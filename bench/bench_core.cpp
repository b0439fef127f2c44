// Whole-grid operations and the full fusion step on N×N grids (800×800 = 160 m at 0.2 m), and a
// baseline that only streams the bytes the fusion step reads and writes.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <random>
#include <vector>

#include "map_aided_fusion/core/fusion.hpp"
#include "map_aided_fusion/core/grid_ops.hpp"

using namespace map_aided_fusion::core;

namespace {

GridGeometry squareGrid(int n) { return GridGeometry{ 0.2, n, n, 0.0, 0.0 }; }

/// A MapGrid after a few realistic fusion steps, so that most focal sets carry mass.
struct Scene
{
  MapMassGrid map;
  ScanMassGrid scan;
  PriorWindow prior;
  explicit Scene(int n) : map(squareGrid(n)), scan(squareGrid(n)), prior(squareGrid(n))
  {
    std::mt19937 rng(1);
    std::uniform_int_distribution<int> cls(0, 3), kind(0, 2);
    const PriorConfidence beta;
    for (std::size_t i = 0; i < map.numCells(); ++i)
    {
      const auto m = priorMass(static_cast<PriorClass>(cls(rng)), beta);
      prior.building[i] = static_cast<float>(m[FrameMG::kBuilding]);
      prior.road[i] = static_cast<float>(m[FrameMG::kRoad]);
      prior.other[i] = static_cast<float>(m[FrameMG::kOther]);
    }
    FusionParams params;
    for (int step = 0; step < 3; ++step)
    {
      for (std::size_t i = 0; i < scan.numCells(); ++i)
      {
        const int k = kind(rng);
        scan.setCell(i, k == 0 ? MassSG{ { FrameSG::kF, 0.7 }, { FrameSG::kOmega, 0.3 } }
                               : k == 1 ? MassSG{ { FrameSG::kO, 0.8 }, { FrameSG::kOmega, 0.2 } } : MassSG());
      }
      fusionStep(map, scan, &prior, params);
    }
  }
};

void setCells(benchmark::State& state, int n)
{
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(n) * n);
  state.counters["ns_per_cell"] = benchmark::Counter(static_cast<double>(state.iterations()) * n * n * 1e-9,
                                                     benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

/// Args: N (cells per side), threads.
void BM_FusionStep(benchmark::State& state)
{
  const int n = static_cast<int>(state.range(0));
  const Parallel parallel(static_cast<int>(state.range(1)));
  Scene scene(n);
  FusionParams params;
  for (auto _ : state)
  {
    fusionStep(scene.map, scene.scan, &scene.prior, params, nullptr, nullptr, &parallel);
    benchmark::ClobberMemory();
  }
  setCells(state, n);
}

/// Reads everything the fusion step reads (the MapGrid's blocks: 29 stored masses and ζ per cell; 3 scan planes,
/// 3 prior planes) and writes the blocks: the memory traffic of BM_FusionStep with no arithmetic, in the same
/// layout, chunks and threads. Args: N, threads.
void BM_StreamBaseline(benchmark::State& state)
{
  const int n = static_cast<int>(state.range(0));
  const Parallel parallel(static_cast<int>(state.range(1)));
  Scene scene(n);
  const std::size_t cells = scene.map.numCells();
  constexpr std::size_t kBlock = MapMassGrid::kBlockCells;
  constexpr int kSlots = MapMassGrid::kNumPlanes + 1;  // and ζ
  for (auto _ : state)
  {
    float* base = scene.map.planes();
    const float* in[6] = { scene.scan.plane(FrameSG::kF), scene.scan.plane(FrameSG::kO),
                           scene.scan.plane(FrameSG::kOmega), scene.prior.building.data(),
                           scene.prior.road.data(), scene.prior.other.data() };
    parallel.forRange(cells, kFusionChunkCells, [&](std::size_t c0, std::size_t c1) {
      for (std::size_t i0 = c0; i0 < c1; i0 += kBlock)
      {
        const std::size_t len = std::min(kBlock, c1 - i0);
        float add[kBlock] = {};
        for (const float* p : in)
          for (std::size_t k = 0; k < len; ++k) add[k] += p[i0 + k];
        float* block = base + MapMassGrid::blockOffset(i0);
        for (int a = 0; a < kSlots; ++a)
          for (std::size_t k = 0; k < len; ++k) block[a * kBlock + k] = block[a * kBlock + k] * 0.5f + add[k];
      }
    });
    benchmark::ClobberMemory();
  }
  setCells(state, n);
}

void BM_RefineGrid(benchmark::State& state)
{
  const int n = static_cast<int>(state.range(0));
  Scene scene(n);
  MapMassGrid out(scene.map.geometry());
  for (auto _ : state)
  {
    refineGrid(scene.scan, out);
    benchmark::ClobberMemory();
  }
  setCells(state, n);
}

void BM_CombineWithPriorGrid(benchmark::State& state)
{
  const int n = static_cast<int>(state.range(0));
  Scene scene(n);
  MapMassGrid sg;
  refineGrid(scene.scan, sg);
  for (auto _ : state)
  {
    combineWithPriorGrid(sg, scene.prior);
    benchmark::ClobberMemory();
  }
  setCells(state, n);
}

void BM_ContextualDiscountGrid(benchmark::State& state)
{
  const int n = static_cast<int>(state.range(0));
  Scene scene(n);
  const ContextualRates rates;
  for (auto _ : state)
  {
    contextualDiscountGrid(scene.map, rates);
    benchmark::ClobberMemory();
  }
  setCells(state, n);
}

void BM_ModifiedYagerGrid(benchmark::State& state)
{
  const int n = static_cast<int>(state.range(0));
  Scene scene(n);
  MapMassGrid sg;
  refineGrid(scene.scan, sg);
  combineWithPriorGrid(sg, scene.prior);
  MapMassGrid out(scene.map.geometry());
  std::vector<float> fo(scene.map.numCells()), of(scene.map.numCells());
  for (auto _ : state)
  {
    modifiedYagerGrid(scene.map, sg, out, fo.data(), of.data());
    benchmark::ClobberMemory();
  }
  setCells(state, n);
}

void BM_CounterSpecialiseGrid(benchmark::State& state)
{
  const int n = static_cast<int>(state.range(0));
  Scene scene(n);
  std::vector<float> fo(scene.map.numCells(), 0.05f), of(scene.map.numCells(), 0.0f);
  const CounterParams params;
  for (auto _ : state)
  {
    updateCounterAndSpecialiseGrid(scene.map, fo.data(), of.data(), params);
    benchmark::ClobberMemory();
  }
  setCells(state, n);
}

void BM_PignisticGrid(benchmark::State& state)
{
  const int n = static_cast<int>(state.range(0));
  Scene scene(n);
  PignisticPlanes out;
  for (auto _ : state)
  {
    pignisticGrid(scene.map, out);
    benchmark::ClobberMemory();
  }
  setCells(state, n);
}

}  // namespace

BENCHMARK(BM_FusionStep)->ArgsProduct({ { 200, 800 }, { 1, 2 } })->ArgNames({ "n", "threads" })->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_StreamBaseline)->ArgsProduct({ { 200, 800 }, { 1, 2 } })->ArgNames({ "n", "threads" })->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RefineGrid)->Arg(800)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CombineWithPriorGrid)->Arg(800)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ContextualDiscountGrid)->Arg(800)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ModifiedYagerGrid)->Arg(800)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CounterSpecialiseGrid)->Arg(800)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PignisticGrid)->Arg(800)->Unit(benchmark::kMillisecond);

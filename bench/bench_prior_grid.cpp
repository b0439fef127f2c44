// PriorGrid: the whole of Monaco (../shared/data/osm/monaco.osm.pbf, ~23,000 buildings) read, projected and
// rasterised at 0.5 m (target ≤ 3 s, ≤ 1 byte of prior per cell), its parts, and the window extraction the
// fusion asks for at every scan. Skipped, with a message, when the real data is absent.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <string>

#include "map_aided_fusion/core/prior_grid.hpp"
#include "map_aided_fusion/map_io/map_loader.hpp"

using namespace map_aided_fusion;

namespace {

constexpr double kResolution = 0.5;
const std::string kMonaco = std::string(MAF_PRIOR_SHARED_DATA_DIR) + "/osm/monaco.osm.pbf";

bool haveMonaco(benchmark::State& state)
{
  if (std::filesystem::exists(kMonaco)) return true;
  state.SkipWithError(("SKIPPED: real data " + kMonaco + " is absent").c_str());
  return false;
}

map_io::MapLoadParams monacoParams()
{
  map_io::MapLoadParams p;
  p.file = kMonaco;
  p.origin_latitude = 43.7384;  // Monaco-Ville
  p.origin_longitude = 7.4246;
  return p;
}

void BM_PriorMonacoLoadProjectRasterise(benchmark::State& state)
{
  if (!haveMonaco(state)) return;
  const map_io::MapLoadParams p = monacoParams();
  std::size_t cells = 0, bytes = 0, buildings = 0;
  for (auto _ : state)
  {
    const core::VectorMap m = map_io::loadVectorMap(p);
    const core::PriorGrid grid = core::PriorGrid::fromVectorMap(m, kResolution);
    benchmark::DoNotOptimize(grid.labels().data());
    cells = grid.geometry().numCells();
    bytes = grid.bytes();
    buildings = m.buildings.size();
  }
  state.counters["cells"] = static_cast<double>(cells);
  state.counters["bytes_per_cell"] = static_cast<double>(bytes) / static_cast<double>(cells);
  state.counters["buildings"] = static_cast<double>(buildings);
}
BENCHMARK(BM_PriorMonacoLoadProjectRasterise)->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_PriorMonacoLoadProject(benchmark::State& state)
{
  if (!haveMonaco(state)) return;
  const map_io::MapLoadParams p = monacoParams();
  for (auto _ : state)
  {
    const core::VectorMap m = map_io::loadVectorMap(p);
    benchmark::DoNotOptimize(m.buildings.data());
  }
}
BENCHMARK(BM_PriorMonacoLoadProject)->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_PriorMonacoRasterise(benchmark::State& state)
{
  if (!haveMonaco(state)) return;
  const core::VectorMap m = map_io::loadVectorMap(monacoParams());
  const core::GridGeometry g = core::PriorGrid::extentOf(m, kResolution);
  core::PriorGrid grid;
  for (auto _ : state)
  {
    grid.build(m, g);
    benchmark::DoNotOptimize(grid.labels().data());
  }
  state.counters["Mcells_per_s"] =
      benchmark::Counter(static_cast<double>(g.numCells()) * 1e-6, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_PriorMonacoRasterise)->Unit(benchmark::kMillisecond)->Iterations(3);

/// The prior of a 100 m × 100 m window at 0.5 m (200 × 200 cells) around the origin, as the fusion asks.
void BM_PriorFillWindow(benchmark::State& state)
{
  if (!haveMonaco(state)) return;
  const core::VectorMap m = map_io::loadVectorMap(monacoParams());
  const core::PriorCellTest test = state.range(1) != 0 ? core::PriorCellTest::kCoverage : core::PriorCellTest::kCentre;
  const core::PriorGrid grid = core::PriorGrid::fromVectorMap(m, kResolution, 0.0, nullptr, test);
  const bool aligned = state.range(0) != 0;
  const double offset = aligned ? 0.0 : 0.13;  // unaligned: per-cell centre sampling
  const core::GridGeometry w = core::GridGeometry::centred(100.0, 100.0, kResolution, offset, offset);
  const core::PriorConfidence beta;
  core::PriorWindow out;
  for (auto _ : state)
  {
    grid.fillWindow(w, beta, out);
    benchmark::DoNotOptimize(out.building.data());
  }
  state.counters["cells"] = static_cast<double>(w.numCells());
}
// Args: {aligned, cell test (0 centre, 1 coverage)}.
BENCHMARK(BM_PriorFillWindow)->Args({ 1, 0 })->Args({ 0, 0 })->Args({ 1, 1 })->Args({ 0, 1 })->Unit(benchmark::kMicrosecond);

}  // namespace

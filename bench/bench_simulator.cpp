// One simulated scan (ray casting + ground truth) on the town with N-beam lidars, and the fan cast alone.
#include <benchmark/benchmark.h>

#include "../test/sim/town_fixture.hpp"
#include "map_aided_fusion/sim/simulator.hpp"

using namespace map_aided_fusion::sim;

namespace {

Scenario benchScenario(const std::string& preset)
{
  Scenario sc;
  sc.duration = 60.0;
  sc.lidar = LidarParams::fromPreset(preset);
  sc.ego.route = { { -130.0, -1.5 }, { 1.75, -1.5 }, { 1.75, 78.25 }, { 80.0, 78.25 } };
  sc.ego.motion.speed = 8.0;
  for (int i = 0; i < 40; ++i)
  {
    ObjectSpec o;
    objectKindDefaults(i % 4 == 0 ? "pedestrian" : "car", o);
    o.id = static_cast<std::uint32_t>(i + 1);
    const double x = -140.0 + 7.0 * i;
    o.path = { { x, i % 2 ? 1.5 : -4.0 }, { x + 200.0, i % 2 ? 1.5 : -4.0 } };
    o.motion.speed = i % 3 == 0 ? 0.0 : 8.0;
    sc.objects.push_back(o);
  }
  return sc;
}

const char* presetOf(int beams) { return beams == 4 ? "ibeo4" : beams == 32 ? "vlp32" : "hdl64"; }

void BM_SimulateScan(benchmark::State& state)
{
  Simulator sim(benchScenario(presetOf(static_cast<int>(state.range(0)))), maf_test::townLikeMap());
  ScanFrame frame;
  int k = 0;
  std::size_t points = 0;
  for (auto _ : state)
  {
    sim.scan(k, frame);
    points += frame.points.size();
    k = (k + 7) % sim.numScans();
  }
  state.counters["points/scan"] = static_cast<double>(points) / static_cast<double>(state.iterations());
  state.counters["rays/s"] = benchmark::Counter(static_cast<double>(frame.rays) * state.iterations(),
                                                benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SimulateScan)->Arg(4)->Arg(32)->Arg(64)->Unit(benchmark::kMillisecond);

void BM_CastFan32(benchmark::State& state)
{
  Simulator sim(benchScenario("vlp32"), maf_test::townLikeMap());
  ScanFrame frame;
  sim.scan(100, frame);  // objects of t = 10 s in place
  const LidarParams& l = sim.scenario().lidar;
  std::vector<double> slopes, max_s;
  for (double e : l.elevations_deg)
  {
    slopes.push_back(std::tan(e * 3.14159265358979323846 / 180.0));
    max_s.push_back(l.max_range * std::cos(e * 3.14159265358979323846 / 180.0));
  }
  std::vector<BeamHit> hits(slopes.size());
  double az = 0.0;
  for (auto _ : state)
  {
    sim.scene().castFan(frame.lidar.x, frame.lidar.y, l.mount_z, az, slopes.data(), max_s.data(),
                        static_cast<int>(slopes.size()), hits.data());
    benchmark::DoNotOptimize(hits.data());
    az += 0.0035;
  }
  state.SetItemsProcessed(state.iterations() * static_cast<long>(slopes.size()));
}
BENCHMARK(BM_CastFan32);

}  // namespace

#ifdef MAF_SIM_BENCH_MAP_IO
#include <filesystem>

#include "map_aided_fusion/map_io/map_loader.hpp"

namespace {

/// One scan in Monaco (23 k buildings, ../shared/data): the acceleration grid on a real dense city.
void BM_SimulateScanMonaco(benchmark::State& state)
{
  const std::string path = std::string(MAF_SIM_SHARED_DATA_DIR) + "/osm/monaco.osm.pbf";
  if (!std::filesystem::exists(path))
  {
    state.SkipWithError("SKIPPED: ../shared/data/osm/monaco.osm.pbf is absent");
    return;
  }
  map_aided_fusion::map_io::MapLoadParams p;
  p.file = path;
  const auto map = map_aided_fusion::map_io::loadVectorMap(p);
  Scenario sc;
  sc.duration = 10.0;
  sc.lidar = LidarParams::fromPreset(presetOf(static_cast<int>(state.range(0))));
  const auto& line = map.road_lines[map.road_lines.size() / 2];
  sc.ego.route = line.points;
  sc.ego.motion.speed = 8.0;
  Simulator sim(sc, map);
  ScanFrame frame;
  int k = 0;
  for (auto _ : state)
  {
    sim.scan(k, frame);
    k = (k + 1) % sim.numScans();
  }
  state.counters["points/scan"] = static_cast<double>(frame.points.size());
}
BENCHMARK(BM_SimulateScanMonaco)->Arg(32)->Unit(benchmark::kMillisecond);

}  // namespace
#endif

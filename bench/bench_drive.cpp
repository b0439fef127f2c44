// MapGrid::update() on a realistic drive: 20 s through the simulator's town at 8 m/s with a 32-beam lidar and 40
// objects, each sweep turned into a ScanGrid by the ScanGridBuilder (so the scan observes what such a lidar sees, a
// few per cent of the window), with the town's PriorGrid, as the live default runs it (obstacle returns). Each
// repetition is the whole drive from an empty MapGrid. On average over the drive, with MapGridParams::skip_unchanged:
// skipped_share is the share of cells it left alone, observed_share that of the cells the scan observed (counted by
// blocks of MapMassGrid::kBlockCells) and changing_share the rest: cells the scan did not observe whose evidence still
// decays towards the prior's fixed point, so that the step changes their bits (BM_ScansToFixedPoint: for how long).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <map>
#include <memory>
#include <vector>

#include <Eigen/Geometry>

#include "../test/sim/town_fixture.hpp"
#include "map_aided_fusion/core/map_grid.hpp"
#include "map_aided_fusion/core/prior_grid.hpp"
#include "map_aided_fusion/core/prior_uncertainty.hpp"
#include "map_aided_fusion/core/scan_grid.hpp"
#include "map_aided_fusion/sim/simulator.hpp"
#include "window_params.hpp"

using namespace map_aided_fusion;
using namespace map_aided_fusion::core;

namespace {

constexpr double kDriveSeconds = 20.0;
constexpr double kPriorMargin = 100.0;  // m of prior around the town: the window stays inside it

/// One sweep of the drive, ready for MapGrid::update().
struct DriveScan
{
  ScanMassGrid scan;
  std::vector<float> obstacles;  // x, y pairs in base_link
  Pose2 pose;
  double time = 0.0;
};

struct Drive
{
  std::vector<DriveScan> scans;
  std::shared_ptr<PriorWindow> prior;
};

/// The drive at @p resolution (scan grid and prior), built once per resolution.
const Drive& drive(double resolution)
{
  static std::map<double, Drive> cache;
  auto it = cache.find(resolution);
  if (it != cache.end()) return it->second;
  sim::Scenario sc;
  sc.duration = kDriveSeconds;
  sc.lidar = sim::LidarParams::fromPreset("vlp32");
  sc.ego.route = { { -130.0, -1.5 }, { 1.75, -1.5 }, { 1.75, 78.25 }, { 80.0, 78.25 } };
  sc.ego.motion.speed = 8.0;
  for (int i = 0; i < 40; ++i)
  {
    sim::ObjectSpec o;
    sim::objectKindDefaults(i % 4 == 0 ? "pedestrian" : "car", o);
    o.id = static_cast<std::uint32_t>(i + 1);
    const double x = -140.0 + 7.0 * i;
    o.path = { { x, i % 2 ? 1.5 : -4.0 }, { x + 200.0, i % 2 ? 1.5 : -4.0 } };
    o.motion.speed = i % 3 == 0 ? 0.0 : 8.0;
    sc.objects.push_back(o);
  }
  const VectorMap map = maf_test::townLikeMap();
  sim::Simulator simulator(sc, map);
  Drive d;
  const PriorGrid grid = PriorGrid::fromVectorMap(map, resolution, kPriorMargin, nullptr, PriorCellTest::kCoverage);
  d.prior = std::make_shared<PriorWindow>();
  mapPrior(grid, grid.geometry(), PriorConfidence{}, PriorGridOptions{}, *d.prior);
  ScanGridParams sp;
  sp.grid_resolution = resolution;
  Eigen::Isometry3d mount = Eigen::Isometry3d::Identity();
  mount.translation() << sc.lidar.mount_x, sc.lidar.mount_y, sc.lidar.mount_z;
  ScanGridBuilder builder(sp, mount);
  sim::ScanFrame frame;
  for (int k = 0; k < simulator.numScans(); ++k)
  {
    simulator.scan(k, frame);
    DriveScan s;
    builder.build(PointCloudView::packed(frame.points.data(), frame.points.size(), sizeof(sim::LidarPoint)), s.scan);
    const ObstaclePoints o = builder.obstaclePoints();
    s.obstacles.assign(o.xy, o.xy + 2 * o.count);
    s.pose = Pose2{ frame.ego.x, frame.ego.y, frame.ego.yaw };
    s.time = frame.time;
    d.scans.push_back(std::move(s));
  }
  return cache.emplace(resolution, std::move(d)).first->second;
}

/// Args: N (cells per side: 200 at 0.5 m, 800 at 0.2 m), threads, skip_unchanged (0 or 1).
void BM_MapGridUpdateDrive(benchmark::State& state)
{
  const int n = static_cast<int>(state.range(0));
  const Drive& d = drive(maf_bench::windowResolution(n));
  MapGrid grid(maf_bench::windowParams(n, static_cast<int>(state.range(1)), state.range(2) != 0));
  std::size_t k = 0;
  double skipped = 0.0, observed = 0.0, changing = 0.0;
  StageTimes sum;
  for (auto _ : state)
  {
    const DriveScan& s = d.scans[k];
    const ObstaclePoints obstacles{ s.obstacles.data(), s.obstacles.size() / 2 };
    StageTimes t;
    grid.update(s.scan, s.pose, s.time, d.prior.get(), &t, &obstacles);
    sum.shift += t.shift;
    sum.project_scan += t.project_scan;
    sum.prior_window += t.prior_window;
    sum.fusion += t.fusion;
    skipped += grid.skippedShare();
    observed += grid.observedShare();
    changing += state.range(2) != 0 ? grid.changingShare() : 0.0;
    benchmark::ClobberMemory();
    if (++k == d.scans.size())
    {
      k = 0;
      state.PauseTiming();
      grid.reset();
      state.ResumeTiming();
    }
  }
  const double per_scan = 1.0 / static_cast<double>(std::max<std::int64_t>(1, state.iterations()));
  state.counters["skipped_share"] = skipped * per_scan;
  if (state.range(2) != 0)
  {
    state.counters["observed_share"] = observed * per_scan;
    state.counters["changing_share"] = changing * per_scan;
  }
  // Mean milliseconds per scan of each stage (as BM_MapGridUpdate's).
  state.counters["shift_ms"] = 1e3 * sum.shift * per_scan;
  state.counters["project_ms"] = 1e3 * sum.project_scan * per_scan;
  state.counters["prior_ms"] = 1e3 * sum.prior_window * per_scan;
  state.counters["fusion_ms"] = 1e3 * sum.fusion * per_scan;
  state.counters["scans"] = static_cast<double>(d.scans.size());
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(n) * n);
}

constexpr double kFixedPointWindow = 8.0;     // m: 16 × 16 cells at the paper's 0.5 m, every one alike
constexpr int kObservedScans = 10;            // scans that observe the cells first
constexpr int kMaxUnseenScans = 100000;       // scans without observation before giving up (a cycle, not a point)

/// A cell's history before it leaves the scan's view (Args of BM_ScansToFixedPoint).
enum FixedPointCase
{
  kFreeOnRoad,      ///< seen free on a mapped road
  kOccupiedOnRoad,  ///< seen occupied on a mapped road (a parked car)
  kOccupiedOnBuilding,  ///< seen occupied on a mapped building
  kFreeWithoutMap   ///< seen free, no prior
};

/// Scans without observation that the default profile's step computes after the last observation of a cell, before it
/// leaves the cell bit for bit so that MapGridParams::skip_unchanged skips it: the evidence decays towards the prior's
/// fixed point at the discounting's rates (alpha_static 0.02 per scan: 2 % of the distance a scan), and the float
/// steps stop changing only some ulps from it. The time measured is that of the whole history on a tiny window.
void BM_ScansToFixedPoint(benchmark::State& state)
{
  const auto history = static_cast<FixedPointCase>(state.range(0));
  MapGridParams params = maf_bench::windowParams(200, 1, true);
  params.size_x = params.size_y = kFixedPointWindow;
  params.recentre_distance = 0.25 * kFixedPointWindow;
  const GridGeometry g = GridGeometry::centred(kFixedPointWindow, kFixedPointWindow, params.resolution);
  const PriorConfidence beta;
  PriorWindow prior(GridGeometry::centred(2.0 * kFixedPointWindow, 2.0 * kFixedPointWindow, params.resolution));
  if (history != kFreeWithoutMap)
    std::fill_n((history == kOccupiedOnBuilding ? prior.building : prior.road).begin(), prior.building.size(),
                static_cast<float>(history == kOccupiedOnBuilding ? beta.beta_building : beta.beta_road));
  const ScanGridParams sp;
  ScanMassGrid observed(g), unseen(g);
  const MassSG seen = history == kFreeOnRoad || history == kFreeWithoutMap ?
                          MassSG{ { FrameSG::kF, sp.mu_free }, { FrameSG::kOmega, 1.0 - sp.mu_free } } :
                          MassSG{ { FrameSG::kO, sp.mu_occupied }, { FrameSG::kOmega, 1.0 - sp.mu_occupied } };
  for (std::size_t i = 0; i < observed.numCells(); ++i) observed.setCell(i, seen);
  const PriorWindow* const p = history == kFreeWithoutMap ? nullptr : &prior;
  int computed = 0;
  for (auto _ : state)
  {
    MapGrid grid(params);
    double t = 0.0;
    for (int k = 0; k < kObservedScans; ++k, t += 0.1) grid.update(observed, Pose2{}, t, p);
    computed = 0;
    for (; computed < kMaxUnseenScans; ++computed, t += 0.1)
    {
      grid.update(unseen, Pose2{}, t, p);
      if (grid.skippedShare() == 1.0) break;
    }
    benchmark::DoNotOptimize(grid.masses().planes());
  }
  state.counters["scans"] = computed;
}

}  // namespace

BENCHMARK(BM_ScansToFixedPoint)
    ->DenseRange(kFreeOnRoad, kFreeWithoutMap)
    ->ArgName("history")
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);

// One repetition is the whole drive (200 sweeps) from an empty grid.
BENCHMARK(BM_MapGridUpdateDrive)
    ->ArgsProduct({ { 200, 800 }, { 1, 2 }, { 0, 1 } })
    ->ArgNames({ "n", "threads", "skip" })
    ->Iterations(static_cast<std::int64_t>(kDriveSeconds * 10.0))
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

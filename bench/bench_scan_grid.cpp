// ScanGrid construction: a 64-beam-like cloud into a 160 m × 160 m grid at 0.2 m (BM_ScanGrid/points:N/threads:T;
// with the `planes` ground model and step ground consensus BM_ScanGridGround/points:N/threads:T, without the step
// BM_ScanGridGroundAlone; its deskewing at 15 m/s BM_Deskew/N), the
// paper's IBEO Alaska XT case (4 layers, ~800 points, 0.5 m cells; BM_ScanGridPaper/N), and the one-off
// cost of the geometry table (BM_ScanGridTable).
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "map_aided_fusion/core/deskew.hpp"
#include "map_aided_fusion/core/scan_grid.hpp"

using namespace map_aided_fusion::core;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr std::size_t kVelodyneStep = 22;  // x y z intensity (float32), ring (uint16), time (float32)
constexpr std::size_t kTimeOffset = 18;
constexpr double kSweepPeriod = 0.1;  // s, a 10 Hz spin: each column's time
constexpr double kSweepSpeed = 15.0;  // m/s, the ego's speed in BM_Deskew

struct Ray
{
  double elevation, azimuth;
};

/// Range along a ray from a sensor at height @p h over flat ground to a street-like scene: walls at
/// 18–32 m depending on azimuth, 6 m high; beyond them, or above them, no return (0, 0, 0).
void castRay(const Ray& ray, double h, float out[3])
{
  const double wall = 25.0 + 7.0 * std::sin(3.0 * ray.azimuth);
  const double wall_height = 6.0;
  const double ce = std::cos(ray.elevation), se = std::sin(ray.elevation);
  double horizontal = wall;
  double z = h + wall * se / ce;
  if (se < 0.0 && h / -se * ce < wall)
  {
    horizontal = h / -se * ce;
    z = 0.0;
  }
  if (z > wall_height)
  {
    out[0] = out[1] = out[2] = 0.0f;
    return;
  }
  out[0] = static_cast<float>(horizontal * std::cos(ray.azimuth));
  out[1] = static_cast<float>(horizontal * std::sin(ray.azimuth));
  out[2] = static_cast<float>(z - h);  // sensor frame
}

/// @p n points from @p beams beams (elevations lo … hi, degrees) over an azimuth span (radians), in a
/// Velodyne-style 22-byte layout.
std::vector<std::uint8_t> makeCloud(std::size_t n, int beams, double lo_deg, double hi_deg, double az_from,
                                    double az_span, double h)
{
  std::vector<std::uint8_t> buf(n * kVelodyneStep, 0);
  const std::size_t columns = (n + static_cast<std::size_t>(beams) - 1) / static_cast<std::size_t>(beams);
  for (std::size_t i = 0; i < n; ++i)
  {
    const int beam = static_cast<int>(i % static_cast<std::size_t>(beams));
    const std::size_t column = i / static_cast<std::size_t>(beams);
    const double el = (lo_deg + (hi_deg - lo_deg) * beam / std::max(1, beams - 1)) * kPi / 180.0;
    const double az = az_from + az_span * static_cast<double>(column) / static_cast<double>(columns);
    float xyz[3];
    castRay({ el, az }, h, xyz);
    std::memcpy(buf.data() + i * kVelodyneStep, xyz, sizeof xyz);
    const std::uint16_t ring = static_cast<std::uint16_t>(beam);
    std::memcpy(buf.data() + i * kVelodyneStep + 16, &ring, sizeof ring);
    const float time = static_cast<float>(kSweepPeriod * static_cast<double>(column) / static_cast<double>(columns));
    std::memcpy(buf.data() + i * kVelodyneStep + kTimeOffset, &time, sizeof time);
  }
  return buf;
}

Eigen::Isometry3d sensorAt(double x, double z)
{
  return Eigen::Isometry3d(Eigen::Translation3d(x, 0.0, z));
}

ScanGridParams spinningParams()
{
  ScanGridParams p;
  p.grid_resolution = 0.2;
  p.grid_size_x = 160.0;
  p.grid_size_y = 160.0;
  p.azimuth_resolution_deg = 0.2;
  p.max_range = 80.0;
  return p;
}

/// The 64-beam street cloud of @p state.range(0) points into the 160 m grid with @p ground_model, on
/// state.range(1) threads (ScanGridParams::threads).
void scanGrid(benchmark::State& state, const char* ground_model, bool consensus = true)
{
  const std::size_t n = static_cast<std::size_t>(state.range(0));
  const double h = 1.8;
  const auto cloud = makeCloud(n, 64, -25.0, 15.0, -kPi, 2.0 * kPi, h);
  ScanGridParams p = spinningParams();
  p.ground_model = ground_model;
  p.ground_consensus = consensus;
  p.threads = static_cast<int>(state.range(1));
  ScanGridBuilder builder(p, sensorAt(0.9, h));
  ScanMassGrid grid(builder.geometry());
  ScanGridStats st;
  const PointCloudView v = PointCloudView::packed(cloud.data(), n, kVelodyneStep);
  for (auto _ : state)
  {
    builder.build(v, grid, &st);
    benchmark::DoNotOptimize(grid.plane(FrameSG::kO));
  }
  state.counters["cells"] = static_cast<double>(grid.numCells());
  state.counters["occupied"] = static_cast<double>(st.occupied_cells);
  state.counters["free"] = static_cast<double>(st.free_cells);
  state.counters["zones_fitted"] = static_cast<double>(st.ground_fit.fitted);
  state.counters["points/s"] = benchmark::Counter(static_cast<double>(n), benchmark::Counter::kIsIterationInvariantRate);
}

void BM_ScanGrid(benchmark::State& state) { scanGrid(state, "flat"); }
BENCHMARK(BM_ScanGrid)->ArgsProduct({ { 0, 130000, 260000 }, { 1, 2 } })->ArgNames({ "points", "threads" })
    ->UseRealTime()->Unit(benchmark::kMillisecond);

void BM_ScanGridGround(benchmark::State& state) { scanGrid(state, "planes"); }
BENCHMARK(BM_ScanGridGround)->ArgsProduct({ { 130000 }, { 1, 2 } })->ArgNames({ "points", "threads" })
    ->UseRealTime()->Unit(benchmark::kMillisecond);

/// The `planes` model alone: without step ground consensus (which fits `zones` beside it).
void BM_ScanGridGroundAlone(benchmark::State& state) { scanGrid(state, "planes", false); }
BENCHMARK(BM_ScanGridGroundAlone)->ArgsProduct({ { 130000 }, { 1 } })->ArgNames({ "points", "threads" })
    ->UseRealTime()->Unit(benchmark::kMillisecond);

void BM_Deskew(benchmark::State& state)
{
  const std::size_t n = static_cast<std::size_t>(state.range(0));
  const auto cloud = makeCloud(n, 64, -25.0, 15.0, -kPi, 2.0 * kPi, 1.8);
  const PointCloudView v = PointCloudView::packed(cloud.data(), n, kVelodyneStep);
  const PointTimeField time{ kTimeOffset, TimeEncoding::kFloat32, 1.0, false, "time" };
  SweepMotion motion;
  motion.delta = Eigen::Isometry3d(Eigen::Translation3d(kSweepSpeed * kSweepPeriod, 0.0, 0.0)) *
                 Eigen::AngleAxisd(0.02, Eigen::Vector3d::UnitZ());
  motion.duration = kSweepPeriod;
  std::vector<float> out;
  PointCloudView deskewed;
  for (auto _ : state)
  {
    benchmark::DoNotOptimize(deskew(v, time, 0.0, motion, 2.0 * kSweepPeriod, out, deskewed));
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["points/s"] = benchmark::Counter(static_cast<double>(n), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_Deskew)->Arg(130000)->Unit(benchmark::kMillisecond);

void BM_ScanGridPaper(benchmark::State& state)
{
  const std::size_t n = static_cast<std::size_t>(state.range(0));
  const double h = 0.5;
  // IBEO Alaska XT at the front bumper: 4 layers over 3.2°, ~110° wide.
  const double span = 110.0 * kPi / 180.0;
  const auto cloud = makeCloud(n, 4, -1.6, 1.6, -0.5 * span, span, h);
  ScanGridParams p;  // config/ibeo/scan_grid.yaml: 100 m × 100 m at 0.5 m, 0.5° sectors, flat ground
  p.azimuth_resolution_deg = 0.5;
  p.ground_model = "flat";
  p.relative_height_limit = 0.0;
  ScanGridBuilder builder(p, sensorAt(3.5, h));
  ScanMassGrid grid(builder.geometry());
  ScanGridStats st;
  const PointCloudView v = PointCloudView::packed(cloud.data(), n, kVelodyneStep);
  for (auto _ : state)
  {
    builder.build(v, grid, &st);
    benchmark::DoNotOptimize(grid.plane(FrameSG::kO));
  }
  state.counters["cells"] = static_cast<double>(grid.numCells());
  state.counters["occupied"] = static_cast<double>(st.occupied_cells);
}
BENCHMARK(BM_ScanGridPaper)->Arg(800)->Unit(benchmark::kMicrosecond);

void BM_ScanGridTable(benchmark::State& state)
{
  ScanGridParams p = spinningParams();
  double x = 0.0;
  ScanGridBuilder builder(p, sensorAt(x, 1.8));
  for (auto _ : state)
  {
    x += 0.01;  // a moved sensor forces a new table
    builder.setSensorPose(sensorAt(x, 1.8));
    benchmark::DoNotOptimize(builder.tableBuilds());
  }
}
BENCHMARK(BM_ScanGridTable)->Unit(benchmark::kMillisecond);

}  // namespace

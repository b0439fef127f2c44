#include "map_aided_fusion/sim/lidar.hpp"

#include <algorithm>
#include <cmath>

#include "map_aided_fusion/core/parameters.hpp"

namespace map_aided_fusion {
namespace sim {

namespace {

constexpr double kFullTurnDeg = 360.0;
constexpr double kMaxElevationDeg = 89.0;
constexpr double kMaxRange = 1000.0;
constexpr double kMaxRate = 100.0;
constexpr double kMaxNoise = 10.0;
constexpr double kMaxMount = 50.0;
constexpr int kMaxRaysPerScan = 4'000'000;

const std::vector<double> kVlp32Elevations{ -25.0,  -15.639, -11.31, -8.843, -7.254, -6.148, -5.333, -4.667,
                                            -4.0,   -3.667,  -3.333, -3.0,   -2.667, -2.333, -2.0,   -1.667,
                                            -1.333, -1.0,    -0.667, -0.333, 0.0,    0.333,  0.667,  1.0,
                                            1.333,  1.667,   2.333,  3.333,  4.667,  7.0,    10.333, 15.0 };

std::vector<double> hdl32Elevations()
{
  constexpr int kBeams = 32;
  constexpr double kLowest = -30.67, kStep = 4.0 / 3.0;
  std::vector<double> e;
  for (int i = 0; i < kBeams; ++i) e.push_back(kLowest + i * kStep);
  return e;
}

std::vector<double> hdl64Elevations()
{
  constexpr int kBlock = 32;
  constexpr double kUpperTop = 2.0, kUpperStep = 1.0 / 3.0;
  constexpr double kLowerTop = -8.83, kLowerStep = 0.5;
  std::vector<double> e;
  for (int i = 0; i < kBlock; ++i) e.push_back(kUpperTop - i * kUpperStep);
  for (int i = 0; i < kBlock; ++i) e.push_back(kLowerTop - i * kLowerStep);
  std::sort(e.begin(), e.end());
  return e;
}

}  // namespace

int LidarParams::numAzimuths() const
{
  const double n = fov_deg / azimuth_resolution_deg;
  if (fov_deg >= kFullTurnDeg) return std::max(1, static_cast<int>(std::lround(n)));
  return static_cast<int>(std::floor(n + 1e-9)) + 1;
}

double LidarParams::azimuthDeg(int i) const
{
  if (fov_deg >= kFullTurnDeg) return -180.0 + i * azimuth_resolution_deg;
  return -0.5 * fov_deg + i * azimuth_resolution_deg;
}

void LidarParams::validate() const
{
  if (elevations_deg.empty()) throw core::ParameterError("lidar.elevations_deg", "needs at least one beam");
  for (double e : elevations_deg) core::requireInRange("lidar.elevations_deg", e, -kMaxElevationDeg, kMaxElevationDeg);
  if (!std::is_sorted(elevations_deg.begin(), elevations_deg.end()))
    throw core::ParameterError("lidar.elevations_deg", "must be ascending (ring 0 = lowest beam)");
  core::requireInRange("lidar.azimuth_resolution_deg", azimuth_resolution_deg, 1e-3, 90.0);
  core::requireInRange("lidar.fov_deg", fov_deg, 1e-3, kFullTurnDeg);
  core::requireInRange("lidar.max_range", max_range, 1e-2, kMaxRange);
  core::requireInRange("lidar.min_range", min_range, 0.0, max_range);
  core::requireInRange("lidar.range_noise_stddev", range_noise_stddev, 0.0, kMaxNoise);
  core::requireInRange("lidar.dropout_probability", dropout_probability, 0.0, 0.999);
  core::requireInRange("lidar.rate_hz", rate_hz, 0.1, kMaxRate);
  core::requireInRange("lidar.mount_x", mount_x, -kMaxMount, kMaxMount);
  core::requireInRange("lidar.mount_y", mount_y, -kMaxMount, kMaxMount);
  core::requireInRange("lidar.mount_z", mount_z, 0.01, kMaxMount);
  core::requireInRange("lidar.mount_yaw_deg", mount_yaw_deg, -kFullTurnDeg, kFullTurnDeg);
  if (static_cast<long>(numAzimuths()) * numBeams() > kMaxRaysPerScan)
    throw core::ParameterError("lidar.azimuth_resolution_deg", "more than 4e6 rays per scan");
}

LidarParams LidarParams::fromPreset(const std::string& name)
{
  LidarParams p;
  p.preset = name;
  if (name == "ibeo4")
  {
    p.elevations_deg = { -1.2, -0.4, 0.4, 1.2 };
    p.azimuth_resolution_deg = 0.5;
    p.fov_deg = 110.0;
    p.max_range = 80.0;
    p.range_noise_stddev = 0.04;
    p.mount_x = 3.7;
    p.mount_z = 0.5;
  }
  else if (name == "vlp32")
  {
    p.elevations_deg = kVlp32Elevations;
    p.azimuth_resolution_deg = 0.2;
    p.max_range = 100.0;
  }
  else if (name == "hdl32")
  {
    p.elevations_deg = hdl32Elevations();
    p.azimuth_resolution_deg = 0.16;
    p.max_range = 100.0;
    p.mount_x = 0.94;
    p.mount_z = 1.84;
  }
  else if (name == "hdl64")
  {
    p.elevations_deg = hdl64Elevations();
    p.azimuth_resolution_deg = 0.18;
    p.max_range = 120.0;
  }
  else
  {
    throw core::ParameterError("lidar.preset", "unknown preset '" + name + "' (ibeo4, vlp32, hdl32, hdl64)");
  }
  return p;
}

std::vector<std::string> lidarPresetNames() { return { "ibeo4", "vlp32", "hdl32", "hdl64" }; }

}  // namespace sim
}  // namespace map_aided_fusion

// The lidar presets against a real sweep: the nuScenes HDL-32E sweep of ../shared/data (skipped when the
// folder is absent): per ring, the median elevation of the returns must match the `hdl32` preset's beam,
// and ring 0 must be the lowest beam, as the simulator numbers them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <vector>

#include "map_aided_fusion/sim/lidar.hpp"

using namespace map_aided_fusion::sim;

namespace {
constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;
constexpr double kMinHorizontalRange = 3.0;  // m, ignore returns from the ego car itself
// deg: a real unit's calibrated beam angles differ from the nominal ones by up to ~0.3 deg (beams are 1.33 apart)
constexpr double kElevationTolerance = 0.4;
constexpr int kFloatsPerPoint = 5;
}  // namespace

TEST(SimRealData, Hdl32PresetMatchesTheNuScenesSweep)
{
  const std::string path = std::string(MAF_SHARED_DATA_DIR) + "/lidar/nuscenes_singapore_1532402927647951.bin";
  std::ifstream in(path, std::ios::binary);
  if (!in) GTEST_SKIP() << "real data not found (" << path << "): SKIPPED";
  std::vector<float> data;
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_EQ(bytes.size() % (kFloatsPerPoint * sizeof(float)), 0u);
  data.resize(bytes.size() / sizeof(float));
  std::memcpy(data.data(), bytes.data(), bytes.size());
  const std::size_t n = data.size() / kFloatsPerPoint;
  EXPECT_EQ(n, 34688u);

  std::map<int, std::vector<double>> per_ring;
  for (std::size_t i = 0; i < n; ++i)
  {
    const float* p = &data[i * kFloatsPerPoint];
    const double h = std::hypot(p[0], p[1]);
    if (h < kMinHorizontalRange) continue;
    per_ring[static_cast<int>(p[4])].push_back(std::atan2(p[2], h) * kRadToDeg);
  }
  const LidarParams hdl32 = LidarParams::fromPreset("hdl32");
  ASSERT_EQ(static_cast<int>(per_ring.size()), hdl32.numBeams());
  double worst = 0.0;
  for (auto& [ring, el] : per_ring)
  {
    ASSERT_GE(ring, 0);
    ASSERT_LT(ring, hdl32.numBeams());
    std::nth_element(el.begin(), el.begin() + static_cast<std::ptrdiff_t>(el.size() / 2), el.end());
    const double median = el[el.size() / 2];
    worst = std::max(worst, std::abs(median - hdl32.elevations_deg[static_cast<std::size_t>(ring)]));
    EXPECT_NEAR(median, hdl32.elevations_deg[static_cast<std::size_t>(ring)], kElevationTolerance) << "ring " << ring;
  }
  std::printf("[ real data ] %zu points, 32 rings, worst |median elevation - hdl32 preset| = %.3f deg\n", n, worst);
}

// The ScanGrid's ground models on the real KITTI 00 frames with SemanticKITTI labels (SKIPPED without
// ../shared/data): the road ahead must stay free and parked cars occupied, with the `planes` model no worse than
// the flat one. Road cells: cells ahead holding road returns and no return of an object (the motorcyclist).
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "map_aided_fusion/core/profiles.hpp"
#include "map_aided_fusion/core/scan_grid.hpp"
#include "map_aided_fusion/dataset/kitti.hpp"

namespace fs = std::filesystem;
using namespace map_aided_fusion;

namespace {

constexpr double kLidarHeight = 1.73;      // m, KITTI's HDL-64E above the ground
constexpr std::uint16_t kRoad = 40;        // SemanticKITTI road
constexpr std::uint16_t kCar = 10;         // SemanticKITTI car (parked: the labelled frames hold no moving car)
constexpr float kAheadMin = 3.0f, kAheadMax = 30.0f, kAheadHalfWidth = 4.0f;  // m, "the road ahead"

struct Score
{
  std::size_t road_cells = 0, road_free = 0, road_occupied = 0;
  std::size_t car_cells = 0, car_occupied = 0;
  core::GroundFitStats fit;
};

Score score(const dataset::KittiSequence& s, std::size_t frame, const std::string& model)
{
  core::ScanGridParams p;  // config/scan_grid.yaml's values
  p.ground_model = model;
  Eigen::Isometry3d lidar = Eigen::Isometry3d::Identity();
  lidar.translation().z() = kLidarHeight;
  core::ScanGridBuilder builder(p, lidar);
  const std::vector<dataset::KittiPoint> pts = s.readScan(frame);
  const std::vector<std::uint32_t> labels = s.readLabels(frame, pts.size());
  core::ScanMassGrid grid;
  core::ScanGridStats st;
  EXPECT_TRUE(builder.build(core::PointCloudView::packed(pts.data(), pts.size(), sizeof(dataset::KittiPoint)), grid, &st));
  const core::GridGeometry& g = builder.geometry();
  std::vector<std::uint8_t> road(g.numCells(), 0), car(g.numCells(), 0), object(g.numCells(), 0);
  for (std::size_t i = 0; i < pts.size(); ++i)
  {
    const float x = pts[i].x, y = pts[i].y, z = pts[i].z + static_cast<float>(kLidarHeight);
    const core::CellIndex c = g.cellAt(core::Point2{ x, y });
    if (!g.contains(c)) continue;
    const std::uint16_t cls = dataset::semanticClass(labels[i]);
    if (cls == kRoad && x >= kAheadMin && x <= kAheadMax && std::abs(y) <= kAheadHalfWidth) road[g.index(c)] = 1;
    const bool in_band = z >= p.obstacle_min_height && z <= p.obstacle_max_height;
    if (cls == kCar && in_band) car[g.index(c)] = 1;
    if (in_band && cls > dataset::kClassOutlier && !dataset::isGroundClass(cls)) object[g.index(c)] = 1;
  }
  Score out;
  out.fit = st.ground_fit;
  const float* f = grid.plane(core::FrameSG::kF);
  const float* o = grid.plane(core::FrameSG::kO);
  for (std::size_t i = 0; i < g.numCells(); ++i)
  {
    if (road[i] && !object[i])
    {
      ++out.road_cells;
      out.road_free += f[i] > 0.0f;
      out.road_occupied += o[i] > 0.0f;
    }
    if (car[i])
    {
      ++out.car_cells;
      out.car_occupied += o[i] > 0.0f;
    }
  }
  return out;
}

/// The shared KITTI 00 frames; prints SKIPPED when they are absent.
fs::path kitti00()
{
  const fs::path dir = fs::path(MAF_SHARED_DATA_DIR) / "lidar" / "kitti_00";
  if (!fs::exists(dir / "times.txt")) std::printf("SKIPPED: %s is absent\n", dir.string().c_str());
  return dir;
}

}  // namespace

TEST(KittiGround, PlanesKeepTheRoadAheadFreeAndParkedCarsOccupied)
{
  const fs::path dir = kitti00();
  if (!fs::exists(dir / "times.txt")) GTEST_SKIP() << dir << " is absent";
  const dataset::KittiSequence s(dir.string());
  ASSERT_GE(s.labelledFrames(), 1u);
  for (std::size_t k = 0; k < s.size(); ++k)
  {
    if (!s.hasLabels(k)) continue;
    const Score flat = score(s, k, "flat");
    const Score planes = score(s, k, "planes");
    std::printf("[ INFO     ] KITTI frame %zu: road ahead free %zu/%zu (flat) %zu/%zu (planes), occupied %zu / %zu; "
                "parked-car cells occupied %zu/%zu (flat) %zu/%zu (planes); zones fitted %zu/%zu\n",
                k, flat.road_free, flat.road_cells, planes.road_free, planes.road_cells, flat.road_occupied,
                planes.road_occupied, flat.car_occupied, flat.car_cells, planes.car_occupied, planes.car_cells,
                planes.fit.fitted, planes.fit.zones);
    ASSERT_GT(planes.road_cells, 100u);
    ASSERT_GT(planes.car_cells, 50u);
    EXPECT_GE(static_cast<double>(planes.road_free), 0.95 * static_cast<double>(planes.road_cells)) << k;
    EXPECT_GE(planes.road_free + planes.road_cells / 100, flat.road_free) << k;
    EXPECT_GE(planes.car_occupied + planes.car_cells / 50, flat.car_occupied) << k;
    EXPECT_FALSE(planes.fit.flat_fallback);
  }
}

TEST(KittiGround, TheDefaultSelfBoxHoldsTheCarsOwnBonnet)
{
  // KITTI's lidar sees its own car's bonnet 2.5 m ahead, 0.8 m above the ground, on most sweeps: returns that move
  // with the vehicle, which the tracker would call a moving object. The default self box must reject them.
  const fs::path dir = kitti00();
  if (!fs::exists(dir / "times.txt")) GTEST_SKIP() << dir << " is absent";
  const dataset::KittiSequence s(dir.string());
  constexpr float kBonnetMin = 2.3f, kBonnetMax = 2.7f, kBonnetHalfWidth = 0.7f;  // m, lidar frame
  constexpr float kBonnetLow = 0.6f, kBonnetHigh = 1.0f;                             // m above the ground
  core::ScanGridParams p = core::defaultProfile().scan_grid;
  Eigen::Isometry3d lidar = Eigen::Isometry3d::Identity();
  lidar.translation().z() = kLidarHeight;
  core::ScanGridBuilder builder(p, lidar);
  std::size_t sweeps_with_bonnet = 0, occupied_on_bonnet = 0;
  for (std::size_t k = 0; k < s.size(); ++k)
  {
    const std::vector<dataset::KittiPoint> pts = s.readScan(k);
    std::size_t bonnet = 0;
    for (const dataset::KittiPoint& q : pts)
    {
      const float z = q.z + static_cast<float>(kLidarHeight);
      bonnet += q.x >= kBonnetMin && q.x <= kBonnetMax && std::abs(q.y) <= kBonnetHalfWidth && z >= kBonnetLow &&
                z <= kBonnetHigh;
    }
    sweeps_with_bonnet += bonnet > 0;
    core::ScanMassGrid grid;
    ASSERT_TRUE(builder.build(core::PointCloudView::packed(pts.data(), pts.size(), sizeof(dataset::KittiPoint)), grid));
    const core::GridGeometry& g = builder.geometry();
    const float* o = grid.plane(core::FrameSG::kO);
    for (float x = kBonnetMin; x <= kBonnetMax; x += static_cast<float>(g.resolution) / 2)
      for (float y = -kBonnetHalfWidth; y <= kBonnetHalfWidth; y += static_cast<float>(g.resolution) / 2)
      {
        const core::CellIndex c = g.cellAt(core::Point2{ x, y });
        occupied_on_bonnet += g.contains(c) && o[g.index(c)] > 0.0f;
      }
  }
  std::printf("[ INFO     ] KITTI 00: %zu of %zu sweeps hold bonnet returns\n", sweeps_with_bonnet, s.size());
  EXPECT_GE(sweeps_with_bonnet, s.size() / 2) << "the data holds the car's own returns";
  EXPECT_EQ(occupied_on_bonnet, 0u) << "the default self box rejects them";
}

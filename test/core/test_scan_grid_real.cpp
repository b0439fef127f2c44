// ScanGrid sensor model on real lidar data from ../shared/data/lidar (skipped when the folder is absent).
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "map_aided_fusion/core/scan_grid.hpp"

using namespace map_aided_fusion::core;

namespace {

const std::string kLidarDir = std::string(MAF_SHARED_DATA_DIR) + "/lidar";
const std::string kNuscenesBin = kLidarDir + "/nuscenes_singapore_1532402927647951.bin";
const std::string kNuscenesJson = kLidarDir + "/nuscenes_singapore_1532402927647951.json";
const std::string kOrganizedPcd = kLidarDir + "/organized_64x1024_no_pose.pcd";

constexpr std::size_t kNuscenesFloatsPerPoint = 5;  // x, y, z, intensity, ring
constexpr std::size_t kMinBoxPoints = 10;
constexpr double kNearRadius = 5.0;  // m around the vehicle (ego origin)

bool exists(const std::string& path) { return std::ifstream(path).good(); }

std::vector<float> readFloats(const std::string& path)
{
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  const std::streamsize bytes = in.tellg();
  in.seekg(0);
  std::vector<float> v(static_cast<std::size_t>(bytes) / sizeof(float));
  in.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(v.size() * sizeof(float)));
  return v;
}

Eigen::Isometry3d readMatrix(const YAML::Node& node)
{
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m(r, c) = node[r][c].as<double>();
  Eigen::Isometry3d t;
  t.matrix() = m;
  return t;
}

struct Box
{
  double x, y, dx, dy, yaw;  // lidar frame
  std::size_t points;
  std::string label;
  /// True when the lidar-frame point (px, py) lies in the footprint.
  bool contains(double px, double py) const
  {
    const double c = std::cos(yaw), s = std::sin(yaw);
    const double lx = c * (px - x) + s * (py - y);
    const double ly = -s * (px - x) + c * (py - y);
    return std::abs(lx) <= 0.5 * dx && std::abs(ly) <= 0.5 * dy;
  }
};

/// The ScanGrid parameters of the checks: defaults except 0.2 m cells (pedestrians are 0.6 m wide).
ScanGridParams realParams()
{
  ScanGridParams p;
  p.grid_resolution = 0.2;
  p.grid_size_x = 100.0;
  p.grid_size_y = 100.0;
  return p;
}

/// The nuScenes ego vehicle (Renault Zoe, 4.1 m × 1.7 m, ego origin on the rear axle) with a margin: the
/// sweep holds a few hundred returns from its own body.
void setNuscenesSelfBox(ScanGridParams& p)
{
  p.self_box_min_x = -1.0;
  p.self_box_max_x = 3.5;
  p.self_box_min_y = -1.0;
  p.self_box_max_y = 1.0;
}

}  // namespace

TEST(ScanGridReal, NuscenesBoxesAreOccupiedAndTheSurroundingsFree)
{
  if (!exists(kNuscenesBin) || !exists(kNuscenesJson))
    GTEST_SKIP() << "SKIPPED: real data not found in " << kLidarDir;
  const std::vector<float> raw = readFloats(kNuscenesBin);
  ASSERT_EQ(raw.size() % kNuscenesFloatsPerPoint, 0u);
  const std::size_t n = raw.size() / kNuscenesFloatsPerPoint;
  ASSERT_EQ(n, 34688u);
  const YAML::Node meta = YAML::LoadFile(kNuscenesJson);
  const Eigen::Isometry3d lidar_to_ego = readMatrix(meta["lidar2ego"]);
  std::vector<Box> boxes;
  for (const auto& b : meta["boxes"])
  {
    const YAML::Node bb = b["bbox_3d"];
    boxes.push_back({ bb[0].as<double>(), bb[1].as<double>(), bb[3].as<double>(), bb[4].as<double>(),
                      bb[6].as<double>(), b["num_lidar_pts"].as<std::size_t>(), b["label"].as<std::string>() });
  }
  ASSERT_EQ(boxes.size(), 69u);

  for (const char* model : { "flat", "planes" })
  {
    SCOPED_TRACE(model);
    std::cout << "[ INFO     ] ground_model " << model << "\n";
    ScanGridParams params = realParams();
    setNuscenesSelfBox(params);
    params.ground_model = model;
    ScanGridBuilder builder(params, lidar_to_ego);
    ScanMassGrid grid;
    ScanGridStats st;
    ASSERT_TRUE(builder.build(
        PointCloudView::packed(raw.data(), n, kNuscenesFloatsPerPoint * sizeof(float)), grid, &st));
    std::cout << "[ INFO     ] nuScenes sweep: " << st.points << " points, ground " << st.ground << ", obstacle "
              << st.obstacle << ", self " << st.self_returns << ", below ground " << st.below_ground << ", gap " << st.height_gap
              << ", above clearance " << st.above_clearance << ", rejected " << st.rejected() << " (min range "
              << st.below_min_range << ", max range " << st.beyond_max_range << "); cells occupied "
              << st.occupied_cells << ", free " << st.free_cells << std::endl;

    const GridGeometry& g = grid.geometry();
    const Eigen::Isometry3d ego_to_lidar = lidar_to_ego.inverse();
    const float* m_o = grid.plane(FrameSG::kO);
    const float* m_f = grid.plane(FrameSG::kF);
    const float occupied_threshold = static_cast<float>(params.mu_occupied) - 1e-6f;
    std::vector<char> covered(g.numCells(), 0);
    std::size_t checked = 0, hit = 0;
    for (const Box& box : boxes)
    {
      bool box_hit = false;
      for (int y = 0; y < g.height; ++y)
        for (int x = 0; x < g.width; ++x)
        {
          const Point2 c = g.cellCentre({ x, y });
          const Eigen::Vector3d l = ego_to_lidar * Eigen::Vector3d(c.x, c.y, 0.0);
          if (!box.contains(l.x(), l.y())) continue;
          covered[g.index(x, y)] = 1;
          if (m_o[g.index(x, y)] >= occupied_threshold) box_hit = true;
        }
      if (box.points < kMinBoxPoints) continue;
      ++checked;
      hit += box_hit;
      if (!box_hit)
        std::cout << "[ INFO     ] box without an occupied cell: " << box.label << " with " << box.points
                  << " points at (" << box.x << ", " << box.y << ") in the lidar frame" << std::endl;
    }
    ASSERT_GT(checked, 0u);
    const double hit_rate = static_cast<double>(hit) / static_cast<double>(checked);
    std::cout << "[ INFO     ] boxes with >= " << kMinBoxPoints << " points: " << checked << ", with an occupied cell "
              << hit << " (" << 100.0 * hit_rate << " %)" << std::endl;
    EXPECT_GE(hit_rate, 0.9);

    std::size_t near = 0, near_free = 0, near_occupied = 0;
    for (int y = 0; y < g.height; ++y)
      for (int x = 0; x < g.width; ++x)
      {
        const Point2 c = g.cellCentre({ x, y });
        const std::size_t i = g.index(x, y);
        if (std::hypot(c.x, c.y) > kNearRadius || covered[i]) continue;
        ++near;
        near_free += m_f[i] > 0.0f;
        near_occupied += m_o[i] > 0.0f;
      }
    const double free_rate = static_cast<double>(near_free) / static_cast<double>(near);
    std::cout << "[ INFO     ] cells within " << kNearRadius << " m not covered by a box: " << near << ", free "
              << near_free << " (" << 100.0 * free_rate << " %), occupied " << near_occupied << std::endl;
    EXPECT_GE(free_rate, 0.9);
    EXPECT_GT(st.self_returns, 0u);

  }
}

TEST(ScanGridReal, OrganizedScanNoReturnPointsNeverOccupyTheSensorCell)
{
  if (!exists(kOrganizedPcd)) GTEST_SKIP() << "SKIPPED: real data not found in " << kLidarDir;
  std::ifstream in(kOrganizedPcd);
  std::string line;
  std::size_t width = 0, height = 0;
  while (std::getline(in, line))
  {
    std::istringstream ls(line);
    std::string key;
    ls >> key;
    if (key == "WIDTH") ls >> width;
    if (key == "HEIGHT") ls >> height;
    if (key == "DATA") break;
  }
  ASSERT_EQ(width, 1024u);
  ASSERT_EQ(height, 64u);
  struct Pt
  {
    float x, y, z, intensity;
  };
  std::vector<Pt> pts(width * height);
  std::size_t zeros = 0;
  for (auto& p : pts)
  {
    ASSERT_TRUE(static_cast<bool>(in >> p.x >> p.y >> p.z >> p.intensity));
    zeros += p.x == 0.0f && p.y == 0.0f && p.z == 0.0f;
  }
  PointCloudView organized;
  organized.data = reinterpret_cast<const std::uint8_t*>(pts.data());
  organized.width = width;
  organized.height = height;
  organized.point_step = sizeof(Pt);
  organized.row_step = width * sizeof(Pt);

  // No pose: the sensor frame is base_link, the ground ~1.8 m below. With no min range, a (0, 0, 0)
  // point taken as a return would be an obstacle (z = 0 is in the band [−1.5, 0.7]) in the sensor's cell.
  for (const char* model : { "flat", "planes" })
  {
    SCOPED_TRACE(model);
    std::cout << "[ INFO     ] ground_model " << model << "\n";
    ScanGridParams params = realParams();
    params.min_range = 0.0;
    params.ground_height = -1.8;
    params.ground_model = model;
    ScanGridBuilder builder(params, Eigen::Isometry3d::Identity());
    ScanMassGrid grid;
    ScanGridStats st;
    ASSERT_TRUE(builder.build(organized, grid, &st));
    std::cout << "[ INFO     ] organized scan: " << st.points << " points, (0,0,0) " << st.no_return
              << ", non-finite " << st.non_finite << ", ground " << st.ground << ", obstacle " << st.obstacle
              << "; cells occupied " << st.occupied_cells << ", free " << st.free_cells << std::endl;
    EXPECT_GT(zeros, 0u);
    EXPECT_EQ(st.no_return, zeros);
    EXPECT_GT(st.occupied_cells, 0u);
    const GridGeometry& g = grid.geometry();
    std::size_t near_occupied = 0;
    for (int y = 0; y < g.height; ++y)
      for (int x = 0; x < g.width; ++x)
      {
        const Point2 c = g.cellCentre({ x, y });
        if (std::hypot(c.x, c.y) <= 1.0 && grid.plane(FrameSG::kO)[g.index(x, y)] > 0.0f) ++near_occupied;
      }
    EXPECT_EQ(near_occupied, 0u);
  }
}

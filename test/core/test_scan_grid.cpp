// ScanGrid sensor model on synthetic scans with hand-computed expected cells.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "map_aided_fusion/core/scan_grid.hpp"

using namespace map_aided_fusion::core;

namespace {

struct P
{
  float x, y, z;
};

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr double kPi = 3.14159265358979323846;

/// 40 m × 40 m at 0.5 m (80 × 80 cells, origin (−20, −20)), 1° sectors, no min range, sensor at the origin.
ScanGridParams testParams()
{
  ScanGridParams p;
  p.grid_resolution = 0.5;
  p.grid_size_x = 40.0;
  p.grid_size_y = 40.0;
  p.azimuth_resolution_deg = 1.0;
  p.min_range = 0.0;
  p.max_range = 30.0;
  p.ground_height = 0.0;
  p.ground_tolerance = 0.2;
  p.obstacle_min_height = 0.3;
  p.obstacle_max_height = 2.5;
  p.mu_free = 0.7;
  p.mu_occupied = 0.8;
  p.relative_height_limit = 0.0;  // the paper's sensor model; the steps have their own tests
  p.ambiguous_unknown = false;
  p.ground_consensus = false;
  p.ground_model = "flat";
  return p;
}

PointCloudView view(const std::vector<P>& pts) { return PointCloudView::packed(pts.data(), pts.size(), sizeof(P)); }

/// Wall of obstacle returns at x = 10.25 m, y ∈ [−4.99, 5.01] every 5 cm, z = 1 m.
std::vector<P> wall()
{
  std::vector<P> pts;
  for (int k = -100; k <= 100; ++k) pts.push_back({ 10.25f, 0.05f * k + 0.01f, 1.0f });
  return pts;
}

struct Cell
{
  float f, o, omega, empty;
};

Cell at(const ScanMassGrid& g, int x, int y)
{
  const std::size_t i = g.geometry().index(x, y);
  return { g.plane(FrameSG::kF)[i], g.plane(FrameSG::kO)[i], g.plane(FrameSG::kOmega)[i],
           g.plane(FrameSG::kEmpty)[i] };
}

void expectFree(const ScanMassGrid& g, int x, int y, float mu = 0.7f)
{
  const Cell c = at(g, x, y);
  EXPECT_FLOAT_EQ(c.f, mu) << "cell " << x << "," << y;
  EXPECT_FLOAT_EQ(c.o, 0.0f) << "cell " << x << "," << y;
  EXPECT_FLOAT_EQ(c.omega, 1.0f - mu) << "cell " << x << "," << y;
}

void expectOccupied(const ScanMassGrid& g, int x, int y, float mu = 0.8f)
{
  const Cell c = at(g, x, y);
  EXPECT_FLOAT_EQ(c.f, 0.0f) << "cell " << x << "," << y;
  EXPECT_FLOAT_EQ(c.o, mu) << "cell " << x << "," << y;
  EXPECT_FLOAT_EQ(c.omega, 1.0f - mu) << "cell " << x << "," << y;
}

void expectUnknown(const ScanMassGrid& g, int x, int y)
{
  const Cell c = at(g, x, y);
  EXPECT_EQ(c.f, 0.0f) << "cell " << x << "," << y;
  EXPECT_EQ(c.o, 0.0f) << "cell " << x << "," << y;
  EXPECT_EQ(c.omega, 1.0f) << "cell " << x << "," << y;
}

std::size_t countAbove(const ScanMassGrid& g, Subset a, float threshold)
{
  std::size_t n = 0;
  for (std::size_t i = 0; i < g.numCells(); ++i) n += g.plane(a)[i] > threshold;
  return n;
}

bool samePlanes(const ScanMassGrid& a, const ScanMassGrid& b)
{
  if (a.geometry() != b.geometry()) return false;
  for (Subset s = 0; s < FrameSG::kNumSubsets; ++s)
    if (std::memcmp(a.plane(s), b.plane(s), a.numCells() * sizeof(float)) != 0) return false;
  return true;
}

}  // namespace

TEST(ScanGrid, WallGivesFreeBeforeOccupiedAtAndUnknownBehind)
{
  ScanGridBuilder builder(testParams(), Eigen::Isometry3d::Identity());
  ScanMassGrid grid;
  ScanGridStats st;
  const auto pts = wall();
  ASSERT_TRUE(builder.build(view(pts), grid, &st));
  ASSERT_EQ(grid.geometry().width, 80);
  ASSERT_EQ(grid.geometry().origin_x, -20.0);
  // Row 40 spans y ∈ [0, 0.5]; the wall (x = 10.25) lies in column 60.
  const int row = 40;
  for (int x = 41; x < 60; ++x) expectFree(grid, x, row);
  expectOccupied(grid, 60, row);
  for (int x = 61; x < 80; ++x) expectUnknown(grid, x, row);
  // Cell (40, 40), centre (0.25, 0.25), looks at 45°: outside the wall's ±26°, nothing seen.
  expectUnknown(grid, 40, row);
  // Behind the sensor nothing is known.
  for (int x = 0; x < 40; ++x) expectUnknown(grid, x, row);
  // Occupied: exactly column 60, rows 30 (y = −5) … 50 (y = 5).
  EXPECT_EQ(st.occupied_cells, 21u);
  EXPECT_EQ(countAbove(grid, FrameSG::kO, 0.0f), 21u);
  for (int y = 30; y <= 50; ++y) expectOccupied(grid, 60, y);
  EXPECT_EQ(st.obstacle, 201u);
  EXPECT_EQ(st.rejected(), 0u);
  EXPECT_EQ(st.free_cells, countAbove(grid, FrameSG::kF, 0.0f));
  for (std::size_t i = 0; i < grid.numCells(); ++i)
  {
    const float sum = grid.plane(FrameSG::kF)[i] + grid.plane(FrameSG::kO)[i] + grid.plane(FrameSG::kOmega)[i];
    ASSERT_NEAR(sum, 1.0f, 1e-6f);
    ASSERT_EQ(grid.plane(FrameSG::kEmpty)[i], 0.0f);
  }
}

TEST(ScanGrid, GroundOnlyScanGivesFreeDisc)
{
  ScanGridBuilder builder(testParams(), Eigen::Isometry3d::Identity());
  std::vector<P> pts;
  const double radius = 8.0;
  for (int k = 0; k < 720; ++k)
  {
    const double a = (k + 0.5) * kPi / 360.0;  // every 0.5°, never on a sector boundary
    pts.push_back({ static_cast<float>(radius * std::cos(a)), static_cast<float>(radius * std::sin(a)), 0.05f });
  }
  ScanMassGrid grid;
  ScanGridStats st;
  ASSERT_TRUE(builder.build(view(pts), grid, &st));
  EXPECT_EQ(st.ground, 720u);
  EXPECT_EQ(st.obstacle, 0u);
  EXPECT_EQ(st.occupied_cells, 0u);
  std::size_t checked = 0;
  const GridGeometry& g = grid.geometry();
  for (int y = 0; y < g.height; ++y)
    for (int x = 0; x < g.width; ++x)
    {
      const Point2 c = g.cellCentre({ x, y });
      const double r = std::hypot(c.x, c.y);
      if (std::abs(r - radius) < 1e-3) continue;
      if (r < radius)
        expectFree(grid, x, y);
      else
        expectUnknown(grid, x, y);
      ++checked;
    }
  EXPECT_GT(checked, 6000u);
  // π·8² / 0.25 ≈ 804 cells.
  EXPECT_NEAR(static_cast<double>(st.free_cells), kPi * radius * radius / 0.25, 30.0);
}

TEST(ScanGrid, PoleOnSectorBoundaryIsMarked)
{
  ScanGridBuilder builder(testParams(), Eigen::Isometry3d::Identity());
  // 30° is a sector boundary (sectors start at −180° every 1°).
  const float px = 7.9f;
  const float py = static_cast<float>(7.9 * std::tan(30.0 * kPi / 180.0));
  std::vector<P> pts;
  for (int k = 0; k < 5; ++k) pts.push_back({ px, py, 0.5f + 0.4f * k });
  ScanMassGrid grid;
  ScanGridStats st;
  ASSERT_TRUE(builder.build(view(pts), grid, &st));
  CellIndex c;
  ASSERT_TRUE(grid.geometry().worldToCell({ px, py }, c));
  expectOccupied(grid, c.x, c.y);
  EXPECT_EQ(st.occupied_cells, 1u);
  EXPECT_EQ(countAbove(grid, FrameSG::kO, 0.0f), 1u);
  // The pole bounds the free space of its sector: a cell halfway along the ray is free.
  const int s = builder.sectorOf(px, py);
  CellIndex mid;
  ASSERT_TRUE(grid.geometry().worldToCell({ 0.5 * px, 0.5 * py }, mid));
  const Point2 mc = grid.geometry().cellCentre(mid);
  if (builder.sectorOf(mc.x, mc.y) == s) expectFree(grid, mid.x, mid.y);
}

TEST(ScanGrid, ThinPoleInCoarseSectorsStillMarksItsCell)
{
  ScanGridParams p = testParams();
  p.azimuth_resolution_deg = 10.0;  // a sector is much wider than the pole
  ScanGridBuilder builder(p, Eigen::Isometry3d::Identity());
  // A single return in a corner of a cell whose centre lies in the neighbouring sector.
  const std::vector<P> pts{ { 10.01f, 1.99f, 1.0f } };  // 11.2°: sector [10°, 20°); cell centre (10.25, 1.75) 9.7°
  ASSERT_NE(builder.sectorOf(10.01, 1.99), builder.sectorOf(10.25, 1.75));
  ScanMassGrid grid;
  ScanGridStats st;
  ASSERT_TRUE(builder.build(view(pts), grid, &st));
  expectOccupied(grid, 60, 43);
  EXPECT_EQ(st.occupied_cells, 1u);
}

TEST(ScanGrid, NoReturnAndNonFinitePointsAreIgnoredAndCounted)
{
  ScanGridBuilder builder(testParams(), Eigen::Isometry3d::Identity());
  const auto clean = wall();
  auto dirty = clean;
  for (int k = 0; k < 50; ++k) dirty.push_back({ 0.0f, 0.0f, 0.0f });
  dirty.push_back({ kNaN, 1.0f, 1.0f });
  dirty.push_back({ 1.0f, kNaN, 1.0f });
  dirty.push_back({ 1.0f, 1.0f, kNaN });
  dirty.push_back({ kInf, 0.0f, 1.0f });
  dirty.push_back({ 0.0f, -kInf, 1.0f });
  ScanMassGrid a, b;
  ScanGridStats sa, sb;
  ASSERT_TRUE(builder.build(view(clean), a, &sa));
  ASSERT_TRUE(builder.build(view(dirty), b, &sb));
  EXPECT_EQ(sb.no_return, 50u);
  EXPECT_EQ(sb.non_finite, 5u);
  EXPECT_EQ(sb.rejected(), 55u);
  EXPECT_EQ(sb.points, clean.size() + 55u);
  EXPECT_TRUE(samePlanes(a, b));
  // With no min range, (0, 0, 0) would sit in cell (40, 40): it must not be occupied.
  expectUnknown(b, 40, 40);

  std::vector<P> only_bad(dirty.begin() + static_cast<long>(clean.size()), dirty.end());
  ScanMassGrid c;
  ASSERT_TRUE(builder.build(view(only_bad), c, nullptr));
  EXPECT_EQ(countAbove(c, FrameSG::kO, 0.0f), 0u);
  EXPECT_EQ(countAbove(c, FrameSG::kF, 0.0f), 0u);
}

TEST(ScanGrid, EmptyCloudGivesAllOmega)
{
  ScanGridBuilder builder(testParams(), Eigen::Isometry3d::Identity());
  ScanMassGrid grid;
  ScanGridStats st;
  // Reuse a grid that held a scan: everything must be reset.
  const auto pts = wall();
  ASSERT_TRUE(builder.build(view(pts), grid, &st));
  ASSERT_TRUE(builder.build(PointCloudView{}, grid, &st));
  EXPECT_EQ(st.points, 0u);
  EXPECT_EQ(countAbove(grid, FrameSG::kO, 0.0f), 0u);
  EXPECT_EQ(countAbove(grid, FrameSG::kF, 0.0f), 0u);
  EXPECT_EQ(countAbove(grid, FrameSG::kOmega, 0.999999f), grid.numCells());
}

TEST(ScanGrid, HeightBandsAndRanges)
{
  ScanGridParams p = testParams();
  p.min_range = 1.0;
  ScanGridBuilder builder(p, Eigen::Isometry3d::Identity());
  const std::vector<P> pts{
    { 5.0f, 0.1f, 3.0f },    // above the clearance (2.5 m): a canopy
    { 5.0f, 0.2f, 0.25f },   // between the ground band (0.2) and the obstacle band (0.3)
    { 5.0f, 0.3f, -0.5f },   // below the ground band
    { 0.5f, 0.5f, 1.0f },    // 0.71 m: below min range
    { 31.0f, 0.0f, 1.0f },   // beyond max range
    { 6.0f, -3.0f, 2.5f },   // top of the obstacle band: obstacle
    { 6.0f, 3.0f, 0.3f },    // bottom of the obstacle band: obstacle
  };
  ScanMassGrid grid;
  ScanGridStats st;
  ASSERT_TRUE(builder.build(view(pts), grid, &st));
  EXPECT_EQ(st.above_clearance, 1u);
  EXPECT_EQ(st.height_gap, 1u);
  EXPECT_EQ(st.below_ground, 1u);
  EXPECT_EQ(st.below_min_range, 1u);
  EXPECT_EQ(st.beyond_max_range, 1u);
  EXPECT_EQ(st.obstacle, 2u);
  EXPECT_EQ(st.ground, 0u);
  EXPECT_EQ(st.occupied_cells, 2u);
  expectOccupied(grid, 52, 34);
  expectOccupied(grid, 52, 46);
  // Neither the canopy nor the others give evidence: their cells stay unknown.
  expectUnknown(grid, 50, 40);
  // Cells closer than min_range are never free: (0.25, 0.25) is 0.35 m from the sensor.
  expectUnknown(grid, 40, 40);
}

TEST(ScanGrid, RelativeHeightDropsRaisedGroundAndKeepsObstaclesOnIt)
{
  std::vector<P> pts;
  int pavement = 0;
  for (float x = 8.0f; x <= 10.0f; x += 0.25f)  // a pavement 0.4 m above the vehicle's ground plane
    for (float y = -1.0f; y <= 1.0f; y += 0.25f, ++pavement) pts.push_back({ x, y, 0.4f });
  for (float x = 13.0f; x < 14.0f; x += 0.25f) pts.push_back({ x, 0.0f, 0.0f });  // road before a low box
  for (float z = 0.3f; z <= 0.7f; z += 0.1f) pts.push_back({ 14.1f, 0.0f, z });    // its face, 0.3-0.7 m
  pts.push_back({ 18.1f, 3.6f, 1.4f });                                          // a roof, no lower return around
  ScanGridParams p = testParams();
  p.relative_height_limit = 0.8;
  ScanGridBuilder builder(p, Eigen::Isometry3d::Identity());
  ScanMassGrid grid;
  ScanGridStats st;
  ASSERT_TRUE(builder.build(view(pts), grid, &st));
  EXPECT_EQ(st.low_relief, static_cast<std::size_t>(pavement));
  EXPECT_EQ(st.occupied_cells, 2u);  // the box and the roof
  for (int x = 56; x <= 60; ++x) EXPECT_EQ(at(grid, x, 40).o, 0.0f) << x;
  expectOccupied(grid, 68, 40);
  expectOccupied(grid, 76, 47);
  EXPECT_EQ(builder.obstaclePoints().count, st.obstacle);

  p.relative_height_limit = 0.0;  // the paper's flat rule: the pavement is an obstacle
  builder.configure(p, Eigen::Isometry3d::Identity());
  ASSERT_TRUE(builder.build(view(pts), grid, &st));
  EXPECT_EQ(st.low_relief, 0u);
  for (int x = 56; x <= 60; ++x) expectOccupied(grid, x, 40);
}

TEST(ScanGrid, SelfFilterDropsTheVehiclesOwnReturns)
{
  ScanGridParams p = testParams();
  p.self_box_min_x = -1.0;
  p.self_box_max_x = 3.0;
  p.self_box_min_y = -1.0;
  p.self_box_max_y = 1.0;
  ScanGridBuilder builder(p, Eigen::Isometry3d(Eigen::Translation3d(1.0, 0.0, 1.8)));
  auto pts = wall();  // sensor frame: the wall is at base_link x = 11.25, z = 2.8: above the clearance
  for (auto& q : pts) q.z = -0.8f;  // 1 m above the ground
  // Body returns 1.5 m ahead of the sensor (base_link x = 2.5, inside the box) would block the view.
  for (int k = -10; k <= 10; ++k) pts.push_back({ 1.5f, 0.05f * k, -0.3f });
  ScanMassGrid grid;
  ScanGridStats st;
  ASSERT_TRUE(builder.build(view(pts), grid, &st));
  EXPECT_EQ(st.self_returns, 21u);
  EXPECT_EQ(st.rejected(), 21u);
  EXPECT_EQ(st.obstacle, 201u);
  EXPECT_EQ(st.occupied_cells, 21u);  // the wall only, column floor((11.25 + 20) / 0.5) = 62
  for (int y = 30; y <= 50; ++y) expectOccupied(grid, 62, y);
  for (int x = 46; x < 62; ++x) expectFree(grid, x, 40);  // the view through the body is free
}

TEST(ScanGrid, GroundBeyondTheNearestObstacleDoesNotExtendFreeSpace)
{
  ScanGridParams p = testParams();
  p.azimuth_resolution_deg = 10.0;  // sector [0°, 10°) holds the centres of row 40 from column 43 on
  ScanGridBuilder builder(p, Eigen::Isometry3d::Identity());
  const std::vector<P> pts{ { 5.25f, 0.05f, 1.0f }, { 3.25f, 0.03f, 0.0f }, { 12.25f, 0.1f, 0.0f } };
  ScanMassGrid grid;
  ASSERT_TRUE(builder.build(view(pts), grid, nullptr));
  const int row = 40;  // y ∈ [0, 0.5]
  expectUnknown(grid, 42, row);  // centre (1.25, 0.25) looks at 11.3°: another sector
  for (int x = 43; x <= 49; ++x) expectFree(grid, x, row);
  expectOccupied(grid, 50, row);
  for (int x = 51; x < 80; ++x) expectUnknown(grid, x, row);
  // Without the obstacle the farthest ground return bounds the free space: 12.2504 m.
  const std::vector<P> ground_only{ { 3.25f, 0.03f, 0.0f }, { 12.25f, 0.1f, 0.0f } };
  ASSERT_TRUE(builder.build(view(ground_only), grid, nullptr));
  for (int x = 43; x <= 63; ++x) expectFree(grid, x, row);  // up to centre 11.75
  expectUnknown(grid, 64, row);                              // centre 12.25: 12.2525 m
  expectUnknown(grid, 65, row);
}

TEST(ScanGrid, OrganizedCloudWithRowPaddingMatchesUnorganized)
{
  ScanGridBuilder builder(testParams(), Eigen::Isometry3d::Identity());
  const auto pts = wall();  // 201 points
  // Organized: 3 rows of 67 points, 16-byte points (x, y, z, intensity), 8 padding bytes per row.
  const std::size_t rows = 3, cols = 67, step = 16, row_step = cols * step + 8;
  std::vector<std::uint8_t> buf(rows * row_step, 0xAB);
  for (std::size_t r = 0; r < rows; ++r)
    for (std::size_t c = 0; c < cols; ++c)
    {
      std::memcpy(buf.data() + r * row_step + c * step, &pts[r * cols + c], sizeof(P));
      const float intensity = 42.0f;
      std::memcpy(buf.data() + r * row_step + c * step + 12, &intensity, sizeof intensity);
    }
  PointCloudView organized;
  organized.data = buf.data();
  organized.width = cols;
  organized.height = rows;
  organized.point_step = step;
  organized.row_step = row_step;
  ASSERT_TRUE(organized.consistent());
  ScanMassGrid a, b;
  ASSERT_TRUE(builder.build(view(pts), a, nullptr));
  ASSERT_TRUE(builder.build(organized, b, nullptr));
  EXPECT_TRUE(samePlanes(a, b));
}

TEST(ScanGrid, SensorPoseIsApplied)
{
  ScanGridParams p = testParams();
  // Sensor 1.5 m ahead, 1.8 m up, yawed +90°: its x axis is base_link's y axis.
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translate(Eigen::Vector3d(1.5, 0.0, 1.8));
  pose.rotate(Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitZ()));
  ScanGridBuilder builder(p, pose);
  std::vector<P> pts;
  // A wall 5.25 m in front of the sensor (base_link y = 5.25), 1 m above the ground (sensor z = −0.8).
  for (int k = -59; k <= 59; ++k) pts.push_back({ 5.25f, 0.05f * k, -0.8f });
  // Ground returns (sensor z = −1.8) on the other side (base_link y = −4.25): not obstacles.
  for (int k = -59; k <= 59; ++k) pts.push_back({ -4.25f, 0.05f * k, -1.8f });
  ScanMassGrid grid;
  ScanGridStats st;
  ASSERT_TRUE(builder.build(view(pts), grid, &st));
  EXPECT_EQ(st.obstacle, 119u);
  EXPECT_EQ(st.ground, 119u);
  // Wall: base_link y = 5.25 → row 50; x = 1.5 − y_s ∈ [−1.45, 4.45] → columns 37 … 48.
  EXPECT_EQ(st.occupied_cells, 12u);
  for (int x = 37; x <= 48; ++x) expectOccupied(grid, x, 50);
  expectFree(grid, 43, 44);     // centre (1.75, 2.25), between the sensor and the wall
  expectUnknown(grid, 43, 53);  // centre (1.75, 6.75), behind the wall
  expectFree(grid, 43, 33);     // centre (1.75, −3.25), before the ground returns
  expectUnknown(grid, 43, 30);  // centre (1.75, −4.75), beyond them
}

TEST(ScanGrid, FreeMassDecaysWithRange)
{
  ScanGridParams p = testParams();
  p.free_decay_length = 20.0;
  ScanGridBuilder builder(p, Eigen::Isometry3d::Identity());
  const auto pts = wall();
  ScanMassGrid grid;
  ASSERT_TRUE(builder.build(view(pts), grid, nullptr));
  for (int x : { 41, 50, 59 })
  {
    const Point2 c = grid.geometry().cellCentre({ x, 40 });
    const float mu = static_cast<float>(0.7 * std::exp(-std::hypot(c.x, c.y) / 20.0));
    const Cell cell = at(grid, x, 40);
    EXPECT_NEAR(cell.f, mu, 1e-6f);
    EXPECT_NEAR(cell.omega, 1.0f - mu, 1e-6f);
  }
  expectOccupied(grid, 60, 40);
}

TEST(ScanGrid, TableIsBuiltOncePerGeometryAndSensorPosition)
{
  ScanGridBuilder builder(testParams(), Eigen::Isometry3d::Identity());
  EXPECT_EQ(builder.tableBuilds(), 1u);
  ScanMassGrid grid;
  const auto pts = wall();
  for (int k = 0; k < 3; ++k) ASSERT_TRUE(builder.build(view(pts), grid, nullptr));
  EXPECT_EQ(builder.tableBuilds(), 1u);
  ScanGridParams p = testParams();
  p.mu_occupied = 0.9;
  p.ground_height = -0.1;
  builder.configure(p, Eigen::Isometry3d(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY())));
  EXPECT_EQ(builder.tableBuilds(), 1u);  // neither the masses of O, the heights nor the sensor's tilt matter
  builder.setSensorPose(Eigen::Isometry3d(Eigen::Translation3d(0.5, 0.0, 0.0)));
  EXPECT_EQ(builder.tableBuilds(), 2u);
  p.grid_resolution = 0.25;
  builder.configure(p, builder.sensorPose());
  EXPECT_EQ(builder.tableBuilds(), 3u);
}

TEST(ScanGrid, ParametersAreValidatedByName)
{
  const auto expectError = [](const char* name, auto mutate) {
    ScanGridParams p = testParams();
    mutate(p);
    try
    {
      p.validate();
      ADD_FAILURE() << "no error for " << name;
    }
    catch (const ParameterError& e)
    {
      EXPECT_EQ(e.parameter(), name);
    }
  };
  expectError("grid_resolution", [](ScanGridParams& p) { p.grid_resolution = 0.0; });
  expectError("grid_size_x", [](ScanGridParams& p) { p.grid_size_x = 0.1; });
  expectError("grid_size_x", [](ScanGridParams& p) { p.grid_size_x = p.grid_size_y = 1e5; });
  expectError("azimuth_resolution_deg", [](ScanGridParams& p) { p.azimuth_resolution_deg = 0.0; });
  expectError("min_range", [](ScanGridParams& p) { p.min_range = -1.0; });
  expectError("max_range", [](ScanGridParams& p) { p.max_range = 0.5, p.min_range = 1.0; });
  expectError("ground_tolerance", [](ScanGridParams& p) { p.ground_tolerance = -0.1; });
  expectError("self_box_max_x", [](ScanGridParams& p) { p.self_box_min_x = 1.0; });
  expectError("self_box_max_y", [](ScanGridParams& p) { p.self_box_max_y = -1.0; });
  expectError("obstacle_min_height", [](ScanGridParams& p) { p.obstacle_min_height = 0.1; });
  expectError("obstacle_max_height", [](ScanGridParams& p) { p.obstacle_max_height = 0.3; });
  expectError("mu_free", [](ScanGridParams& p) { p.mu_free = 1.5; });
  expectError("mu_occupied", [](ScanGridParams& p) { p.mu_occupied = std::nan(""); });
  expectError("free_decay_length", [](ScanGridParams& p) { p.free_decay_length = -1.0; });
  expectError("threads", [](ScanGridParams& p) { p.threads = -1; });
  expectError("threads", [](ScanGridParams& p) { p.threads = kMaxThreads + 1; });
  EXPECT_NO_THROW(testParams().validate());
  EXPECT_NO_THROW(ScanGridParams().validate());

  // A rejected configuration leaves the builder as it was.
  ScanGridBuilder builder(testParams(), Eigen::Isometry3d::Identity());
  ScanGridParams bad = testParams();
  bad.mu_free = 2.0;
  EXPECT_THROW(builder.configure(bad, Eigen::Isometry3d::Identity()), ParameterError);
  EXPECT_EQ(builder.params().mu_free, 0.7);
  ScanGridBuilder unconfigured;
  ScanMassGrid grid;
  EXPECT_FALSE(unconfigured.build(PointCloudView{}, grid, nullptr));
}

TEST(ScanGrid, InconsistentViewIsRefused)
{
  ScanGridBuilder builder(testParams(), Eigen::Isometry3d::Identity());
  const auto pts = wall();
  PointCloudView v = view(pts);
  v.z_offset = 10;  // float at 10..14 does not fit in a 12-byte point
  ScanMassGrid grid;
  ScanGridStats st;
  EXPECT_FALSE(builder.build(v, grid, &st));
  EXPECT_EQ(st.points, pts.size());
  PointCloudView null_data;
  null_data.width = 5;
  null_data.point_step = 12;
  null_data.row_step = 60;
  EXPECT_FALSE(builder.build(null_data, grid, &st));
}

TEST(ScanGrid, RandomCloudsGiveValidMassesAndObstaclesAlwaysMarked)
{
  ScanGridBuilder builder(testParams(), Eigen::Isometry3d::Identity());
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> xy(-25.0f, 25.0f), z(-0.5f, 3.0f);
  ScanMassGrid grid;
  for (int trial = 0; trial < 5; ++trial)
  {
    std::vector<P> pts(2000);
    for (auto& p : pts) p = { xy(rng), xy(rng), z(rng) };
    ScanGridStats st;
    ASSERT_TRUE(builder.build(view(pts), grid, &st));
    EXPECT_EQ(st.ground + st.obstacle + st.below_ground + st.height_gap + st.above_clearance + st.rejected(),
              pts.size());
    for (std::size_t i = 0; i < grid.numCells(); ++i)
    {
      const float f = grid.plane(FrameSG::kF)[i], o = grid.plane(FrameSG::kO)[i];
      const float w = grid.plane(FrameSG::kOmega)[i];
      ASSERT_TRUE(f >= 0.0f && o >= 0.0f && w >= 0.0f);
      ASSERT_NEAR(f + o + w, 1.0f, 1e-6f);
      ASSERT_FALSE(f > 0.0f && o > 0.0f);
    }
    for (const auto& p : pts)
    {
      const float r = std::hypot(p.x, p.y);
      CellIndex c;
      if (p.z >= 0.3f && p.z <= 2.5f && r <= 30.0f && grid.geometry().worldToCell({ p.x, p.y }, c))
      {
        ASSERT_EQ(at(grid, c.x, c.y).o, 0.8f);
      }
    }
  }
}

namespace {

/// An organized cloud of @p rows × @p cols points, each row padded by 12 bytes (so chunks of points start and end
/// inside rows), drawn over every class: no return, non-finite, below min range, beyond max range, the vehicle's box,
/// ground, below ground, height gap, obstacle, above clearance, and obstacles outside the grid.
struct PaddedCloud
{
  std::size_t rows, cols, row_step;
  std::vector<std::uint8_t> bytes;
  PaddedCloud(std::size_t r, std::size_t c, unsigned seed) : rows(r), cols(c), row_step(c * sizeof(P) + 12)
  {
    bytes.assign(rows * row_step, 0xAB);
    std::mt19937 rng(seed);
    std::uniform_int_distribution<int> kind(0, 99);
    std::uniform_real_distribution<float> xy(-19.0f, 19.0f), angle(-3.14159f, 3.14159f), near(2.0f, 12.0f),
        far(12.5f, 19.0f), ground(-0.1f, 0.1f), obstacle(0.5f, 2.0f), raised(0.4f, 0.5f), patch(-1.0f, 1.0f);
    const auto polar = [&](float r, float z) {
      const float a = angle(rng);
      return P{ r * std::cos(a), r * std::sin(a), z };
    };
    for (std::size_t row = 0; row < rows; ++row)
      for (std::size_t col = 0; col < cols; ++col)
      {
        const int k = kind(rng);
        P p = polar(near(rng), ground(rng));  // ground out to 12 m
        if (k < 3) p = { 0.0f, 0.0f, 0.0f };
        else if (k < 5) p.x = kNaN;
        else if (k < 7) p = { 0.2f, 0.1f, 0.0f };                   // below min range
        else if (k < 9) p = { 35.0f, 25.0f, 1.0f };                 // beyond max range
        else if (k < 11) p = { 1.0f, 0.5f, 1.0f };                  // the vehicle's box
        else if (k < 14) p.z = -0.6f;                               // below ground
        else if (k < 17) p = { xy(rng), xy(rng), 0.25f };           // height gap
        else if (k < 20) p = { xy(rng), xy(rng), 3.0f };            // above clearance
        else if (k < 22) p = { 21.0f + 0.01f * k, 3.0f, 1.0f };     // obstacle outside the 40 m grid
        else if (k < 27) p = { 15.0f + patch(rng), patch(rng), raised(rng) };  // a raised patch, no ground around
        else if (k < 45) p = polar(far(rng), obstacle(rng));        // obstacles beyond 12.5 m
        std::memcpy(bytes.data() + row * row_step + col * sizeof(P), &p, sizeof p);
      }
  }
  PointCloudView view() const
  {
    PointCloudView v;
    v.data = bytes.data();
    v.width = cols;
    v.height = rows;
    v.point_step = sizeof(P);
    v.row_step = row_step;
    return v;
  }
  P at(std::size_t row, std::size_t col) const
  {
    P p;
    std::memcpy(&p, bytes.data() + row * row_step + col * sizeof(P), sizeof p);
    return p;
  }
};

ScanGridParams chunkedParams()
{
  ScanGridParams p = testParams();
  p.min_range = 0.5;
  p.self_box_min_x = 0.5;
  p.self_box_max_x = 1.5;
  p.self_box_min_y = 0.0;
  p.self_box_max_y = 1.0;
  return p;
}

}  // namespace

// 100 000 points are one chunk with one thread and 7 with more: the obstacle returns must come out in point order,
// each once, with the counts of every class, whatever the thread count.
TEST(ScanGrid, ObstacleReturnsOfManyChunksAreListedInPointOrder)
{
  const PaddedCloud cloud(50, 2000, 11);
  std::vector<float> expected;
  std::size_t no_return = 0, non_finite = 0, below_min = 0, beyond_max = 0, self = 0, below_ground = 0, gap = 0;
  std::size_t above = 0, ground = 0, obstacle = 0;
  for (std::size_t row = 0; row < cloud.rows; ++row)
    for (std::size_t col = 0; col < cloud.cols; ++col)
    {
      const P p = cloud.at(row, col);
      const float r2 = p.x * p.x + p.y * p.y;
      if (!std::isfinite(p.x)) ++non_finite;
      else if (p.x == 0.0f && p.y == 0.0f && p.z == 0.0f) ++no_return;
      else if (r2 < 0.25f) ++below_min;
      else if (r2 > 900.0f) ++beyond_max;
      else if (p.x > 0.5f && p.x < 1.5f && p.y > 0.0f && p.y < 1.0f) ++self;
      else if (p.z < -0.2f) ++below_ground;
      else if (p.z <= 0.2f) ++ground;
      else if (p.z < 0.3f) ++gap;
      else if (p.z > 2.5f) ++above;
      else
      {
        ++obstacle;
        if (std::abs(p.x) < 20.0f && std::abs(p.y) < 20.0f)
        {
          expected.push_back(p.x);
          expected.push_back(p.y);
        }
      }
    }
  ASSERT_GT(expected.size(), 2 * 10000u);
  ASSERT_LT(expected.size() / 2, obstacle) << "some obstacles must fall outside the grid";
  for (int threads : { 1, 2, 4 })
  {
    ScanGridParams params = chunkedParams();
    params.threads = threads;
    ScanGridBuilder builder(params, Eigen::Isometry3d::Identity());
    ScanMassGrid grid;
    ScanGridStats st;
    ASSERT_TRUE(builder.build(cloud.view(), grid, &st));
    EXPECT_EQ(st.no_return, no_return) << threads;
    EXPECT_EQ(st.non_finite, non_finite) << threads;
    EXPECT_EQ(st.below_min_range, below_min) << threads;
    EXPECT_EQ(st.beyond_max_range, beyond_max) << threads;
    EXPECT_EQ(st.self_returns, self) << threads;
    EXPECT_EQ(st.below_ground, below_ground) << threads;
    EXPECT_EQ(st.height_gap, gap) << threads;
    EXPECT_EQ(st.above_clearance, above) << threads;
    EXPECT_EQ(st.ground, ground) << threads;
    EXPECT_EQ(st.obstacle, obstacle) << threads;
    EXPECT_EQ(st.obstacle_outside_grid, obstacle - expected.size() / 2) << threads;
    const ObstaclePoints got = builder.obstaclePoints();
    ASSERT_EQ(got.count, expected.size() / 2) << threads;
    EXPECT_EQ(std::memcmp(got.xy, expected.data(), expected.size() * sizeof(float)), 0)
        << threads << " threads: the obstacle returns differ from the cloud's, in point order";
  }
}

// The grid, the counts and the obstacle returns of a cloud of many chunks are the same, byte for byte, for 1, 2 and
// 4 threads, with both ground models and with and without the relative obstacle height (its lowest return per cell
// is shared between the chunks).
TEST(ScanGrid, ManyChunksGiveTheSameGridForAnyThreadCount)
{
  const PaddedCloud cloud(64, 2100, 5);
  for (const char* model : { "flat", "planes" })
    for (double relative : { 0.0, 0.8 })
    {
      std::vector<std::uint8_t> first_planes;
      std::vector<float> first_obstacles;
      ScanGridStats first;
      for (int threads : { 1, 2, 4 })
      {
        ScanGridParams params = chunkedParams();
        params.ground_model = model;
        params.relative_height_limit = relative;
        params.threads = threads;
        ScanGridBuilder builder(params, Eigen::Isometry3d::Identity());
        ScanMassGrid grid;
        ScanGridStats st;
        ASSERT_TRUE(builder.build(cloud.view(), grid, &st));
        std::vector<std::uint8_t> planes;
        for (Subset a : { FrameSG::kEmpty, FrameSG::kF, FrameSG::kO, FrameSG::kOmega })
        {
          const auto* b = reinterpret_cast<const std::uint8_t*>(grid.plane(a));
          planes.insert(planes.end(), b, b + grid.numCells() * sizeof(float));
        }
        const ObstaclePoints obs = builder.obstaclePoints();
        const std::vector<float> obstacles(obs.xy, obs.xy + 2 * obs.count);
        if (threads == 1)
        {
          first_planes = planes;
          first_obstacles = obstacles;
          first = st;
          EXPECT_GT(st.free_cells, 1000u) << model;
          EXPECT_GT(st.occupied_cells, 1000u) << model;
          if (relative > 0.0)
          {
            EXPECT_GT(st.low_relief, 0u) << model;
          }
          continue;
        }
        const std::string what = std::string(model) + ", relative " + std::to_string(relative) + ", " +
                                 std::to_string(threads) + " threads";
        EXPECT_TRUE(planes == first_planes) << what << ": the grid differs";
        EXPECT_TRUE(obstacles == first_obstacles) << what << ": the obstacle returns differ";
        EXPECT_EQ(st.ground, first.ground) << what;
        EXPECT_EQ(st.obstacle, first.obstacle) << what;
        EXPECT_EQ(st.low_relief, first.low_relief) << what;
        EXPECT_EQ(st.free_cells, first.free_cells) << what;
        EXPECT_EQ(st.occupied_cells, first.occupied_cells) << what;
        EXPECT_EQ(st.below_ground, first.below_ground) << what;
        EXPECT_EQ(st.ground_fit.fitted, first.ground_fit.fitted) << what;
      }
    }
}

TEST(ScanGrid, ReturnClassesNameWhatTheModelMadeOfEachPoint)
{
  ScanGridParams p = testParams();
  p.min_range = 1.0;
  ScanGridBuilder builder(p, Eigen::Isometry3d::Identity());
  const std::vector<P> pts{
    { 5.0f, 0.1f, 3.0f },    // above the clearance
    { 5.0f, 0.2f, 0.25f },   // in the gap between the bands
    { 5.0f, 0.3f, -0.5f },   // below the ground band
    { 0.5f, 0.5f, 1.0f },    // below min range: rejected
    { 31.0f, 0.0f, 1.0f },   // beyond max range: rejected
    { 6.0f, -3.0f, 2.5f },   // obstacle
    { 7.0f, 1.0f, 0.1f },    // ground
    { kNaN, 1.0f, 0.0f },    // non-finite: rejected
    { 0.0f, 0.0f, 0.0f },    // no return: rejected
  };
  const std::vector<ReturnClass> expected{ ReturnClass::kAboveClearance, ReturnClass::kHeightGap,
                                           ReturnClass::kBelowGround,    ReturnClass::kRejected,
                                           ReturnClass::kRejected,       ReturnClass::kObstacle,
                                           ReturnClass::kGround,         ReturnClass::kRejected,
                                           ReturnClass::kRejected };
  ScanMassGrid grid;
  ASSERT_TRUE(builder.build(view(pts), grid));
  EXPECT_TRUE(builder.returnClasses().empty()) << "off by default";
  const ScanMassGrid without = grid;
  builder.recordReturnClasses(true);
  ASSERT_TRUE(builder.build(view(pts), grid));
  EXPECT_EQ(builder.returnClasses(), expected);
  EXPECT_TRUE(samePlanes(grid, without)) << "recording changes nothing in the grid";
}

TEST(ScanGrid, ReturnClassesAgreeWithTheCountsForAnyModelAndThreadCount)
{
  const PaddedCloud cloud(64, 2100, 5);
  for (const char* model : { "flat", "planes", "planes+consensus" })
    for (double relative : { 0.0, 0.8 })
    {
      std::vector<ReturnClass> first;
      const bool consensus = std::string(model) == "planes+consensus";
      for (int threads : { 1, 2 })
      {
        ScanGridParams params = chunkedParams();
        params.ground_model = consensus ? "planes" : model;
        params.ground_consensus = consensus;
        params.relative_height_limit = relative;
        params.threads = threads;
        ScanGridBuilder builder(params, Eigen::Isometry3d::Identity());
        builder.recordReturnClasses(true);
        ScanMassGrid grid;
        ScanGridStats st;
        ASSERT_TRUE(builder.build(cloud.view(), grid, &st));
        const auto& c = builder.returnClasses();
        ASSERT_EQ(c.size(), st.points);
        auto count = [&](ReturnClass r) { return static_cast<std::size_t>(std::count(c.begin(), c.end(), r)); };
        const std::string what = std::string(model) + ", relative " + std::to_string(relative) + ", " +
                                 std::to_string(threads) + " threads";
        EXPECT_EQ(count(ReturnClass::kRejected), st.rejected()) << what;
        EXPECT_EQ(count(ReturnClass::kGround), st.ground) << what;
        EXPECT_EQ(count(ReturnClass::kObstacle), st.obstacle) << what;
        EXPECT_EQ(count(ReturnClass::kBelowGround), st.below_ground) << what;
        EXPECT_EQ(count(ReturnClass::kHeightGap), st.height_gap) << what;
        EXPECT_EQ(count(ReturnClass::kAboveClearance), st.above_clearance) << what;
        EXPECT_EQ(count(ReturnClass::kLowRelief), st.low_relief) << what;
        EXPECT_EQ(count(ReturnClass::kDisputed), st.disputed) << what;
        if (relative > 0.0 && !consensus)
        {
          EXPECT_GT(st.low_relief, 0u) << what;
        }
        if (consensus)
        {
          EXPECT_GT(st.disputed, 0u) << what << ": the random cloud's two ground fits disagree somewhere";
        }
        if (threads == 1)
          first = c;
        else
          EXPECT_TRUE(c == first) << what << ": the classes differ between thread counts";
      }
    }
}

TEST(ScanGrid, AmbiguousReturnsLeaveTheirCellUnknownNotFree)
{
  ScanGridParams p = testParams();
  p.azimuth_resolution_deg = 10.0;  // sector [0°, 10°) holds the centres of row 40 from column 43 on
  const int row = 40;
  ScanMassGrid off, on;
  ScanGridStats st_off, st_on;
  ScanGridBuilder builder;
  // The grids of @p pts without the step (off) and with it (on).
  const auto buildBoth = [&](const std::vector<P>& pts) {
    for (const bool step : { false, true })
    {
      p.ambiguous_unknown = step;
      builder.configure(p, Eigen::Isometry3d::Identity());
      ASSERT_TRUE(builder.build(view(pts), step ? on : off, step ? &st_on : &st_off));
    }
  };
  // Ground out to 12.25 m; a return in the gap between the bands at 5.25 m (cell 50), one at 8.25 m (cell 56).
  buildBoth({ { 12.25f, 0.1f, 0.0f }, { 5.25f, 0.05f, 0.25f }, { 8.25f, 0.05f, 0.27f } });
  for (int x = 43; x <= 63; ++x) expectFree(off, x, row);
  for (int x = 43; x <= 63; ++x)
    if (x == 50 || x == 56)
      expectUnknown(on, x, row);
    else
      expectFree(on, x, row);
  EXPECT_EQ(st_on.free_cells, st_off.free_cells - 2);
  EXPECT_EQ(st_on.height_gap, 2u);

  // Returns the relative obstacle height drops (a raised pavement) are ambiguous too; an obstacle stays occupied.
  std::vector<P> pavement;
  for (float x = 8.0f; x < 10.0f; x += 0.25f)
    for (float y = 0.05f; y <= 0.45f; y += 0.2f) pavement.push_back({ x, y, 0.4f });
  pavement.push_back({ 14.25f, 0.1f, 0.0f });  // ground beyond it
  pavement.push_back({ 6.25f, 0.05f, 1.0f });  // an obstacle before it: the sector's free space ends there
  p.relative_height_limit = 0.8;
  buildBoth(pavement);
  EXPECT_GT(st_on.low_relief, 0u);
  EXPECT_TRUE(samePlanes(on, off)) << "the pavement lies behind the obstacle: nothing free to take back";
  expectOccupied(on, 52, row);
  pavement.pop_back();  // without the obstacle the ground at 14.25 m frees the sector through the pavement
  buildBoth(pavement);
  for (int x = 56; x <= 59; ++x)
  {
    expectFree(off, x, row);
    expectUnknown(on, x, row);  // centres 8.25 … 9.75: the pavement's cells
  }
  expectFree(on, 55, row);
  expectFree(on, 60, row);
  EXPECT_EQ(on.plane(FrameSG::kO)[on.geometry().index(56, row)], 0.0f) << "ambiguous, not occupied";
}

TEST(ScanGrid, GroundCellsFreeGivesTheCellsOfGroundReturnsBehindAnObstacleFreeMassAndNothingElse)
{
  ScanGridParams p = testParams();
  p.azimuth_resolution_deg = 10.0;  // sector [0°, 10°) holds the centres of row 40 from column 43 on
  const int row = 40;
  // An obstacle at 6.25 m (cell 52): the sector's free space ends there. Ground returns behind it at 12.25 m (cell 64)
  // and 14.3 m (cell 68), where an obstacle return lies too.
  const std::vector<P> pts{ { 6.25f, 0.05f, 1.0f }, { 12.25f, 0.1f, 0.0f }, { 14.3f, 0.3f, 0.0f },
                            { 14.4f, 0.2f, 1.0f } };
  ScanGridBuilder builder;
  ScanMassGrid off, on;
  ScanGridStats st_off, st_on;
  for (const bool step : { false, true })
  {
    p.ground_cells_free = step;
    builder.configure(p, Eigen::Isometry3d::Identity());
    ASSERT_TRUE(builder.build(view(pts), step ? on : off, step ? &st_on : &st_off));
  }
  for (int x = 43; x <= 51; ++x)
  {
    expectFree(off, x, row);
    expectFree(on, x, row);
  }
  for (ScanMassGrid* g : { &off, &on })
  {
    expectOccupied(*g, 52, row);
    expectOccupied(*g, 68, row);
  }
  expectUnknown(off, 64, row);
  expectFree(on, 64, row);  // μ_F of the cell: the ground return's own cell only
  for (int x = 53; x <= 67; ++x)
    if (x != 64) expectUnknown(on, x, row);  // the ray's path passed above whatever stands there
  EXPECT_EQ(st_on.free_cells, st_off.free_cells + 1);

  // With the decay, the cell's μ_F is that of its centre's range, as in front of the obstacle.
  p.free_decay_length = 20.0;
  builder.configure(p, Eigen::Isometry3d::Identity());
  ASSERT_TRUE(builder.build(view(pts), on));
  expectFree(on, 64, row, static_cast<float>(0.7 * std::exp(-std::hypot(12.25, 0.25) / 20.0)));

  // Step ambiguous unknown still takes the free mass of a cell holding an ambiguous return back.
  p.free_decay_length = 0.0;
  p.ambiguous_unknown = true;
  std::vector<P> with_gap = pts;
  with_gap.push_back({ 12.4f, 0.2f, 0.25f });  // between the ground and obstacle bands, in cell 64
  builder.configure(p, Eigen::Isometry3d::Identity());
  ASSERT_TRUE(builder.build(view(with_gap), on));
  expectUnknown(on, 64, row);
}

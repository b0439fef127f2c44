// The MapGrid on scripted scenes, without ROS.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <random>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "map_aided_fusion/core/map_grid.hpp"
#include "map_aided_fusion/core/pignistic.hpp"
#include "test_util.hpp"

using namespace map_aided_fusion::core;

namespace {

constexpr double kRes = 0.5;
const MassSG kFreeScan{ { FrameSG::kF, 0.7 }, { FrameSG::kOmega, 0.3 } };
const MassSG kOccupiedScan{ { FrameSG::kO, 0.8 }, { FrameSG::kOmega, 0.2 } };

struct Box
{
  double x0, y0, x1, y1;  // map frame, metres
  bool contains(Point2 p) const { return p.x >= x0 && p.x < x1 && p.y >= y0 && p.y < y1; }
};

/// A ScanGrid in the vehicle frame (vehicle at the map origin, yaw 0): cells inside a box are occupied,
/// every other cell within @p range is seen free. No occlusion.
ScanMassGrid scriptedScan(const std::vector<Box>& boxes, double range = 20.0)
{
  ScanMassGrid scan(GridGeometry::centred(50.0, 50.0, kRes));
  const auto& g = scan.geometry();
  for (std::size_t i = 0; i < scan.numCells(); ++i)
  {
    const Point2 p = g.cellCentre(g.cellOf(i));
    bool occupied = false;
    for (const auto& b : boxes) occupied = occupied || b.contains(p);
    if (occupied)
      scan.setCell(i, kOccupiedScan);
    else if (std::hypot(p.x, p.y) <= range)
      scan.setCell(i, kFreeScan);
  }
  return scan;
}

/// A prior over 100 m × 100 m: a road y ∈ [−4, 4), pavements (T) elsewhere, a building x,y ∈ [10, 16) × [8, 14).
PriorWindow scriptedPrior()
{
  const auto g = GridGeometry::centred(100.0, 100.0, kRes);
  PriorWindow prior(g);
  const PriorConfidence beta;
  for (std::size_t i = 0; i < g.numCells(); ++i)
  {
    const Point2 p = g.cellCentre(g.cellOf(i));
    PriorClass c = PriorClass::kOther;
    if (p.y >= -4.0 && p.y < 4.0) c = PriorClass::kRoad;
    if (p.x >= 10.0 && p.x < 16.0 && p.y >= 8.0 && p.y < 14.0) c = PriorClass::kBuilding;
    const auto m = priorMass(c, beta);
    prior.building[i] = static_cast<float>(m[FrameMG::kBuilding]);
    prior.road[i] = static_cast<float>(m[FrameMG::kRoad]);
    prior.other[i] = static_cast<float>(m[FrameMG::kOther]);
  }
  return prior;
}

struct Outputs
{
  PignisticPlanes betp;
  std::vector<std::int8_t> decision;
};

Outputs outputs(const MapGrid& mg)
{
  Outputs o;
  pignisticGrid(mg.masses(), o.betp);
  for (int e = 0; e < FrameMG::kSize; ++e)
    for (std::size_t i = 0; i < mg.masses().numCells(); ++i)
      EXPECT_NEAR(mg.pignistic()[e][i], o.betp[e][i], 1e-6) << "BetP computed in the fusion pass differs";
  decide(mg.masses(), o.betp, mg.params().decision_threshold, o.decision);
  return o;
}

CellClass classAt(const MapGrid& mg, const Outputs& o, Point2 p)
{
  CellIndex c;
  EXPECT_TRUE(mg.geometry().worldToCell(p, c));
  return static_cast<CellClass>(o.decision[mg.geometry().index(c)]);
}

MapGridParams defaultParams()
{
  MapGridParams p;
  p.size_x = p.size_y = 60.0;
  p.resolution = kRes;
  return p;
}

}  // namespace

class MapGridShift : public ::testing::TestWithParam<double>
{
};

// Widths of 40 cells (rows of whole blocks: rows moved as blocks) and 41 (the cell-by-cell path).
INSTANTIATE_TEST_SUITE_P(BlockRowsAndAnyWidth, MapGridShift, ::testing::Values(20.0, 20.5));

namespace {

void expectShiftsKeepMassesBitExact(double size_x, double size_y, int threads)
{
  MapGridParams params = defaultParams();
  params.size_x = size_x;
  params.size_y = size_y;
  params.threads = threads;
  MapGrid mg(params);
  ASSERT_EQ(mg.geometry().width % 8 == 0, size_x == 20.0);
  std::mt19937 rng(3);
  auto& grid = mg.mutableMasses();
  for (std::size_t i = 0; i < grid.numCells(); ++i)
  {
    grid.setCell(i, maf_test::randomMass<FrameMG>(rng, 6, false, true));
    grid.zeta(i) = static_cast<float>(i % 17) / 17.0f;
  }
  const MapMassGrid before = grid;
  for (auto [dx, dy] : { std::pair{ 3, -2 }, std::pair{ -5, 0 }, std::pair{ 0, 4 }, std::pair{ 1, 1 }, std::pair{ -16, 3 },
                         std::pair{ 0, -9 }, std::pair{ 7, 9 }, std::pair{ -2, 12 }, std::pair{ 0, -12 } })
  {
    MapGrid moved = mg;
    moved.shift(dx, dy);
    const auto& g = moved.geometry();
    EXPECT_DOUBLE_EQ(g.origin_x, before.geometry().origin_x + dx * kRes);
    EXPECT_DOUBLE_EQ(g.origin_y, before.geometry().origin_y + dy * kRes);
    for (int y = 0; y < g.height; ++y)
      for (int x = 0; x < g.width; ++x)
      {
        const std::size_t j = g.index(x, y);
        const CellIndex src{ x + dx, y + dy };
        if (g.contains(src))
        {
          const std::size_t i = g.index(src);
          for (int a = 0; a < 32; ++a)
            if (MapMassGrid::stored(static_cast<Subset>(a)))
            {
              ASSERT_EQ(moved.masses().at(static_cast<Subset>(a), j), before.at(static_cast<Subset>(a), i));
            }
          ASSERT_EQ(moved.masses().zeta(j), before.zeta(i));
          // Same world position before and after.
          const Point2 pw = g.cellCentre(CellIndex{ x, y });
          const Point2 pb = before.geometry().cellCentre(src);
          ASSERT_DOUBLE_EQ(pw.x, pb.x);
          ASSERT_DOUBLE_EQ(pw.y, pb.y);
        }
        else
        {
          ASSERT_TRUE(maf_test::massNear(moved.masses().cell(j), MassMG::vacuous(), 0.0));
          ASSERT_EQ(moved.masses().zeta(j), 0.0f);
        }
      }
  }
  MapGrid far = mg;
  far.shift(1000, 0);
  for (std::size_t i = 0; i < far.masses().numCells(); ++i)
    ASSERT_TRUE(maf_test::massNear(far.masses().cell(i), MassMG::vacuous(), 0.0));
}

}  // namespace

TEST_P(MapGridShift, KeepsMassesBitExactAtTheirNewIndex)
{
  // One to three threads (bands of rows move in parallel), by up to 16 columns and 12 rows, in windows of 30 rows
  // (one band) and of 100 rows (bands of 32 to 96 rows, which read rows of their neighbours).
  for (int threads : { 1, 2, 3 })
    for (double size_y : { 15.0, 50.0 })
    {
      SCOPED_TRACE("threads " + std::to_string(threads) + ", " + std::to_string(size_y) + " m");
      expectShiftsKeepMassesBitExact(GetParam(), size_y, threads);
    }
}

TEST(ProjectScan, RotatedWindowSamplesTheScanCellUnderEachCellCentre)
{
  // Free and unknown evidence only (no forward pass, no clearance): every window cell takes the scan cell under its
  // centre, seen from the vehicle, or is vacuous outside the scan grid, for windows that cross the scan's edges.
  const auto sg = GridGeometry::centred(20.0, 14.0, kRes);
  ScanMassGrid scan(sg);
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> free_mass(0.0, 1.0);
  for (std::size_t i = 0; i < scan.numCells(); ++i)
  {
    const double f = free_mass(rng);
    scan.setCell(i, MassSG{ { FrameSG::kF, f }, { FrameSG::kOmega, 1.0 - f } });
  }
  std::uniform_real_distribution<double> yaw(-M_PI, M_PI), shift(-6.0, 6.0);
  ScanMassGrid out;  // reused: every cell of every trial must be written again
  for (int trial = 0; trial < 6; ++trial)
  {
    // The window follows the vehicle by whole cells (its origin changes, its size does not), as in MapGrid::update.
    const auto window = GridGeometry::centred(30.0, 24.0, kRes, (trial % 3) * 3 * kRes, -(trial % 2) * 5 * kRes);
    const Pose2 pose{ shift(rng), shift(rng), yaw(rng) };
    projectScan(scan, pose, window, out);
    std::size_t sampled = 0, mismatches = 0;
    for (int y = 0; y < window.height; ++y)
      for (int x = 0; x < window.width; ++x)
      {
        const Point2 p = window.cellCentre(CellIndex{ x, y });
        const double dx = p.x - pose.x, dy = p.y - pose.y;
        const Point2 v{ std::cos(pose.yaw) * dx + std::sin(pose.yaw) * dy, -std::sin(pose.yaw) * dx + std::cos(pose.yaw) * dy };
        CellIndex sc;
        const bool inside = sg.worldToCell(v, sc);
        sampled += inside;
        const MassSG expected = inside ? scan.cell(sg.index(sc)) : MassSG::vacuous();
        mismatches += !maf_test::massNear(out.cell(window.index(x, y)), expected, 1e-6);
      }
    EXPECT_GT(sampled, 200u) << "trial " << trial << " must overlap the scan";
    EXPECT_LT(sampled, window.numCells()) << "trial " << trial << " must cross the scan's edges";
    EXPECT_EQ(mismatches, 0u) << "trial " << trial << " yaw " << pose.yaw;
  }
}

TEST(ProjectScan, IdentityIsAnExactCopyAndRotationLosesNoObstacle)
{
  const auto sg = GridGeometry::centred(20.0, 20.0, kRes);
  ScanMassGrid scan(sg);
  std::mt19937 rng(4);
  for (std::size_t i = 0; i < scan.numCells(); ++i) scan.setCell(i, maf_test::randomMass<FrameSG>(rng, 3));
  ScanMassGrid out;
  projectScan(scan, Pose2{ 0.0, 0.0, 0.0 }, sg, out);
  for (std::size_t i = 0; i < scan.numCells(); ++i)
    for (int a = 0; a < 4; ++a) ASSERT_EQ(out.at(static_cast<Subset>(a), i), scan.at(static_cast<Subset>(a), i));

  // A window translated by whole cells and a vehicle away from the origin: still a copy.
  auto window = sg;
  window.origin_x += 7 * kRes;
  window.origin_y -= 3 * kRes;
  projectScan(scan, Pose2{ 2.0, -1.0, 0.0 }, window, out);
  for (int y = 0; y < window.height; ++y)
    for (int x = 0; x < window.width; ++x)
    {
      const Point2 p = window.cellCentre(CellIndex{ x, y });
      CellIndex sc;
      const bool inside = sg.worldToCell(Point2{ p.x - 2.0, p.y + 1.0 }, sc);
      const auto expected = inside ? scan.cell(sg.index(sc)) : MassSG::vacuous();
      ASSERT_TRUE(maf_test::massNear(out.cell(window.index(x, y)), expected, 0.0));
    }

  // One occupied cell per scan at many angles: it always reaches the window.
  for (double yaw = 0.0; yaw < 6.3; yaw += 0.1)
  {
    ScanMassGrid pole(sg);
    const std::size_t k = sg.index(27, 13);
    pole.setCell(k, kOccupiedScan);
    projectScan(pole, Pose2{ 1.3, -0.7, yaw }, GridGeometry::centred(40.0, 40.0, kRes), out);
    int occupied = 0;
    for (std::size_t i = 0; i < out.numCells(); ++i) occupied += out.at(FrameSG::kO, i) > 0.0f;
    EXPECT_GE(occupied, 1) << "yaw " << yaw;
  }
}

TEST(ProjectScan, ClearanceTakesTheFreeMassWithinTheSquareOfEveryObstacle)
{
  // Sparse obstacles over free space, with and without point occupancy, at several clearances: each window cell within
  // k cells (square, Chebyshev) of a cell with occupied mass has its free mass moved to Ω, every other cell is the
  // projection without clearance, bit for bit.
  const auto sg = GridGeometry::centred(30.0, 26.0, kRes);
  ScanMassGrid scan(sg);
  std::mt19937 rng(21);
  std::uniform_int_distribution<int> kind(0, 99);
  std::uniform_real_distribution<double> u(0.05, 0.9);
  std::vector<float> xy;
  for (std::size_t i = 0; i < scan.numCells(); ++i)
  {
    const double m = u(rng);
    const bool obstacle = kind(rng) < 2;
    scan.setCell(i, obstacle ? MassSG{ { FrameSG::kO, m }, { FrameSG::kOmega, 1.0 - m } }
                             : MassSG{ { FrameSG::kF, m }, { FrameSG::kOmega, 1.0 - m } });
    if (obstacle)
    {
      const Point2 c = sg.cellCentre(sg.cellOf(i));
      xy.push_back(static_cast<float>(c.x));
      xy.push_back(static_cast<float>(c.y));
    }
  }
  const ObstaclePoints points{ xy.data(), xy.size() / 2 };
  const auto window = GridGeometry::centred(36.0, 28.0, kRes);
  ScanMassGrid plain, cleared;
  for (const ObstaclePoints* obstacles : { static_cast<const ObstaclePoints*>(nullptr), &points })
    for (int k : { 1, 3, 7 })
      for (double yaw : { 0.0, 0.6, -2.3 })
      {
        const Pose2 pose{ 1.1, -0.4, yaw };
        projectScan(scan, pose, window, plain, obstacles, 0);
        projectScan(scan, pose, window, cleared, obstacles, k);
        std::size_t near_obstacle = 0, mismatches = 0;
        for (int y = 0; y < window.height; ++y)
          for (int x = 0; x < window.width; ++x)
          {
            bool near = false;
            for (int yy = std::max(0, y - k); yy <= std::min(window.height - 1, y + k) && !near; ++yy)
              for (int xx = std::max(0, x - k); xx <= std::min(window.width - 1, x + k) && !near; ++xx)
                near = plain.at(FrameSG::kO, window.index(xx, yy)) > 0.0f;
            const std::size_t j = window.index(x, y);
            const float f = plain.at(FrameSG::kF, j), w = plain.at(FrameSG::kOmega, j);
            near_obstacle += near && f > 0.0f;
            mismatches += cleared.at(FrameSG::kF, j) != (near ? 0.0f : f) ||
                          cleared.at(FrameSG::kOmega, j) != (near ? w + f : w) ||
                          cleared.at(FrameSG::kO, j) != plain.at(FrameSG::kO, j);
          }
        EXPECT_GT(near_obstacle, 50u) << "k " << k << " yaw " << yaw;
        EXPECT_EQ(mismatches, 0u) << "k " << k << " yaw " << yaw << (obstacles ? " with points" : "");
      }
}

TEST(ExtractPriorWindow, MapConflictInTheSamePassEqualsTheTwoSteps)
{
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 0.9f);
  PriorWindow prior(GridGeometry::centred(30.0, 30.0, kRes));
  for (std::size_t i = 0; i < prior.building.size(); ++i)
  {
    prior.building[i] = u(rng) * 0.3f;
    prior.road[i] = u(rng) * 0.3f;
    prior.wall[i] = u(rng) * 0.3f;
    prior.other[i] = u(rng) * 0.1f;
  }
  // Aligned and half outside; not aligned (a third of a cell off): each cell sampled.
  for (const GridGeometry& window : { GridGeometry::centred(20.0, 16.0, kRes, 12.0, -3.0),
                                      GridGeometry::centred(20.0, 16.0, kRes, 2.0 + kRes / 3.0, 1.0) })
  {
    ScanMassGrid scan(window);
    for (std::size_t i = 0; i < scan.numCells(); ++i) scan.setCell(i, maf_test::randomMass<FrameSG>(rng, 3));
    AlignedVector<float> doubt_two(window.numCells(), 0.1f), doubt_one = doubt_two;
    PriorWindow two, one;
    for (int step = 0; step < 3; ++step)  // η accumulates
    {
      extractPriorWindow(prior, window, two);
      applyMapConflict(two, scan, 0.3, doubt_two);
      extractPriorWindow(prior, window, one, MapConflict{ &scan, 0.3, &doubt_one });
    }
    float largest = 0.0f;
    for (float e : doubt_one) largest = std::max(largest, e);
    EXPECT_GT(largest, 0.1f) << "the scan must raise the doubt somewhere";
    EXPECT_EQ(std::memcmp(doubt_one.data(), doubt_two.data(), doubt_one.size() * sizeof(float)), 0);
    for (auto plane : { &PriorWindow::building, &PriorWindow::road, &PriorWindow::other, &PriorWindow::wall })
      EXPECT_EQ(std::memcmp((one.*plane).data(), (two.*plane).data(), (one.*plane).size() * sizeof(float)), 0);
  }
  PriorWindow out;
  AlignedVector<float> doubt;
  ScanMassGrid small(GridGeometry::centred(4.0, 4.0, kRes));
  const MapConflict mismatched{ &small, 0.2, &doubt };  // a scan of another size than the window
  EXPECT_THROW(extractPriorWindow(prior, GridGeometry::centred(8.0, 8.0, kRes), out, mismatched), std::invalid_argument);
}

TEST(AlignedPriorStart, IsTheIndexOfTheWindowsFirstCellOnlyWhenTheWholeWindowLiesOnThePriorsLattice)
{
  const GridGeometry prior = GridGeometry::centred(30.0, 20.0, kRes);  // 60 × 40 cells, origin (−15, −10)
  const GridGeometry inside = GridGeometry::centred(8.0, 4.0, kRes, 2.0, -1.0);  // origin (−2, −3): cell (26, 14)
  ASSERT_TRUE(alignedPriorStart(prior, inside).has_value());
  EXPECT_EQ(*alignedPriorStart(prior, inside), 14u * 60u + 26u);
  EXPECT_EQ(*alignedPriorStart(prior, prior), 0u);
  EXPECT_FALSE(alignedPriorStart(prior, GridGeometry::centred(8.0, 4.0, kRes, 12.0, 0.0)));  // over the right edge
  EXPECT_FALSE(alignedPriorStart(prior, GridGeometry::centred(8.0, 4.0, kRes, 0.0, -9.0)));  // below the first row
  EXPECT_FALSE(alignedPriorStart(prior, GridGeometry::centred(8.0, 4.0, kRes / 2.0)));       // twice as fine
  // A window off the lattice by less than half a cell samples the same cells: still consecutive.
  const GridGeometry off = GridGeometry::centred(8.0, 4.0, kRes, 2.0 + kRes / 3.0, -1.0);
  EXPECT_EQ(alignedPriorStart(prior, off), alignedPriorStart(prior, inside));
}

TEST(FusionStep, ReadingThePriorsRowsWithItsDoubtEqualsTheExtractedWindowWithItsConflict)
{
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  PriorWindow prior(GridGeometry::centred(40.0, 30.0, kRes));  // 80 × 60 cells
  for (std::size_t i = 0; i < prior.building.size(); ++i)
  {
    const float total = 0.95f * u(rng);
    const int kind = static_cast<int>(rng() % 4);
    (kind == 0 ? prior.building : kind == 1 ? prior.road : kind == 2 ? prior.other : prior.wall)[i] = total;
  }
  const GridGeometry window = GridGeometry::centred(16.0, 12.0, kRes, 3.0, -2.0);  // 32 × 24 cells
  const auto first = alignedPriorStart(prior.geometry, window);
  ASSERT_TRUE(first.has_value());
  FusionParams params;
  constexpr double kGain = 0.3;
  const std::size_t floats =
      (window.numCells() + MapMassGrid::kBlockCells - 1) / MapMassGrid::kBlockCells * MapMassGrid::kBlockFloats;
  // Three ways to the same step: the prior's rows (MapGrid::update); its window copied, the doubt in the step (the
  // update's fallback); the window discounted by applyMapConflict() first (the two public steps).
  struct Path
  {
    MapMassGrid map;
    AlignedVector<float> doubt;
    PignisticPlanes betp;
    std::vector<std::int8_t> decision;
  };
  for (int threads : { 1, 2 })
  {
    const Parallel parallel(threads);
    Path rows{ MapMassGrid(window), AlignedVector<float>(window.numCells(), 0.05f), {}, {} };
    Path copied = rows, separate = rows;
    std::mt19937 scans(3);
    for (int step = 0; step < 4; ++step)
    {
      ScanMassGrid scan(window);
      for (std::size_t i = 0; i < scan.numCells(); ++i) scan.setCell(i, maf_test::randomMass<FrameSG>(scans, 3));
      auto run = [&](Path& p, const StepPrior& sp) {
        StepDecisions d;
        d.out = &p.decision;
        FusionStepStats s;
        fusionStep(p.map, scan, sp, params, &s, &p.betp, &parallel, &d);
        return s;
      };
      StepPrior by_rows{ &prior, *first, static_cast<std::size_t>(prior.geometry.width), rows.doubt.data(), kGain };
      const FusionStepStats s_rows = run(rows, by_rows);
      PriorWindow w;
      extractPriorWindow(prior, window, w);
      const FusionStepStats s_copied =
          run(copied, StepPrior{ &w, 0, static_cast<std::size_t>(window.width), copied.doubt.data(), kGain });
      extractPriorWindow(prior, window, w, MapConflict{ &scan, kGain, &separate.doubt });
      StepDecisions d;
      d.out = &separate.decision;
      FusionStepStats s_separate;
      fusionStep(separate.map, scan, &w, params, &s_separate, &separate.betp, &parallel, &d);
      EXPECT_EQ(s_rows.num_cells, window.numCells());
      EXPECT_NEAR(s_rows.meanConflict(), s_copied.meanConflict(), 1e-6);
      EXPECT_NEAR(s_rows.meanConflict(), s_separate.meanConflict(), 1e-5);
    }
    float largest = 0.0f;
    for (float e : rows.doubt) largest = std::max(largest, e);
    EXPECT_GT(largest, 0.05f) << "the scans must raise the doubt somewhere";
    // The same kernel: the same bits.
    EXPECT_EQ(std::memcmp(rows.doubt.data(), copied.doubt.data(), rows.doubt.size() * sizeof(float)), 0) << threads;
    EXPECT_EQ(std::memcmp(rows.map.planes(), copied.map.planes(), floats * sizeof(float)), 0) << threads;
    for (int e = 0; e < FrameMG::kSize; ++e)
      EXPECT_EQ(std::memcmp(rows.betp[e].data(), copied.betp[e].data(), window.numCells() * sizeof(float)), 0) << e;
    EXPECT_EQ(rows.decision, copied.decision);
    // The separate steps: the same up to the rounding of η (contracted into an FMA or not).
    for (std::size_t i = 0; i < window.numCells(); ++i)
    {
      EXPECT_NEAR(rows.doubt[i], separate.doubt[i], 1e-6) << i;
      for (int e = 0; e < FrameMG::kSize; ++e) EXPECT_NEAR(rows.betp[e][i], separate.betp[e][i], 1e-5) << i;
    }
    for (std::size_t f = 0; f < floats; ++f) ASSERT_NEAR(rows.map.planes()[f], separate.map.planes()[f], 1e-5) << f;
  }
  // Rows of another width need whole blocks per row; and the window must lie inside the prior.
  const GridGeometry odd = GridGeometry::centred(16.5, 12.0, kRes, 3.0, -2.0);  // 33 cells a row
  MapMassGrid m(odd);
  ScanMassGrid scan(odd);
  StepPrior rows;
  rows.grid = &prior;
  rows.first = *alignedPriorStart(prior.geometry, odd);
  rows.row_stride = static_cast<std::size_t>(prior.geometry.width);
  EXPECT_THROW(fusionStep(m, scan, rows, params), std::invalid_argument);
  MapMassGrid big(window);
  ScanMassGrid big_scan(window);
  rows.first = prior.building.size() - 10;
  EXPECT_THROW(fusionStep(big, big_scan, rows, params), std::invalid_argument);
}

TEST(MapGrid, PriorWindowIsThePriorOfTheUpdateDiscountedByTheMapDoubt)
{
  MapGridParams params;
  params.size_x = params.size_y = 8.0;
  params.resolution = kRes;
  params.recentre_distance = 1.0;
  MapGrid grid(params);
  PriorWindow prior(GridGeometry::centred(20.0, 20.0, kRes));
  std::fill(prior.building.begin(), prior.building.end(), 0.9f);  // a mapped building the lidar sees through
  ScanMassGrid scan(GridGeometry::centred(8.0, 8.0, kRes));
  for (std::size_t i = 0; i < scan.numCells(); ++i) scan.setCell(i, kFreeScan);
  for (int k = 0; k < 3; ++k) grid.update(scan, Pose2{}, 0.1 * k, &prior);
  PriorWindow w;
  grid.priorWindow(&prior, w);
  ASSERT_EQ(w.geometry, grid.geometry());
  const AlignedVector<float>& doubt = grid.mapDoubt();
  for (std::size_t i = 0; i < w.building.size(); ++i)
  {
    EXPECT_NEAR(doubt[i], 3 * 0.2 * 0.9 * 0.7, 1e-5) << i;
    EXPECT_EQ(w.building[i], 0.9f * (1.0f - doubt[i])) << i;
    EXPECT_EQ(w.road[i] + w.other[i] + w.wall[i], 0.0f) << i;
  }
  grid.priorWindow(nullptr, w);
  for (std::size_t i = 0; i < w.building.size(); ++i) EXPECT_EQ(w.building[i], 0.0f) << i;
}

TEST(ExtractPriorWindow, CopiesAlignedCellsAndIsVacuousOutside)
{
  const PriorWindow prior = scriptedPrior();
  auto window = GridGeometry::centred(20.0, 20.0, kRes, 45.0, 0.0);  // half outside the prior
  PriorWindow out;
  extractPriorWindow(prior, window, out);
  for (int y = 0; y < window.height; ++y)
    for (int x = 0; x < window.width; ++x)
    {
      const Point2 p = window.cellCentre(CellIndex{ x, y });
      const std::size_t j = window.index(x, y);
      CellIndex pc;
      if (prior.geometry.worldToCell(p, pc))
      {
        ASSERT_EQ(out.road[j], prior.road[prior.geometry.index(pc)]);
        ASSERT_EQ(out.other[j], prior.other[prior.geometry.index(pc)]);
      }
      else
      {
        ASSERT_EQ(out.building[j] + out.road[j] + out.other[j], 0.0f);
      }
    }
}

TEST(MapGridScene, CarCrossingIsMovingAndLeavesNoTrail)
{
  MapGrid mg(defaultParams());
  const PriorWindow prior = scriptedPrior();
  // Free road for 1 s, then a 4 m × 2 m car driving at 10 m/s (one metre per scan) along y = 0.
  for (int t = 0; t < 10; ++t) mg.update(scriptedScan({}), Pose2{}, 0.1 * t, &prior);
  double x_car = -15.0;
  for (int t = 10; t < 40; ++t, x_car += 1.0)
  {
    mg.update(scriptedScan({ Box{ x_car, -1.0, x_car + 4.0, 1.0 } }), Pose2{}, 0.1 * t, &prior);
    if (t < 13) continue;
    const auto o = outputs(mg);
    EXPECT_EQ(classAt(mg, o, Point2{ x_car + 3.75, 0.25 }), CellClass::kMoving) << "front of the car at scan " << t;
    // Where the car was 1 s ago (10 scans), no V is left.
    if (t >= 22)
    {
      for (double x = x_car - 10.0; x < x_car - 6.0; x += kRes)
        EXPECT_NE(classAt(mg, o, Point2{ x + 0.25, 0.25 }), CellClass::kMoving) << "trail at x=" << x << " scan " << t;
    }
  }
  const auto o = outputs(mg);
  const auto objects = extractObjects(mg.geometry(), o.decision, o.betp, mg.params());
  int moving = 0;
  for (const auto& obj : objects)
    if (obj.cell_class == CellClass::kMoving)
    {
      ++moving;
      EXPECT_NEAR(obj.centroid.y, 0.0, 1.0);
      EXPECT_GT(obj.centroid.x, x_car - 3.0);
    }
  EXPECT_GE(moving, 1);
}

TEST(MapGridScene, BusThatStopsEndsStopped)
{
  MapGrid mg(defaultParams());
  const PriorWindow prior = scriptedPrior();
  for (int t = 0; t < 10; ++t) mg.update(scriptedScan({}), Pose2{}, 0.1 * t, &prior);
  // A 12 m bus drives 1 m per scan for 5 scans, then stays for 5 s.
  double x = -20.0;
  int t = 10;
  for (; t < 15; ++t, x += 1.0) mg.update(scriptedScan({ Box{ x, -1.5, x + 12.0, 1.5 } }), Pose2{}, 0.1 * t, &prior);
  const Box parked{ x, -1.5, x + 12.0, 1.5 };
  for (; t < 65; ++t) mg.update(scriptedScan({ parked }), Pose2{}, 0.1 * t, &prior);
  const auto o = outputs(mg);
  int stopped = 0, moving = 0, cells = 0;
  for (double px = parked.x0 + 0.25; px < parked.x1; px += kRes)
    for (double py = parked.y0 + 0.25; py < parked.y1; py += kRes)
    {
      const auto c = classAt(mg, o, Point2{ px, py });
      stopped += c == CellClass::kStopped;
      moving += c == CellClass::kMoving;
      ++cells;
    }
  EXPECT_GT(stopped, cells * 9 / 10);
  EXPECT_EQ(moving, 0);
}

TEST(MapGridScene, PoleOnPavementIsInfrastructureOrStoppedNeverMoving)
{
  MapGrid mg(defaultParams());
  const PriorWindow prior = scriptedPrior();
  const Box pole{ 5.0, 6.0, 5.5, 6.5 };  // on the pavement (T)
  for (int t = 0; t < 40; ++t)
  {
    mg.update(scriptedScan({ pole }), Pose2{}, 0.1 * t, &prior);
    const auto o = outputs(mg);
    const auto c = classAt(mg, o, Point2{ 5.25, 6.25 });
    EXPECT_NE(c, CellClass::kMoving) << "scan " << t;
    if (t > 5)
    {
      EXPECT_TRUE(c == CellClass::kInfrastructure || c == CellClass::kStopped) << "scan " << t;
    }
  }
  const auto m = mg.masses().cell(mg.geometry().index(mg.geometry().cellAt(Point2{ 5.25, 6.25 })));
  EXPECT_LT(m[FrameMG::kV], 1e-3);
}

TEST(MapGridScene, BuildingIsCWithPriorAndAmbiguousWithout)
{
  const Box wall{ 10.0, 8.0, 16.0, 14.0 };
  const Point2 inside{ 12.25, 10.25 };
  for (bool with_prior : { true, false })
  {
    MapGrid mg(defaultParams());
    const PriorWindow prior = scriptedPrior();
    for (int t = 0; t < 30; ++t) mg.update(scriptedScan({ wall }), Pose2{}, 0.1 * t, with_prior ? &prior : nullptr);
    const auto o = outputs(mg);
    const auto m = mg.masses().cell(mg.geometry().index(mg.geometry().cellAt(inside)));
    int largest = 1;
    for (int a = 2; a < 32; ++a)
      if (m[a] > m[largest]) largest = a;
    if (with_prior)
    {
      EXPECT_EQ(classAt(mg, o, inside), CellClass::kBuilding);
      EXPECT_EQ(largest, FrameMG::kC);
    }
    else
    {
      // Occupied without knowing by what: the mass stays on a set of several occupied classes.
      EXPECT_TRUE(isSubsetOf(static_cast<Subset>(largest), FrameMG::kO)) << subsetName<FrameMG>(largest);
      EXPECT_GE(cardinality(static_cast<Subset>(largest)), 3) << subsetName<FrameMG>(largest);
      EXPECT_NE(classAt(mg, o, inside), CellClass::kBuilding);
      EXPECT_NE(classAt(mg, o, inside), CellClass::kMoving);
    }
  }
}

TEST(MapGrid, FollowsTheVehicleByWholeCells)
{
  MapGridParams params = defaultParams();
  params.recentre_distance = 0.0;
  MapGrid mg(params);
  mg.update(scriptedScan({}), Pose2{ 0.0, 0.0, 0.0 }, 0.0, nullptr);
  const auto g0 = mg.geometry();
  mg.update(scriptedScan({}), Pose2{ 3.3, -1.1, 0.2 }, 0.1, nullptr);
  const auto g1 = mg.geometry();
  const double sx = (g1.origin_x - g0.origin_x) / kRes, sy = (g1.origin_y - g0.origin_y) / kRes;
  EXPECT_DOUBLE_EQ(sx, std::round(sx));
  EXPECT_DOUBLE_EQ(sy, std::round(sy));
  EXPECT_NEAR(g1.origin_x + 0.5 * g1.sizeX(), 3.3, kRes);
  EXPECT_NEAR(g1.origin_y + 0.5 * g1.sizeY(), -1.1, kRes);
  EXPECT_EQ(mg.scans(), 2u);
  // With slack, the window stays put until the vehicle is farther than recentre_distance from its centre.
  params.recentre_distance = 4.0;
  MapGrid lazy(params);
  lazy.update(scriptedScan({}), Pose2{}, 0.0, nullptr);
  const auto l0 = lazy.geometry();
  lazy.update(scriptedScan({}), Pose2{ 3.9, -3.9, 0.0 }, 0.1, nullptr);
  EXPECT_EQ(lazy.geometry(), l0);
  lazy.update(scriptedScan({}), Pose2{ 4.2, 0.0, 0.0 }, 0.2, nullptr);
  EXPECT_NEAR(lazy.geometry().origin_x + 0.5 * lazy.geometry().sizeX(), 4.2, kRes);
  mg.reset();
  EXPECT_EQ(mg.scans(), 0u);
}

TEST(MapGrid, RatesPerSecondForgetByElapsedTime)
{
  MapGridParams p = defaultParams();
  p.rates_per_second = true;
  p.fusion.discount = ContextualRates{ 0.1, 0.5, 0.3 };
  MapGrid a(p), b(p);
  const auto occupied = scriptedScan({ Box{ 2.0, 2.0, 3.0, 3.0 } });
  const auto nothing = scriptedScan({}, 0.0);
  a.update(occupied, Pose2{}, 0.0, nullptr);
  b.update(occupied, Pose2{}, 0.0, nullptr);
  // a: one empty scan 2 s later; expected: the reference step with rates 1 − (1 − α)^2.
  a.update(nothing, Pose2{}, 2.0, nullptr);
  const std::size_t k = b.geometry().index(b.geometry().cellAt(Point2{ 2.25, 2.25 }));
  FusionParams two_seconds = p.fusion;
  two_seconds.discount = p.fusion.discount.compounded(2.0);
  const auto expected = fuseCell(b.masses().cell(k), b.masses().zeta(k), MassSG::vacuous(), MassMG::vacuous(),
                                 two_seconds);
  EXPECT_TRUE(maf_test::massNear(a.masses().cell(k), expected.mass, 1e-5));
  const auto per_scan = fuseCell(b.masses().cell(k), b.masses().zeta(k), MassSG::vacuous(), MassMG::vacuous(),
                                 p.fusion);
  EXPECT_FALSE(maf_test::massNear(a.masses().cell(k), per_scan.mass, 1e-3)) << "2 s must forget more than one scan";
}

TEST(MapGrid, RejectsBadParametersNamingThem)
{
  MapGridParams p = defaultParams();
  p.resolution = -1.0;
  try
  {
    MapGrid mg(p);
    FAIL();
  }
  catch (const ParameterError& e)
  {
    EXPECT_EQ(e.parameter(), "resolution");
  }
  p = defaultParams();
  p.min_object_cells = 0;
  EXPECT_THROW(MapGrid{ p }, ParameterError);
  p = defaultParams();
  p.size_x = 1e6;
  EXPECT_THROW(MapGrid{ p }, ParameterError);
}

TEST(Objects, ConnectedRegionsWithExtentAndClass)
{
  const GridGeometry g{ 1.0, 10, 8, 0.0, 0.0 };
  std::vector<std::int8_t> decision(g.numCells(), static_cast<std::int8_t>(CellClass::kFree));
  PignisticPlanes betp;
  for (auto& p : betp.p) p.assign(g.numCells(), 0.0f);
  // A 4 × 2 moving block at x ∈ [1, 5), y ∈ [1, 3) and a stopped 2 × 3 block at x ∈ [7, 9), y ∈ [4, 7).
  for (int y = 1; y < 3; ++y)
    for (int x = 1; x < 5; ++x)
    {
      decision[g.index(x, y)] = static_cast<std::int8_t>(CellClass::kMoving);
      betp.p[4][g.index(x, y)] = 0.8f;
    }
  for (int y = 4; y < 7; ++y)
    for (int x = 7; x < 9; ++x)
    {
      decision[g.index(x, y)] = static_cast<std::int8_t>(CellClass::kStopped);
      betp.p[3][g.index(x, y)] = 0.6f;
    }
  decision[g.index(0, 7)] = static_cast<std::int8_t>(CellClass::kMoving);  // a single cell: noise
  const auto objects = extractObjects(g, decision, betp, MapGridParams{});
  ASSERT_EQ(objects.size(), 2u);
  const auto& car = objects[0].cell_class == CellClass::kMoving ? objects[0] : objects[1];
  const auto& bus = objects[0].cell_class == CellClass::kMoving ? objects[1] : objects[0];
  EXPECT_EQ(car.cells, 8);
  EXPECT_NEAR(car.centroid.x, 3.0, 1e-9);
  EXPECT_NEAR(car.centroid.y, 2.0, 1e-9);
  EXPECT_NEAR(car.length, 4.0, 1e-9);
  EXPECT_NEAR(car.width, 2.0, 1e-9);
  EXPECT_NEAR(std::abs(std::cos(car.yaw)), 1.0, 1e-9);
  EXPECT_NEAR(car.mean_betp, 0.8, 1e-6);
  EXPECT_EQ(bus.cell_class, CellClass::kStopped);
  EXPECT_EQ(bus.cells, 6);
  EXPECT_NEAR(bus.length, 3.0, 1e-9);
  EXPECT_NEAR(bus.width, 2.0, 1e-9);
  EXPECT_NEAR(bus.centroid.x, 8.0, 1e-9);
  EXPECT_NEAR(bus.centroid.y, 5.5, 1e-9);
}

TEST(Objects, WallsFencesAndHugeRegionsAreNotObjects)
{
  const GridGeometry g{ 0.5, 100, 100, 0.0, 0.0 };
  std::vector<std::int8_t> decision(g.numCells(), static_cast<std::int8_t>(CellClass::kFree));
  PignisticPlanes betp;
  for (auto& p : betp.p) p.assign(g.numCells(), 0.5f);
  const auto fill = [&](int x0, int y0, int x1, int y1, CellClass c) {
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) decision[g.index(x, y)] = static_cast<std::int8_t>(c);
  };
  fill(2, 2, 22, 3, CellClass::kStopped);    // a fence: 10 m x 0.5 m
  fill(2, 10, 52, 12, CellClass::kStopped);  // a wall: 25 m x 1 m
  fill(60, 60, 80, 80, CellClass::kStopped); // a 10 m x 10 m block: 100 m^2
  fill(2, 30, 11, 34, CellClass::kStopped);  // a parked car: 4.5 m x 2 m
  fill(2, 40, 24, 41, CellClass::kMoving);   // a moving bus seen side-on: 11 m x 0.5 m, moving: kept
  fill(30, 30, 40, 31, CellClass::kStopped); // a parked car seen side-on: 5 m x 0.5 m, kept
  MapGridParams p;
  const auto objects = extractObjects(g, decision, betp, p);
  ASSERT_EQ(objects.size(), 3u);
  for (const auto& o : objects) EXPECT_LE(o.length, 11.0 + 1e-9);
  // The limits are parameters: without them every region is an object.
  p.max_object_length = p.max_object_area = 1000.0;
  p.thin_structure_width = 0.0;
  EXPECT_EQ(extractObjects(g, decision, betp, p).size(), 6u);
  p.max_object_area = -1.0;
  try
  {
    p.validate();
    FAIL() << "max_object_area -1 accepted";
  }
  catch (const ParameterError& e)
  {
    EXPECT_NE(std::string(e.what()).find("max_object_area"), std::string::npos);
  }
}

TEST(MapGridParams, CombinationRuleIsAParameterNamedInErrors)
{
  for (CombinationRule r : { CombinationRule::kModifiedYager, CombinationRule::kYager, CombinationRule::kDempster })
    EXPECT_EQ(parseCombinationRule(toString(r)), r);
  EXPECT_STREQ(toString(MapGridParams{}.fusion.rule), "modified_yager") << "the paper's rule by default";
  auto withRule = [](const std::string& name) {
    MapGridParams p;
    forEachParam(p, [&](const std::string& key, auto& value, const ParamDoc&) {
      if constexpr (std::is_same_v<std::decay_t<decltype(value)>, std::string>)
        if (key == "combination_rule") value = name;
    });
    return p.fusion.rule;
  };
  EXPECT_EQ(withRule("dempster"), CombinationRule::kDempster);
  EXPECT_EQ(withRule("yager"), CombinationRule::kYager);
  try
  {
    withRule("murphy");
    FAIL() << "an unknown rule must be refused";
  }
  catch (const ParameterError& e)
  {
    EXPECT_EQ(e.parameter(), "combination_rule");
  }
}

// Cell coverage, the outline focal set W = {F, C}, softening by position uncertainty, the pose covariance, the
// navigable layer and the map-conflict step: exact values from their definitions and invariants.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "map_aided_fusion/core/cell_class.hpp"
#include "map_aided_fusion/core/fusion.hpp"
#include "map_aided_fusion/core/map_grid.hpp"
#include "map_aided_fusion/core/prior_grid.hpp"
#include "map_aided_fusion/core/prior_uncertainty.hpp"

namespace {

using namespace map_aided_fusion::core;

constexpr float kTol = 1e-6f;
const PriorConfidence kBeta{ 0.9, 0.85, 0.8 };

Polygon square(double x0, double y0, double x1, double y1)
{
  return Polygon{ Ring{ { x0, y0 }, { x1, y0 }, { x1, y1 }, { x0, y1 } }, {} };
}

GridGeometry grid10()
{
  return GridGeometry{ 0.5, 20, 20, 0.0, 0.0 };
}

PriorWindow coverageWindow(const VectorMap& map, PriorBuildStats* stats = nullptr)
{
  PriorGrid g;
  g.build(map, grid10(), stats, PriorCellTest::kCoverage);
  PriorWindow w;
  g.fillWindow(g.geometry(), kBeta, w);
  return w;
}

void expectValid(const PriorWindow& w)
{
  for (std::size_t i = 0; i < w.geometry.numCells(); ++i)
  {
    for (float v : { w.building[i], w.road[i], w.other[i], w.wall[i] }) ASSERT_GE(v, 0.0f) << i;
    ASSERT_LE(w.building[i] + w.road[i] + w.other[i] + w.wall[i], 1.0f + kTol) << i;
  }
}

}  // namespace

TEST(CellCoverage, OutlineCellsAreWallInteriorIsBuildingOutsideIsOther)
{
  VectorMap map;
  map.buildings.push_back(Building{ square(1.25, 1.25, 3.25, 3.25), 10.0, "b" });
  PriorBuildStats stats;
  const PriorWindow w = coverageWindow(map, &stats);
  const GridGeometry g = grid10();
  // Edges at 1.25 and 3.25 run through columns/rows 2 and 6; 3..5 are inside, the rest outside.
  for (int y = 0; y < g.height; ++y)
    for (int x = 0; x < g.width; ++x)
    {
      const std::size_t i = g.index(x, y);
      const bool in_box = x >= 2 && x <= 6 && y >= 2 && y <= 6;
      const bool interior = x >= 3 && x <= 5 && y >= 3 && y <= 5;
      if (interior)
        EXPECT_FLOAT_EQ(w.building[i], 0.9f) << x << "," << y;
      else if (in_box)
        EXPECT_FLOAT_EQ(w.wall[i], 0.9f) << x << "," << y;
      else
        EXPECT_FLOAT_EQ(w.other[i], 0.8f) << x << "," << y;
    }
  EXPECT_EQ(stats.outline_cells, 16u);
  // The centre test calls the same cells by their centres: 1.25 lies on column 2's centre (inside, half-open).
  PriorGrid centre;
  centre.build(map, g, nullptr, PriorCellTest::kCentre);
  EXPECT_EQ(centre.label(CellIndex{ 2, 2 }), PriorClass::kBuilding);
  EXPECT_EQ(centre.label(CellIndex{ 6, 6 }), PriorClass::kOther);
}

TEST(CellCoverage, MixedRoadCellIsTheLinearPoolOfItsAreas)
{
  VectorMap map;
  map.road_areas.push_back(square(0.0, 0.0, 2.25, 10.0));  // columns 0..3 road, column 4 half road
  const PriorWindow w = coverageWindow(map);
  const GridGeometry g = grid10();
  const std::size_t half = g.index(4, 5), full = g.index(1, 5), none = g.index(8, 5);
  EXPECT_NEAR(w.road[half], 0.85f * 0.5f, kTol);
  EXPECT_NEAR(w.other[half], 0.8f * 0.5f, kTol);
  EXPECT_NEAR(w.road[full], 0.85f, kTol);
  EXPECT_NEAR(w.other[full], 0.0f, kTol);
  EXPECT_NEAR(w.other[none], 0.8f, kTol);
  expectValid(w);
}

TEST(CellCoverage, SharedWallOfTwoBuildingsIsInteriorAndDegeneratePolygonsStayInTheirBox)
{
  VectorMap map;
  map.buildings.push_back(Building{ square(1.0, 1.0, 3.1, 3.0), 10.0, "a" });
  map.buildings.push_back(Building{ square(3.1, 1.0, 5.0, 3.0), 10.0, "b" });
  // Zero area (collinear) and self-touching (a bow tie touching itself at (8, 8)).
  map.buildings.push_back(Building{ Polygon{ Ring{ { 7.0, 6.0 }, { 8.0, 6.0 }, { 9.0, 6.0 } }, {} }, 5.0, "flat" });
  map.buildings.push_back(
      Building{ Polygon{ Ring{ { 7.0, 7.0 }, { 9.0, 9.0 }, { 9.0, 7.0 }, { 7.0, 9.0 } }, {} }, 5.0, "bow" });
  PriorGrid grid;
  ASSERT_NO_THROW(grid.build(map, grid10(), nullptr, PriorCellTest::kCoverage));
  // The cell the shared wall x = 3.1 crosses (column 6) is inside both: interior, not outline.
  EXPECT_FALSE(grid.outline(CellIndex{ 6, 4 }));
  EXPECT_DOUBLE_EQ(grid.buildingCoverage(CellIndex{ 6, 4 }), 1.0);
  EXPECT_TRUE(grid.outline(CellIndex{ 10, 4 }));  // x = 5.0 is column 10's left edge: the walk marks column 10
  const GridGeometry& g = grid.geometry();
  for (int y = 0; y < g.height; ++y)
    for (int x = 0; x < g.width; ++x)
    {
      const Point2 c = g.cellCentre(CellIndex{ x, y });
      const bool near_degenerate = c.x > 6.5 && c.x < 9.5 && c.y > 5.5 && c.y < 9.5;
      const bool near_pair = c.x > 0.5 && c.x < 5.5 && c.y > 0.5 && c.y < 3.5;
      if (!near_degenerate && !near_pair)
      {
        EXPECT_FALSE(grid.outline(CellIndex{ x, y })) << x << "," << y;
        EXPECT_EQ(grid.buildingCoverage(CellIndex{ x, y }), 0.0) << x << "," << y;
      }
    }
}

TEST(Softening, ZeroSigmaIsTheIdentityAndMassesStayValid)
{
  VectorMap map;
  map.buildings.push_back(Building{ square(2.0, 2.0, 6.3, 5.1), 10.0, "b" });
  map.road_areas.push_back(square(0.0, 6.0, 10.0, 8.2));
  const PriorWindow raw = coverageWindow(map);
  PriorWindow same;
  softenPrior(raw, 0.0, 0.0, same);
  for (std::size_t i = 0; i < raw.geometry.numCells(); ++i)
  {
    ASSERT_EQ(same.building[i], raw.building[i]);
    ASSERT_EQ(same.road[i], raw.road[i]);
    ASSERT_EQ(same.other[i], raw.other[i]);
    ASSERT_EQ(same.wall[i], raw.wall[i]);
  }
  for (double sb : { 0.2, 0.5, 1.5 })
    for (double sr : { 0.0, 0.7 })
    {
      PriorWindow soft;
      softenPrior(raw, sb, sr, soft);
      expectValid(soft);
    }
  PriorWindow out;
  EXPECT_THROW(softenPrior(raw, -0.1, 0.0, out), ParameterError);
  EXPECT_THROW(softenPrior(raw, 0.0, kMaxPositionSigma + 1.0, out), ParameterError);
}

TEST(Softening, OutlineMassIsAGaussianPossibilityAroundTheWall)
{
  const GridGeometry g = grid10();
  PriorWindow raw(g);
  for (std::size_t i = 0; i < g.numCells(); ++i) raw.other[i] = 0.8f;
  const std::size_t w = g.index(10, 10);
  raw.other[w] = 0.0f;
  raw.wall[w] = 0.9f;
  const double sigma = 0.5;
  PriorWindow soft;
  softenPrior(raw, sigma, 0.0, soft);
  EXPECT_NEAR(soft.wall[w], 0.9f, kTol);
  for (int d : { 1, 2 })
  {
    const double expected = 0.9 * std::exp(-0.5 * std::pow(d * 0.5 / sigma, 2));
    EXPECT_NEAR(soft.wall[g.index(10 + d, 10)], expected, 1e-6) << d;
    EXPECT_NEAR(soft.wall[g.index(10, 10 - d)], expected, 1e-6) << d;
    EXPECT_NEAR(soft.wall[g.index(10 + d, 10 + d)], 0.9 * std::exp(-std::pow(d * 0.5 / sigma, 2)), 1e-6) << d;
  }
  EXPECT_EQ(soft.wall[g.index(0, 0)], 0.0f);
  expectValid(soft);
}

TEST(Softening, TheSoftenerRecomputesOnlyWhenSigmaMovesOrThePriorChanges)
{
  auto raw = std::make_shared<PriorWindow>(grid10());
  raw->wall[grid10().index(5, 5)] = 0.9f;
  PriorSoftener s(0.05);
  bool again = false;
  EXPECT_EQ(s.softened(0.3, &again), nullptr);
  s.setPrior(raw);
  ASSERT_NE(s.softened(0.3, &again), nullptr);
  EXPECT_TRUE(again);
  s.softened(0.32, &again);
  EXPECT_FALSE(again);
  EXPECT_DOUBLE_EQ(s.sigmaInForce(), 0.3);
  s.softened(std::numeric_limits<double>::quiet_NaN(), &again);
  EXPECT_FALSE(again);
  s.softened(0.5, &again);
  EXPECT_TRUE(again);
  s.softened(50.0, &again);
  EXPECT_DOUBLE_EQ(s.sigmaInForce(), kMaxPositionSigma);
  s.setPrior(raw);
  s.softened(kMaxPositionSigma, &again);
  EXPECT_TRUE(again);
}

TEST(PoseCovariance, SigmaIsTheLargestStandardDeviationOfThePositionAndFaultsAreNamed)
{
  std::array<double, 36> c{};
  c[0] = 0.09;
  c[7] = 0.04;
  c[35] = 0.01;
  double sigma = -1.0;
  ASSERT_EQ(positionSigma(c, sigma), CovarianceFault::kNone);
  EXPECT_NEAR(sigma, 0.3, 1e-12);
  c[1] = c[6] = 0.06;  // x-y block [[0.09, 0.06], [0.06, 0.04]]: eigenvalues 0.13 and 0
  ASSERT_EQ(positionSigma(c, sigma), CovarianceFault::kNone);
  EXPECT_NEAR(sigma, std::sqrt(0.13), 1e-12);
  auto bad = c;
  bad[14] = std::numeric_limits<double>::quiet_NaN();
  sigma = 7.0;
  EXPECT_EQ(positionSigma(bad, sigma), CovarianceFault::kNonFinite);
  EXPECT_EQ(sigma, 7.0);
  bad = c;
  bad[7] = -0.01;
  EXPECT_EQ(positionSigma(bad, sigma), CovarianceFault::kNegativeVariance);
  bad = c;
  bad[1] = 0.5;
  EXPECT_EQ(positionSigma(bad, sigma), CovarianceFault::kAsymmetric);
  // [[1, 5], [5, 1]]: symmetric, positive diagonal, eigenvalues 6 and -4: no covariance (it read as sigma 2.45 m).
  bad = c;
  bad[0] = bad[7] = 1.0;
  bad[1] = bad[6] = 5.0;
  sigma = 7.0;
  EXPECT_EQ(positionSigma(bad, sigma), CovarianceFault::kIndefinite);
  EXPECT_EQ(sigma, 7.0);
  EXPECT_NE(std::string(toString(CovarianceFault::kIndefinite)).find("indefinite"), std::string::npos);
}

TEST(Navigable, FreeRoadIsZeroFreeElsewhereIsOffRoadOccupiedIsHundred)
{
  const GridGeometry g{ 0.5, 5, 1, 0.0, 0.0 };
  PriorWindow prior(g);
  prior.road = { 0.9f, 0.0f, 0.0f, 0.9f, 0.0f };
  prior.other = { 0.0f, 0.8f, 0.0f, 0.0f, 0.0f };
  const std::vector<std::int8_t> decision{ 0, 0, 0, 4, -1 };
  std::vector<std::int8_t> out;
  navigableLayer(decision, prior, out);
  EXPECT_EQ(out, (std::vector<std::int8_t>{ 0, kNavigableOffRoad, kNavigableOffRoad, 100, -1 }));
}

TEST(MapConflict, ABuildingSeenThroughLosesItsPriorAndAWallSeenKeepsIt)
{
  const GridGeometry g{ 0.5, 2, 1, 0.0, 0.0 };
  PriorWindow prior(g);
  ScanMassGrid scan(g);
  prior.building[0] = 0.9f;  // seen free: conflict
  prior.wall[1] = 0.9f;      // seen occupied: agreement
  scan.plane(FrameSG::kF)[0] = 0.7f;
  scan.plane(FrameSG::kOmega)[0] = 0.3f;
  scan.plane(FrameSG::kO)[1] = 0.7f;
  scan.plane(FrameSG::kOmega)[1] = 0.3f;
  AlignedVector<float> doubt;
  float last = 0.0f;
  for (int k = 1; k <= 10; ++k)
  {
    PriorWindow p = prior;
    applyMapConflict(p, scan, 0.2, doubt);
    EXPECT_NEAR(doubt[0], std::min(1.0, k * 0.2 * 0.9 * 0.7), 1e-6) << k;
    EXPECT_NEAR(p.building[0], 0.9f * (1.0f - doubt[0]), 1e-6);
    EXPECT_GE(doubt[0], last);
    last = doubt[0];
    EXPECT_EQ(doubt[1], 0.0f);
    EXPECT_EQ(p.wall[1], 0.9f);
  }
  EXPECT_EQ(last, 1.0f);
}

TEST(WallFocalSet, DecidesOccupiedAsBuildingAndFreeAsFree)
{
  FusionParams params;
  MassMG prior{ { FrameMG::kWall, 0.9 }, { FrameMG::kOmega, 0.1 } };
  MassSG occupied{ { FrameSG::kO, 0.7 }, { FrameSG::kOmega, 0.3 } };
  MassSG free{ { FrameSG::kF, 0.7 }, { FrameSG::kOmega, 0.3 } };
  const auto o = fuseCell(MassMG::vacuous(), 0.0, occupied, prior, params);
  EXPECT_NEAR(o.mass[FrameMG::kC], 0.9 * 0.7, 1e-12);
  EXPECT_NEAR(o.mass[FrameMG::kN] + o.mass[FrameMG::kS] + o.mass[FrameMG::kV], 0.0, 1e-12);
  const auto f = fuseCell(MassMG::vacuous(), 0.0, free, prior, params);
  EXPECT_NEAR(f.mass[FrameMG::kF], 0.7, 1e-12);
  EXPECT_NEAR(f.mass[FrameMG::kWall], 0.9 * 0.3, 1e-12);
}

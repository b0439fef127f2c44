// PriorGrid and scanline rasteriser (core, ROS-free): exact cell counts computed by hand, invariants
// against a brute-force point-in-polygon test, and window extraction.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "map_aided_fusion/core/prior_grid.hpp"
#include "map_aided_fusion/core/rasterizer.hpp"

namespace {

using namespace map_aided_fusion::core;

Ring rect(double x0, double y0, double x1, double y1) { return Ring{ { x0, y0 }, { x1, y0 }, { x1, y1 }, { x0, y1 } }; }

GridGeometry testGrid()
{
  GridGeometry g;
  g.resolution = 1.0;
  g.width = 40;
  g.height = 40;
  g.origin_x = -20.0;
  g.origin_y = -20.0;
  return g;
}

std::size_t cellsOf(const std::vector<CellSpan>& spans)
{
  std::size_t n = 0;
  for (const auto& s : spans) n += static_cast<std::size_t>(s.col_end - s.col_begin);
  return n;
}

/// The blocks of test/prior/fixtures/README.md, in the map frame.
VectorMap blocks()
{
  VectorMap m;
  Building square;
  square.footprint.outer = rect(2, 2, 12, 12);
  square.height = 12.5;
  m.buildings.push_back(square);
  Building garage;
  garage.footprint.outer = rect(-15, -11, -5, -3);
  m.buildings.push_back(garage);
  Building cloister;
  cloister.footprint.outer = rect(-18, 2, -2, 18);
  cloister.footprint.holes.push_back(rect(-14, 6, -6, 14));
  m.buildings.push_back(cloister);
  RoadLine road;
  road.points = { { -20, -10 }, { 20, -10 } };
  road.width = 4.0;
  m.road_lines.push_back(road);
  return m;
}

TEST(ScanlineRasterizer, AxisAlignedSquareGivesExactlyItsCells)
{
  ScanlineRasterizer r(testGrid());
  std::vector<CellSpan> spans;
  r.fill(rect(2, 2, 12, 12), spans);
  ASSERT_EQ(spans.size(), 10u);
  EXPECT_EQ(cellsOf(spans), 100u);
  // x ∈ [2, 12] → columns 22..31 (centres −20 + c + 0.5 ∈ [2, 12)).
  EXPECT_EQ(spans.front().row, 22);
  EXPECT_EQ(spans.front().col_begin, 22);
  EXPECT_EQ(spans.front().col_end, 32);
  EXPECT_EQ(spans.back().row, 31);
}

TEST(ScanlineRasterizer, NonAlignedBoundsTestCellCentres)
{
  ScanlineRasterizer r(testGrid());
  std::vector<CellSpan> spans;
  r.fill(rect(0.3, 0.3, 2.7, 2.7), spans);  // centres 0.5, 1.5, 2.5 on each axis
  EXPECT_EQ(cellsOf(spans), 9u);
  r.fill(rect(0.6, 0.6, 1.4, 1.4), spans);  // no centre inside
  EXPECT_EQ(cellsOf(spans), 0u);
}

TEST(ScanlineRasterizer, TriangleHalfOpenRule)
{
  ScanlineRasterizer r(testGrid());
  std::vector<CellSpan> spans;
  // Centres with x + y < 4 (the hypotenuse is a right edge: centres on it are outside): 3 + 2 + 1 + 0.
  r.fill(Ring{ { 0, 0 }, { 4, 0 }, { 0, 4 } }, spans);
  EXPECT_EQ(cellsOf(spans), 6u);
}

TEST(ScanlineRasterizer, SharedEdgesTileWithoutGapOrOverlap)
{
  ScanlineRasterizer r(testGrid());
  std::vector<CellSpan> a, b;
  r.fill(Ring{ { -10, -10 }, { 10, -10 }, { -10, 10 } }, a);
  r.fill(Ring{ { 10, -10 }, { 10, 10 }, { -10, 10 } }, b);
  EXPECT_EQ(cellsOf(a) + cellsOf(b), 400u);
  std::vector<int> hits(1600, 0);
  const GridGeometry g = testGrid();
  for (const auto* s : { &a, &b })
    for (const auto& span : *s)
      for (int c = span.col_begin; c < span.col_end; ++c) ++hits[g.index(c, span.row)];
  for (int h : hits) EXPECT_LE(h, 1);
}

TEST(ScanlineRasterizer, HoleIsExcludedAndClosingVertexIsHarmless)
{
  ScanlineRasterizer r(testGrid());
  std::vector<CellSpan> spans;
  Polygon p;
  p.outer = rect(-18, 2, -2, 18);
  p.holes.push_back(rect(-14, 6, -6, 14));
  r.fill(p, spans);
  EXPECT_EQ(cellsOf(spans), 256u - 64u);
  Ring closed = rect(2, 2, 12, 12);
  closed.push_back(closed.front());
  r.fill(closed, spans);
  EXPECT_EQ(cellsOf(spans), 100u);
}

TEST(ScanlineRasterizer, ClipsToTheGridAndIgnoresNonFiniteRings)
{
  ScanlineRasterizer r(testGrid());
  std::vector<CellSpan> spans;
  r.fill(rect(-100, -100, 100, 100), spans);
  EXPECT_EQ(cellsOf(spans), 1600u);
  r.fill(Ring{ { 0, 0 }, { std::numeric_limits<double>::quiet_NaN(), 1 }, { 1, 1 } }, spans);
  EXPECT_TRUE(spans.empty());
  r.fill(Ring{ { 0, 0 }, { 1, 1 } }, spans);
  EXPECT_TRUE(spans.empty());
  // Absurd but finite coordinates: clamped, no overflow.
  r.fill(Ring{ { -1e300, -1e300 }, { 1e300, -1e300 }, { 1e300, 1e300 }, { -1e300, 1e300 } }, spans);
  EXPECT_EQ(cellsOf(spans), 1600u);
}

TEST(PriorGrid, HugeExtentIsAnError)
{
  VectorMap m;
  Building b;
  b.footprint.outer = rect(0, 0, 1e12, 1);
  m.buildings.push_back(b);
  EXPECT_THROW(PriorGrid::extentOf(m, 0.5), ParameterError);
}

// Crossing-number point-in-polygon with the same half-open convention.
bool insideBruteForce(const Ring& ring, Point2 p)
{
  bool in = false;
  for (std::size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++)
  {
    const Point2 a = ring[j], b = ring[i];
    if ((a.y <= p.y) != (b.y <= p.y))
    {
      const double x = a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y);
      if (p.x >= x) in = !in;
    }
  }
  return in;
}

TEST(ScanlineRasterizer, MatchesBruteForceOnRandomPolygons)
{
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> coord(-25.0, 25.0);
  std::uniform_int_distribution<int> nverts(3, 12);
  const GridGeometry g = testGrid();
  ScanlineRasterizer r(g);
  std::vector<CellSpan> spans;
  for (int trial = 0; trial < 200; ++trial)
  {
    Ring ring(static_cast<std::size_t>(nverts(rng)));
    for (auto& v : ring) v = Point2{ coord(rng), coord(rng) };  // self-intersecting in general: even-odd
    r.fill(ring, spans);
    std::vector<char> mask(g.numCells(), 0);
    for (const auto& s : spans)
      for (int c = s.col_begin; c < s.col_end; ++c) mask[g.index(c, s.row)] = 1;
    for (int y = 0; y < g.height; ++y)
      for (int x = 0; x < g.width; ++x)
        ASSERT_EQ(mask[g.index(x, y)] != 0, insideBruteForce(ring, g.cellCentre({ x, y })))
            << "trial " << trial << " cell " << x << "," << y;
  }
}

TEST(BufferRoadLine, RectanglesAndDiscs)
{
  RoadLine line;
  line.points = { { 0, 0 }, { 10, 0 }, { 10, 10 } };
  line.width = 4.0;
  std::vector<Ring> out;
  bufferRoadLine(line, out);
  ASSERT_EQ(out.size(), 2u + 3u);
  // First rectangle spans y ∈ [−2, 2] along x ∈ [0, 10].
  double ymin = 1e9, ymax = -1e9;
  for (const auto& p : out[0]) ymin = std::min(ymin, p.y), ymax = std::max(ymax, p.y);
  EXPECT_DOUBLE_EQ(ymin, -2.0);
  EXPECT_DOUBLE_EQ(ymax, 2.0);
  line.width = 0.0;
  out.clear();
  bufferRoadLine(line, out);
  EXPECT_TRUE(out.empty());
}

TEST(PriorGrid, RoadJoinsAreRoundAndCourtyardsKeepTheRoadBelow)
{
  VectorMap m;
  RoadLine l;
  l.points = { { 0, 0 }, { 10, 0 }, { 10, 10 } };
  l.width = 4.0;
  m.road_lines.push_back(l);
  Building ring;  // a building around the road's corner, with the corner in its courtyard
  ring.footprint.outer = rect(6, -6, 16, 4);
  ring.footprint.holes.push_back(rect(7, -5, 15, 3));
  m.buildings.push_back(ring);
  PriorGrid grid;
  grid.build(m, testGrid());
  EXPECT_EQ(grid.labelAt({ 10.5, -0.5 }), PriorClass::kRoad);   // inside the join's disc (0.71 m from the vertex)
  EXPECT_EQ(grid.labelAt({ 11.5, -1.5 }), PriorClass::kOther);  // 2.12 m from the vertex: outside the buffer
  EXPECT_EQ(grid.labelAt({ 11.5, 1.5 }), PriorClass::kRoad);    // second segment, in the courtyard
  EXPECT_EQ(grid.labelAt({ 6.5, 0.5 }), PriorClass::kBuilding); // the ring's wall over the road
  EXPECT_EQ(grid.labelAt({ 7.5, 0.5 }), PriorClass::kRoad);     // courtyard over the road: still road
}

TEST(PriorGrid, BlocksGiveExactClassCounts)
{
  PriorGrid grid;
  PriorBuildStats stats;
  grid.build(blocks(), testGrid(), &stats);
  const PriorClassCounts n = grid.classCounts();
  EXPECT_EQ(n[static_cast<int>(PriorClass::kBuilding)], 100u + 80u + 192u);
  EXPECT_EQ(n[static_cast<int>(PriorClass::kRoad)], 160u - 30u);
  EXPECT_EQ(n[static_cast<int>(PriorClass::kOther)], 1600u - 372u - 130u);
  EXPECT_EQ(n[static_cast<int>(PriorClass::kUnknown)], 0u);
  EXPECT_EQ(stats.buildings_rasterised, 3u);
  EXPECT_EQ(stats.road_lines_rasterised, 1u);
  EXPECT_EQ(grid.bytes(), 1600u);
}

TEST(VectorMap, DistanceToTheNearestDataIsToEdgesAndLinesNotVertices)
{
  VectorMap m;
  EXPECT_TRUE(std::isinf(distanceToMapData(m, { 0.0, 0.0 })));
  Building b;
  b.footprint.outer = rect(0.0, 0.0, 10.0, 10.0);
  m.buildings.push_back(b);
  EXPECT_DOUBLE_EQ(distanceToMapData(m, { 5.0, 13.0 }), 3.0);   // above the top edge, far from its vertices
  EXPECT_DOUBLE_EQ(distanceToMapData(m, { 5.0, 5.0 }), 5.0);    // inside: to the nearest edge
  EXPECT_DOUBLE_EQ(distanceToMapData(m, { -3.0, -4.0 }), 5.0);  // to a corner
  RoadLine road;
  road.points = { { 100.0, -1000.0 }, { 100.0, 1000.0 } };  // 2 km of straight road, two vertices
  m.road_lines.push_back(road);
  EXPECT_DOUBLE_EQ(distanceToMapData(m, { 130.0, 0.0 }), 30.0);
}

TEST(PriorGrid, ASmallMapAfterAHugeOneGivesTheMemoryBack)
{
  // The map loader reloads into the same grid: its buffers must follow the new map, not stay at the peak.
  GridGeometry huge = testGrid();
  huge.width = huge.height = 3000;
  PriorGrid grid;
  for (const PriorCellTest test : { PriorCellTest::kCentre, PriorCellTest::kCoverage })
  {
    grid.build(blocks(), huge, nullptr, test);
    grid.build(blocks(), testGrid(), nullptr, test);
    EXPECT_EQ(grid.labels().size(), testGrid().numCells());
    EXPECT_LE(grid.labels().capacity(), 2 * testGrid().numCells()) << "labels kept the huge map's buffer";
    EXPECT_LE(grid.bytes(), 6 * testGrid().numCells());
    EXPECT_EQ(grid.labelAt({ 0.5, -9.5 }), PriorClass::kRoad);
  }
}

TEST(PriorGrid, BuildingsWinCourtyardsStayOtherAndOutsideIsUnknown)
{
  PriorGrid grid;
  grid.build(blocks(), testGrid());
  EXPECT_EQ(grid.labelAt({ -10.5, -9.5 }), PriorClass::kBuilding);  // garage over the road
  EXPECT_EQ(grid.labelAt({ 0.5, -9.5 }), PriorClass::kRoad);
  EXPECT_EQ(grid.labelAt({ -10.5, 10.5 }), PriorClass::kOther);  // courtyard
  EXPECT_EQ(grid.labelAt({ -16.5, 10.5 }), PriorClass::kBuilding);
  EXPECT_EQ(grid.labelAt({ 0.5, 0.5 }), PriorClass::kOther);
  EXPECT_EQ(grid.labelAt({ 25.0, 0.0 }), PriorClass::kUnknown);
  EXPECT_EQ(grid.label({ -1, 0 }), PriorClass::kUnknown);
}

TEST(PriorGrid, InvalidGeometryIsSkippedAndCounted)
{
  VectorMap m = blocks();
  Building broken;
  broken.footprint.outer = { { 0, 0 }, { std::numeric_limits<double>::infinity(), 0 }, { 1, 1 } };
  m.buildings.push_back(broken);
  RoadLine zero;
  zero.points = { { 0, 0 }, { 1, 0 } };
  zero.width = -1.0;
  m.road_lines.push_back(zero);
  PriorGrid grid;
  PriorBuildStats stats;
  grid.build(m, testGrid(), &stats);
  EXPECT_EQ(stats.skipped_invalid, 2u);
  EXPECT_EQ(stats.buildings_outside, 0u);
  EXPECT_EQ(grid.classCounts()[static_cast<int>(PriorClass::kBuilding)], 372u);
  // A window that misses the cloister: counted outside, not empty; a sliver smaller than a cell: empty.
  Building sliver;
  sliver.footprint.outer = rect(0.6, 0.6, 1.4, 1.4);
  m.buildings.push_back(sliver);
  GridGeometry right = testGrid();
  right.origin_x = 0.0;  // x ∈ [0, 40]: the cloister (x ≤ −2) and the garage (x ≤ −5) are outside
  grid.build(m, right, &stats);
  EXPECT_EQ(stats.buildings_outside, 2u);
  EXPECT_EQ(stats.buildings_empty, 1u);
  EXPECT_EQ(stats.buildings_rasterised, 1u);
}

TEST(PriorGrid, ExtentIsSnappedToTheResolution)
{
  const GridGeometry g = PriorGrid::extentOf(blocks(), 0.5, 1.0);
  // Bounds: x ∈ [−22, 22] (road ends ± half width), y ∈ [−12, 18]; + 1 m margin.
  EXPECT_DOUBLE_EQ(g.origin_x, -23.0);
  EXPECT_DOUBLE_EQ(g.origin_y, -13.0);
  EXPECT_EQ(g.width, 92);
  EXPECT_EQ(g.height, 64);
  EXPECT_THROW(PriorGrid::extentOf(VectorMap{}, 0.5), ParameterError);
  EXPECT_THROW(PriorGrid::extentOf(blocks(), 0.0), ParameterError);
}

TEST(PriorGrid, FillWindowCopiesWholeCellsAndIsVacuousOutside)
{
  PriorGrid grid;
  grid.build(blocks(), testGrid());
  PriorConfidence beta;
  beta.beta_building = 0.7;
  beta.beta_road = 0.6;
  beta.beta_other = 0.5;
  // Window straddling the grid's right border by 10 cells.
  GridGeometry w;
  w.resolution = 1.0;
  w.width = 20;
  w.height = 20;
  w.origin_x = 10.0;
  w.origin_y = -15.0;
  PriorWindow out;
  grid.fillWindow(w, beta, out);
  ASSERT_EQ(out.geometry, w);
  for (int y = 0; y < w.height; ++y)
    for (int x = 0; x < w.width; ++x)
    {
      const std::size_t i = w.index(x, y);
      const PriorClass c = grid.labelAt(w.cellCentre({ x, y }));
      EXPECT_FLOAT_EQ(out.building[i], c == PriorClass::kBuilding ? 0.7f : 0.0f);
      EXPECT_FLOAT_EQ(out.road[i], c == PriorClass::kRoad ? 0.6f : 0.0f);
      EXPECT_FLOAT_EQ(out.other[i], c == PriorClass::kOther ? 0.5f : 0.0f);
      if (x >= 10)
      {
        EXPECT_EQ(c, PriorClass::kUnknown);
      }
    }
  // A road cell and a vacuous cell, by hand: (10.5, −9.5) is road, (25.5, −9.5) outside.
  EXPECT_FLOAT_EQ(out.road[w.index(0, 5)], 0.6f);
  EXPECT_FLOAT_EQ(out.road[w.index(15, 5)] + out.building[w.index(15, 5)] + out.other[w.index(15, 5)], 0.0f);
}

TEST(PriorGrid, FillWindowSamplesCentresWhenNotAligned)
{
  PriorGrid grid;
  grid.build(blocks(), testGrid());
  const PriorConfidence beta;
  GridGeometry w = GridGeometry::centred(8.0, 8.0, 0.25, 7.1, 7.1);  // other resolution, unaligned
  PriorWindow out;
  grid.fillWindow(w, beta, out);
  std::size_t building = 0;
  for (int y = 0; y < w.height; ++y)
    for (int x = 0; x < w.width; ++x)
    {
      const PriorClass c = grid.labelAt(w.cellCentre({ x, y }));
      building += c == PriorClass::kBuilding;
      EXPECT_FLOAT_EQ(out.building[w.index(x, y)], c == PriorClass::kBuilding ? float(beta.beta_building) : 0.f);
    }
  EXPECT_GT(building, 0u);
}

TEST(PriorGrid, CropKeepsLabelsAndPadsWithUnknown)
{
  PriorGrid grid;
  grid.build(blocks(), testGrid());
  GridGeometry w = testGrid();
  w.origin_x = 0.0;  // right half + 20 columns beyond the grid
  const PriorGrid c = grid.crop(w);
  for (int y = 0; y < w.height; ++y)
    for (int x = 0; x < w.width; ++x)
      EXPECT_EQ(c.label({ x, y }), grid.labelAt(w.cellCentre({ x, y })));
  w.origin_x = 0.3;
  EXPECT_THROW(grid.crop(w), ParameterError);
}

}  // namespace

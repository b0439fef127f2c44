#include "map_aided_fusion/core/prior_grid.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "map_aided_fusion/core/rasterizer.hpp"

namespace map_aided_fusion {
namespace core {

namespace {

/// Sides of the regular polygon approximating the disc at each road-line vertex.
constexpr int kJoinPolygonSides = 16;
/// Relative tolerance for "the window origin is a whole number of cells away".
constexpr double kWholeCellTolerance = 1e-6;
constexpr double kPi = 3.14159265358979323846;

bool finiteRing(const Ring& r)
{
  return std::all_of(r.begin(), r.end(), [](const Point2& p) { return std::isfinite(p.x) && std::isfinite(p.y); });
}

/// Largest grid side in cells accepted by extentOf() (2^30, well inside int).
constexpr double kMaxCellsPerAxis = 1073741824.0;

/// Index of the first row/column whose centre is ≥ v (centres at origin + (i + 0.5)·res), clamped to
/// [0, n] (NaN gives n: an empty range).
inline long firstCentreAtOrAbove(double v, double origin, double res, long n)
{
  const double c = std::ceil((v - origin) / res - 0.5);
  if (c <= 0.0) return 0;
  if (!(c < static_cast<double>(n))) return n;
  return static_cast<long>(c);
}

}  // namespace

// ------------------------------------------------------------------------------------------------
// ScanlineRasterizer
// ------------------------------------------------------------------------------------------------

void ScanlineRasterizer::addRing(const Ring& ring)
{
  const std::size_t n = ring.size();
  if (n < 3) return;
  const double res = geometry_.resolution;
  const double oy = geometry_.origin_y;
  for (std::size_t i = 0; i < n; ++i)
  {
    const Point2& a = ring[i];
    const Point2& b = ring[(i + 1) % n];
    if (a.y == b.y) continue;
    const double ylo = std::min(a.y, b.y), yhi = std::max(a.y, b.y);
    const long r0 = firstCentreAtOrAbove(ylo, oy, res, geometry_.height);
    const long r1 = firstCentreAtOrAbove(yhi, oy, res, geometry_.height);
    if (r0 >= r1) continue;
    edges_.push_back(Edge{ r0, r1, a.x, a.y, (b.x - a.x) / (b.y - a.y) });
  }
}

void ScanlineRasterizer::fill(const std::vector<const Ring*>& rings, std::vector<CellSpan>& spans)
{
  spans.clear();
  edges_.clear();
  active_.clear();
  for (const Ring* r : rings)
    if (r == nullptr || !finiteRing(*r)) return;
  for (const Ring* r : rings) addRing(*r);
  if (edges_.empty()) return;
  std::sort(edges_.begin(), edges_.end(), [](const Edge& a, const Edge& b) { return a.row_begin < b.row_begin; });
  long last_row = 0;
  for (const Edge& e : edges_) last_row = std::max(last_row, e.row_end);
  const double res = geometry_.resolution;
  const double ox = geometry_.origin_x;
  const double oy = geometry_.origin_y;
  const long w = geometry_.width;
  std::size_t next = 0;
  for (long row = edges_.front().row_begin; row < last_row; ++row)
  {
    while (next < edges_.size() && edges_[next].row_begin == row) active_.push_back(next++);
    active_.erase(std::remove_if(active_.begin(), active_.end(), [&](std::size_t k) { return edges_[k].row_end <= row; }),
                  active_.end());
    if (active_.empty())
    {
      if (next < edges_.size()) row = edges_[next].row_begin - 1;
      continue;
    }
    const double yc = oy + (static_cast<double>(row) + 0.5) * res;
    row_x_.clear();
    for (std::size_t k : active_) row_x_.push_back(edges_[k].ax + (yc - edges_[k].ay) * edges_[k].slope);
    std::sort(row_x_.begin(), row_x_.end());
    // Within a row the number of crossings is even (half-open rule on closed rings).
    for (std::size_t k = 0; k + 1 < row_x_.size(); k += 2)
    {
      const long c0 = firstCentreAtOrAbove(row_x_[k], ox, res, w);
      const long c1 = firstCentreAtOrAbove(row_x_[k + 1], ox, res, w);
      if (c0 < c1) spans.push_back(CellSpan{ static_cast<int>(row), static_cast<int>(c0), static_cast<int>(c1) });
    }
  }
}

void ScanlineRasterizer::fill(const Polygon& polygon, std::vector<CellSpan>& spans)
{
  std::vector<const Ring*> rings;
  rings.reserve(1 + polygon.holes.size());
  rings.push_back(&polygon.outer);
  for (const Ring& h : polygon.holes) rings.push_back(&h);
  fill(rings, spans);
}

void ScanlineRasterizer::fill(const Ring& ring, std::vector<CellSpan>& spans)
{
  fill(std::vector<const Ring*>{ &ring }, spans);
}

void bufferRoadLine(const RoadLine& line, std::vector<Ring>& out)
{
  const double h = 0.5 * line.width;
  if (!(h > 0.0) || !std::isfinite(h) || line.points.empty() || !finiteRing(line.points)) return;
  for (std::size_t i = 0; i + 1 < line.points.size(); ++i)
  {
    const Point2 a = line.points[i], b = line.points[i + 1];
    const double dx = b.x - a.x, dy = b.y - a.y;
    const double len = std::hypot(dx, dy);
    if (!(len > 0.0)) continue;
    const double nx = -dy / len * h, ny = dx / len * h;
    out.push_back(Ring{ { a.x + nx, a.y + ny }, { a.x - nx, a.y - ny }, { b.x - nx, b.y - ny }, { b.x + nx, b.y + ny } });
  }
  for (const Point2& p : line.points)
  {
    Ring disc;
    disc.reserve(kJoinPolygonSides);
    for (int k = 0; k < kJoinPolygonSides; ++k)
    {
      const double t = 2.0 * kPi * k / kJoinPolygonSides;
      disc.push_back(Point2{ p.x + h * std::cos(t), p.y + h * std::sin(t) });
    }
    out.push_back(std::move(disc));
  }
}

// ------------------------------------------------------------------------------------------------
// PriorGrid
// ------------------------------------------------------------------------------------------------

namespace {

bool validPolygon(const Polygon& p)
{
  if (p.outer.size() < 3 || !finiteRing(p.outer)) return false;
  return std::all_of(p.holes.begin(), p.holes.end(), finiteRing);
}

constexpr std::uint16_t kAllSamples = static_cast<std::uint16_t>((1u << kCoverageSamples) - 1u);

/// A buffer holding more than this many times the cells it needs is given back (a small map after a huge one).
constexpr std::size_t kMaxSpareCapacity = 2;

/// v = n copies of @p value, releasing the old buffer when it is far larger than n.
template <class T>
void assignFitted(std::vector<T>& v, std::size_t n, T value)
{
  if (v.capacity() > kMaxSpareCapacity * n)
    std::vector<T>(n, value).swap(v);
  else
    v.assign(n, value);
}

int samplesIn(std::uint16_t bits)
{
  return __builtin_popcount(static_cast<unsigned>(bits));
}

}  // namespace

PriorGrid::PriorGrid(const GridGeometry& geometry) : geometry_(geometry)
{
  geometry.validate();
  labels_.assign(geometry.numCells(), PriorClass::kUnknown);
}

GridGeometry PriorGrid::extentOf(const VectorMap& map, double resolution, double margin)
{
  requirePositive("resolution", resolution);
  if (!std::isfinite(margin) || margin < 0.0) throw ParameterError("margin", "must be finite and >= 0");
  double x0 = std::numeric_limits<double>::infinity(), y0 = x0, x1 = -x0, y1 = -x0;
  auto add = [&](const Point2& p, double grow) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) return;
    x0 = std::min(x0, p.x - grow);
    y0 = std::min(y0, p.y - grow);
    x1 = std::max(x1, p.x + grow);
    y1 = std::max(y1, p.y + grow);
  };
  for (const auto& b : map.buildings)
    for (const auto& p : b.footprint.outer) add(p, 0.0);
  for (const auto& a : map.road_areas)
    for (const auto& p : a.outer) add(p, 0.0);
  for (const auto& l : map.road_lines)
  {
    const double grow = std::isfinite(l.width) && l.width > 0.0 ? 0.5 * l.width : 0.0;
    for (const auto& p : l.points) add(p, grow);
  }
  if (!(x0 <= x1 && y0 <= y1)) throw ParameterError("map", "the map has no finite geometry");
  GridGeometry g;
  g.resolution = resolution;
  g.origin_x = std::floor((x0 - margin) / resolution) * resolution;
  g.origin_y = std::floor((y0 - margin) / resolution) * resolution;
  const double w = std::ceil((x1 + margin - g.origin_x) / resolution);
  const double h = std::ceil((y1 + margin - g.origin_y) / resolution);
  if (!(w <= kMaxCellsPerAxis && h <= kMaxCellsPerAxis))
    throw ParameterError("resolution", "the map's extent (" + std::to_string(x1 - x0) + " m x " +
                                           std::to_string(y1 - y0) + " m) is too many cells at this resolution");
  g.width = std::max(1, static_cast<int>(w));
  g.height = std::max(1, static_cast<int>(h));
  return g;
}

const char* toString(PriorCellTest t)
{
  return t == PriorCellTest::kCoverage ? "coverage" : "centre";
}

PriorCellTest parsePriorCellTest(const std::string& s)
{
  if (s == "centre") return PriorCellTest::kCentre;
  if (s == "coverage") return PriorCellTest::kCoverage;
  throw ParameterError("cell_test", "must be 'centre' or 'coverage', not '" + s + "'");
}

PriorGrid PriorGrid::fromVectorMap(const VectorMap& map, double resolution, double margin, PriorBuildStats* stats,
                                   PriorCellTest test)
{
  PriorGrid grid;
  grid.build(map, extentOf(map, resolution, margin), stats, test);
  return grid;
}

void PriorGrid::build(const VectorMap& map, const GridGeometry& geometry, PriorBuildStats* stats, PriorCellTest test)
{
  geometry.validate();
  geometry_ = geometry;
  test_ = test;
  std::vector<std::uint16_t>().swap(building_samples_);
  std::vector<std::uint16_t>().swap(road_samples_);
  std::vector<std::uint8_t>().swap(outline_);
  assignFitted(labels_, geometry.numCells(), PriorClass::kOther);
  PriorBuildStats local;
  PriorBuildStats& st = stats != nullptr ? *stats : local;
  st = PriorBuildStats{};

  ScanlineRasterizer rasterizer(geometry_);
  std::vector<CellSpan> spans;
  const auto paint = [&](PriorClass v) {
    for (const CellSpan& s : spans)
    {
      PriorClass* row = labels_.data() + geometry_.index(0, s.row);
      std::fill(row + s.col_begin, row + s.col_end, v);
    }
    return !spans.empty();
  };
  const auto overlapsGrid = [this](const Ring& r) {
    const auto [xmin, xmax] = std::minmax_element(r.begin(), r.end(), [](auto& a, auto& b) { return a.x < b.x; });
    const auto [ymin, ymax] = std::minmax_element(r.begin(), r.end(), [](auto& a, auto& b) { return a.y < b.y; });
    return xmax->x >= geometry_.origin_x && xmin->x <= geometry_.origin_x + geometry_.sizeX() &&
           ymax->y >= geometry_.origin_y && ymin->y <= geometry_.origin_y + geometry_.sizeY();
  };

  for (const Polygon& area : map.road_areas)
  {
    if (!validPolygon(area))
    {
      ++st.skipped_invalid;
      continue;
    }
    rasterizer.fill(area, spans);
    if (paint(PriorClass::kRoad)) ++st.road_areas_rasterised;
  }
  std::vector<Ring> pieces;
  for (const RoadLine& line : map.road_lines)
  {
    if (!(line.width > 0.0) || !std::isfinite(line.width) || line.points.size() < 2 || !finiteRing(line.points))
    {
      ++st.skipped_invalid;
      continue;
    }
    pieces.clear();
    bufferRoadLine(line, pieces);
    bool any = false;
    for (const Ring& piece : pieces)
    {
      rasterizer.fill(piece, spans);
      any = paint(PriorClass::kRoad) || any;
    }
    if (any) ++st.road_lines_rasterised;
  }
  for (const Building& b : map.buildings)
  {
    if (!validPolygon(b.footprint))
    {
      ++st.skipped_invalid;
      continue;
    }
    rasterizer.fill(b.footprint, spans);
    if (paint(PriorClass::kBuilding))
      ++st.buildings_rasterised;
    else if (overlapsGrid(b.footprint.outer))
      ++st.buildings_empty;
    else
      ++st.buildings_outside;
  }
  if (test == PriorCellTest::kCoverage) sampleCoverage(map, st);
}


void PriorGrid::sampleCoverage(const VectorMap& map, PriorBuildStats& st)
{
  constexpr int k = kCoverageSamplesPerSide;
  static_assert(kCoverageSamples <= 16, "one bit per sample in a uint16_t");
  if (geometry_.width > std::numeric_limits<int>::max() / k || geometry_.height > std::numeric_limits<int>::max() / k)
    throw ParameterError("cell_test", "the grid is too large for the coverage test");
  const std::size_t n = geometry_.numCells();
  building_samples_.assign(n, 0);  // released at the start of build(): sized afresh
  road_samples_.assign(n, 0);
  outline_.assign(n, 0);
  GridGeometry fine = geometry_;
  fine.resolution = geometry_.resolution / k;
  fine.width = geometry_.width * k;
  fine.height = geometry_.height * k;
  ScanlineRasterizer rasterizer(fine);
  std::vector<CellSpan> spans;
  const auto mark = [&](std::vector<std::uint16_t>& bits) {
    for (const CellSpan& sp : spans)
    {
      std::uint16_t* row = bits.data() + geometry_.index(0, sp.row / k);
      const unsigned shift = static_cast<unsigned>((sp.row % k) * k);
      for (int c = sp.col_begin; c < sp.col_end; ++c) row[c / k] |= static_cast<std::uint16_t>(1u << (shift + c % k));
    }
  };
  for (const Polygon& area : map.road_areas)
    if (validPolygon(area))
    {
      rasterizer.fill(area, spans);
      mark(road_samples_);
    }
  std::vector<Ring> pieces;
  for (const RoadLine& line : map.road_lines)
  {
    if (!(line.width > 0.0) || !std::isfinite(line.width) || line.points.size() < 2 || !finiteRing(line.points)) continue;
    pieces.clear();
    bufferRoadLine(line, pieces);
    for (const Ring& piece : pieces)
    {
      rasterizer.fill(piece, spans);
      mark(road_samples_);
    }
  }
  const auto traceRing = [&](const Ring& ring) {
    for (std::size_t i = 0; i < ring.size(); ++i)
    {
      const Point2 a = ring[i], b = ring[(i + 1) % ring.size()];
      const double len = std::hypot(b.x - a.x, b.y - a.y);
      if (!(len > 0.0)) continue;
      traverseCells(geometry_, a, (b.x - a.x) / len, (b.y - a.y) / len, len, [&](std::size_t c) { outline_[c] = 1; });
    }
  };
  for (const Building& b : map.buildings)
  {
    if (!validPolygon(b.footprint)) continue;
    rasterizer.fill(b.footprint, spans);
    mark(building_samples_);
    traceRing(b.footprint.outer);
    for (const Ring& h : b.footprint.holes) traceRing(h);
  }
  for (std::size_t i = 0; i < n; ++i)
  {
    if (outline_[i] && building_samples_[i] == kAllSamples) outline_[i] = 0;
    if (!outline_[i]) continue;
    labels_[i] = PriorClass::kBuilding;
    ++st.outline_cells;
  }
}

double PriorGrid::buildingCoverage(CellIndex c) const
{
  if (building_samples_.empty() || !geometry_.contains(c)) return 0.0;
  return samplesIn(building_samples_[geometry_.index(c)]) / double(kCoverageSamples);
}

double PriorGrid::roadCoverage(CellIndex c) const
{
  if (road_samples_.empty() || !geometry_.contains(c)) return 0.0;
  const std::size_t i = geometry_.index(c);
  return samplesIn(static_cast<std::uint16_t>(road_samples_[i] & ~building_samples_[i])) / double(kCoverageSamples);
}

bool PriorGrid::outline(CellIndex c) const
{
  return !outline_.empty() && geometry_.contains(c) && outline_[geometry_.index(c)] != 0;
}

void PriorGrid::cellMasses(std::size_t i, const PriorConfidence& beta, float& building, float& road, float& other,
                           float& wall) const
{
  building = road = other = wall = 0.0f;
  const PriorClass label = labels_[i];
  if (label == PriorClass::kUnknown) return;
  if (outline_.empty())
  {
    const float b = static_cast<float>(beta.beta(label));
    (label == PriorClass::kBuilding ? building : label == PriorClass::kRoad ? road : other) = b;
    return;
  }
  if (outline_[i])
  {
    wall = static_cast<float>(beta.beta_building);
    return;
  }
  const int nb = samplesIn(building_samples_[i]);
  const int nr = samplesIn(static_cast<std::uint16_t>(road_samples_[i] & ~building_samples_[i]));
  constexpr double kInv = 1.0 / kCoverageSamples;
  building = static_cast<float>(beta.beta_building * nb * kInv);
  road = static_cast<float>(beta.beta_road * nr * kInv);
  other = static_cast<float>(beta.beta_other * (kCoverageSamples - nb - nr) * kInv);
}

bool anyNonZero(const float* p, std::size_t n)
{
  constexpr std::uint32_t kMagnitudeBits = 0x7fffffffu;  // a float's bits without its sign
  std::uint32_t bits = 0;
  for (std::size_t i = 0; i < n; ++i)
  {
    std::uint32_t b;
    std::memcpy(&b, p + i, sizeof b);
    bits |= b & kMagnitudeBits;
  }
  return bits != 0;
}

bool PriorWindow::hasWall() const { return anyNonZero(wall.data(), wall.size()); }

PriorClass PriorGrid::labelAt(Point2 p) const
{
  CellIndex c;
  return geometry_.worldToCell(p, c) ? labels_[geometry_.index(c)] : PriorClass::kUnknown;
}

PriorClassCounts PriorGrid::classCounts() const
{
  PriorClassCounts counts{};
  for (PriorClass v : labels_) ++counts[static_cast<std::size_t>(v)];
  return counts;
}

namespace {

/// Offset in whole cells of @p b's origin from @p a's; false when not a whole number or resolutions differ.
bool wholeCellOffset(const GridGeometry& a, const GridGeometry& b, long& dx, long& dy)
{
  if (a.resolution != b.resolution) return false;
  const double fx = (b.origin_x - a.origin_x) / a.resolution;
  const double fy = (b.origin_y - a.origin_y) / a.resolution;
  if (!std::isfinite(fx) || !std::isfinite(fy)) return false;
  dx = std::lround(fx);
  dy = std::lround(fy);
  return std::abs(fx - static_cast<double>(dx)) <= kWholeCellTolerance &&
         std::abs(fy - static_cast<double>(dy)) <= kWholeCellTolerance;
}

}  // namespace

void PriorGrid::fillWindow(const GridGeometry& window, const PriorConfidence& beta, PriorWindow& out) const
{
  if (out.geometry != window || out.building.size() != window.numCells() || out.wall.size() != window.numCells())
    out.reset(window);
  std::array<float, kNumPriorClasses> mb{}, mr{}, mt{};
  mb[static_cast<int>(PriorClass::kBuilding)] = static_cast<float>(beta.beta_building);
  mr[static_cast<int>(PriorClass::kRoad)] = static_cast<float>(beta.beta_road);
  mt[static_cast<int>(PriorClass::kOther)] = static_cast<float>(beta.beta_other);
  float* ob = out.building.data();
  float* orr = out.road.data();
  float* ot = out.other.data();
  float* ow = out.wall.data();
  const bool coverage = !outline_.empty();
  const auto vacuous = [&](std::size_t i) { ob[i] = orr[i] = ot[i] = ow[i] = 0.0f; };
  const auto put = [&](std::size_t i, std::size_t j) {
    if (coverage)
    {
      cellMasses(j, beta, ob[i], orr[i], ot[i], ow[i]);
      return;
    }
    const auto k = static_cast<std::size_t>(labels_[j]);
    ob[i] = mb[k];
    orr[i] = mr[k];
    ot[i] = mt[k];
    ow[i] = 0.0f;
  };

  long dx = 0, dy = 0;
  if (!labels_.empty() && wholeCellOffset(geometry_, window, dx, dy))
  {
    for (int r = 0; r < window.height; ++r)
    {
      const std::size_t base = window.index(0, r);
      const long sr = r + dy;
      long c0 = 0, c1 = 0;  // window columns covered by this grid
      if (sr >= 0 && sr < geometry_.height)
      {
        c0 = std::max(0L, -dx);
        c1 = std::min(static_cast<long>(window.width), static_cast<long>(geometry_.width) - dx);
        c1 = std::max(c0, c1);
      }
      for (long c = 0; c < c0; ++c) vacuous(base + c);
      if (c1 > c0)
      {
        const std::size_t src = geometry_.index(static_cast<int>(c0 + dx), static_cast<int>(sr));
        for (long c = c0; c < c1; ++c) put(base + c, src + static_cast<std::size_t>(c - c0));
      }
      for (long c = c1; c < window.width; ++c) vacuous(base + c);
    }
    return;
  }
  for (int r = 0; r < window.height; ++r)
    for (int c = 0; c < window.width; ++c)
    {
      CellIndex src;
      const std::size_t i = window.index(c, r);
      if (!labels_.empty() && geometry_.worldToCell(window.cellCentre(CellIndex{ c, r }), src))
        put(i, geometry_.index(src));
      else
        vacuous(i);
    }
}

PriorGrid PriorGrid::crop(const GridGeometry& window) const
{
  window.validate();
  long dx = 0, dy = 0;
  if (!wholeCellOffset(geometry_, window, dx, dy))
    throw ParameterError("window", "crop needs the same resolution and a whole-cell origin offset");
  PriorGrid out(window);
  out.test_ = test_;
  if (!outline_.empty())
  {
    out.building_samples_.assign(window.numCells(), 0);
    out.road_samples_.assign(window.numCells(), 0);
    out.outline_.assign(window.numCells(), 0);
  }
  for (int r = 0; r < window.height; ++r)
  {
    const long sr = r + dy;
    if (sr < 0 || sr >= geometry_.height) continue;
    const long c0 = std::max(0L, -dx);
    const long c1 = std::min(static_cast<long>(window.width), static_cast<long>(geometry_.width) - dx);
    if (c1 <= c0) continue;
    const std::size_t src = geometry_.index(static_cast<int>(c0 + dx), static_cast<int>(sr));
    const std::size_t dst = window.index(static_cast<int>(c0), r);
    std::copy_n(labels_.begin() + static_cast<std::ptrdiff_t>(src), c1 - c0, out.labels_.begin() + static_cast<std::ptrdiff_t>(dst));
    if (outline_.empty()) continue;
    std::copy_n(building_samples_.begin() + static_cast<std::ptrdiff_t>(src), c1 - c0,
                out.building_samples_.begin() + static_cast<std::ptrdiff_t>(dst));
    std::copy_n(road_samples_.begin() + static_cast<std::ptrdiff_t>(src), c1 - c0,
                out.road_samples_.begin() + static_cast<std::ptrdiff_t>(dst));
    std::copy_n(outline_.begin() + static_cast<std::ptrdiff_t>(src), c1 - c0, out.outline_.begin() + static_cast<std::ptrdiff_t>(dst));
  }
  return out;
}

}  // namespace core
}  // namespace map_aided_fusion

#include "map_aided_fusion/core/prior_grid.hpp"

#include <algorithm>
#include <cmath>
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

PriorGrid PriorGrid::fromVectorMap(const VectorMap& map, double resolution, double margin, PriorBuildStats* stats)
{
  PriorGrid grid;
  grid.build(map, extentOf(map, resolution, margin), stats);
  return grid;
}

void PriorGrid::build(const VectorMap& map, const GridGeometry& geometry, PriorBuildStats* stats)
{
  geometry.validate();
  geometry_ = geometry;
  labels_.assign(geometry.numCells(), PriorClass::kOther);
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
  const auto validPolygon = [](const Polygon& p) {
    if (p.outer.size() < 3 || !finiteRing(p.outer)) return false;
    return std::all_of(p.holes.begin(), p.holes.end(), finiteRing);
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
}

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
  if (out.geometry != window || out.building.size() != window.numCells()) out.reset(window);
  std::array<float, kNumPriorClasses> mb{}, mr{}, mt{};
  mb[static_cast<int>(PriorClass::kBuilding)] = static_cast<float>(beta.beta_building);
  mr[static_cast<int>(PriorClass::kRoad)] = static_cast<float>(beta.beta_road);
  mt[static_cast<int>(PriorClass::kOther)] = static_cast<float>(beta.beta_other);
  float* ob = out.building.data();
  float* orr = out.road.data();
  float* ot = out.other.data();
  const auto put = [&](std::size_t i, PriorClass v) {
    const auto k = static_cast<std::size_t>(v);
    ob[i] = mb[k];
    orr[i] = mr[k];
    ot[i] = mt[k];
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
      for (long c = 0; c < c0; ++c) put(base + c, PriorClass::kUnknown);
      if (c1 > c0)
      {
        const PriorClass* src = labels_.data() + geometry_.index(static_cast<int>(c0 + dx), static_cast<int>(sr));
        for (long c = c0; c < c1; ++c) put(base + c, src[c - c0]);
      }
      for (long c = c1; c < window.width; ++c) put(base + c, PriorClass::kUnknown);
    }
    return;
  }
  for (int r = 0; r < window.height; ++r)
    for (int c = 0; c < window.width; ++c)
      put(window.index(c, r), labelAt(window.cellCentre(CellIndex{ c, r })));
}

PriorGrid PriorGrid::crop(const GridGeometry& window) const
{
  window.validate();
  long dx = 0, dy = 0;
  if (!wholeCellOffset(geometry_, window, dx, dy))
    throw ParameterError("window", "crop needs the same resolution and a whole-cell origin offset");
  PriorGrid out(window);
  for (int r = 0; r < window.height; ++r)
  {
    const long sr = r + dy;
    if (sr < 0 || sr >= geometry_.height) continue;
    const long c0 = std::max(0L, -dx);
    const long c1 = std::min(static_cast<long>(window.width), static_cast<long>(geometry_.width) - dx);
    if (c1 <= c0) continue;
    const PriorClass* src = labels_.data() + geometry_.index(static_cast<int>(c0 + dx), static_cast<int>(sr));
    std::copy(src, src + (c1 - c0), out.labels_.data() + window.index(static_cast<int>(c0), r));
  }
  return out;
}

}  // namespace core
}  // namespace map_aided_fusion

#include "map_aided_fusion/sim/ground_truth.hpp"

#include <algorithm>
#include <cmath>

namespace map_aided_fusion {
namespace sim {

namespace {

constexpr double kOverlapEpsilon = 1e-9;  // m, cells that only touch a footprint do not overlap it
constexpr double kStaticMargin = 5.0;     // m around the buildings in the static raster

void setMax(std::vector<std::int8_t>& cells, std::size_t i, std::int8_t v)
{
  if (cells[i] < v) cells[i] = v;
}

void fillCentres(const core::Polygon& polygon, const core::GridGeometry& g, std::int8_t value,
                 std::vector<std::int8_t>& cells)
{
  double y_lo = kNoHit, y_hi = -kNoHit;
  for (const auto& p : polygon.outer)
  {
    y_lo = std::min(y_lo, p.y);
    y_hi = std::max(y_hi, p.y);
  }
  const int r0 = std::max(0, static_cast<int>(std::floor((y_lo - g.origin_y) / g.resolution)));
  const int r1 = std::min(g.height - 1, static_cast<int>(std::floor((y_hi - g.origin_y) / g.resolution)));
  std::vector<double> xs;
  for (int r = r0; r <= r1; ++r)
  {
    const double yc = g.origin_y + (r + 0.5) * g.resolution;
    xs.clear();
    auto ring = [&](const core::Ring& rg) {
      for (std::size_t i = 0, j = rg.size() - 1; i < rg.size(); j = i++)
      {
        const auto& a = rg[j];
        const auto& b = rg[i];
        if ((a.y > yc) != (b.y > yc)) xs.push_back(a.x + (yc - a.y) * (b.x - a.x) / (b.y - a.y));
      }
    };
    if (polygon.outer.size() >= 3) ring(polygon.outer);
    for (const auto& h : polygon.holes)
      if (h.size() >= 3) ring(h);
    std::sort(xs.begin(), xs.end());
    for (std::size_t k = 0; k + 1 < xs.size(); k += 2)
    {
      const int c0 = std::max(0, static_cast<int>(std::ceil((xs[k] - g.origin_x) / g.resolution - 0.5)));
      const int c1 =
          std::min(g.width - 1, static_cast<int>(std::floor((xs[k + 1] - g.origin_x) / g.resolution - 0.5)));
      for (int c = c0; c <= c1; ++c) setMax(cells, g.index(c, r), value);
    }
  }
}

void traceEdge(core::Point2 a, core::Point2 b, const core::GridGeometry& g, std::int8_t value,
               std::vector<std::int8_t>& cells)
{
  const double len = std::hypot(b.x - a.x, b.y - a.y);
  if (len <= 0.0)
  {
    core::CellIndex c;
    if (g.worldToCell(a, c)) setMax(cells, g.index(c), value);
    return;
  }
  traverseCells(g, a, (b.x - a.x) / len, (b.y - a.y) / len, len, [&](std::size_t i) { setMax(cells, i, value); });
}

}  // namespace

void rasterizePolygon(const core::Polygon& polygon, const core::GridGeometry& grid, std::int8_t value,
                      std::vector<std::int8_t>& cells)
{
  fillCentres(polygon, grid, value, cells);
  auto ring = [&](const core::Ring& rg) {
    for (std::size_t i = 0, j = rg.size() - 1; i < rg.size(); j = i++) traceEdge(rg[j], rg[i], grid, value, cells);
  };
  if (!polygon.outer.empty()) ring(polygon.outer);
  for (const auto& h : polygon.holes)
    if (!h.empty()) ring(h);
}

void rasterizeObject(const WorldObject& o, const core::GridGeometry& g, std::vector<std::int8_t>& cells)
{
  const double h = 0.5 * g.resolution;
  const auto value = static_cast<std::int8_t>(o.cell_class);
  double x0, y0, x1, y1;
  double c = 1.0, s = 0.0;
  if (o.shape == WorldObject::Shape::kCylinder)
  {
    x0 = o.cylinder.cx - o.cylinder.radius;
    x1 = o.cylinder.cx + o.cylinder.radius;
    y0 = o.cylinder.cy - o.cylinder.radius;
    y1 = o.cylinder.cy + o.cylinder.radius;
  }
  else
  {
    c = std::cos(o.box.yaw);
    s = std::sin(o.box.yaw);
    const double hx = 0.5 * (std::abs(c) * o.box.length + std::abs(s) * o.box.width);
    const double hy = 0.5 * (std::abs(s) * o.box.length + std::abs(c) * o.box.width);
    x0 = o.box.cx - hx;
    x1 = o.box.cx + hx;
    y0 = o.box.cy - hy;
    y1 = o.box.cy + hy;
  }
  const int cx0 = std::max(0, static_cast<int>(std::floor((x0 - g.origin_x) / g.resolution)));
  const int cy0 = std::max(0, static_cast<int>(std::floor((y0 - g.origin_y) / g.resolution)));
  const int cx1 = std::min(g.width - 1, static_cast<int>(std::floor((x1 - g.origin_x) / g.resolution)));
  const int cy1 = std::min(g.height - 1, static_cast<int>(std::floor((y1 - g.origin_y) / g.resolution)));
  for (int r = cy0; r <= cy1; ++r)
    for (int q = cx0; q <= cx1; ++q)
    {
      const core::Point2 ctr = g.cellCentre(core::CellIndex{ q, r });
      bool overlap;
      if (o.shape == WorldObject::Shape::kCylinder)
      {
        const double dx = std::max(0.0, std::abs(ctr.x - o.cylinder.cx) - h);
        const double dy = std::max(0.0, std::abs(ctr.y - o.cylinder.cy) - h);
        overlap = dx * dx + dy * dy < o.cylinder.radius * o.cylinder.radius - kOverlapEpsilon;
      }
      else
      {
        const double dx = ctr.x - o.box.cx, dy = ctr.y - o.box.cy;
        const double reach = h * (std::abs(c) + std::abs(s));
        overlap = std::abs(dx) < 0.5 * (std::abs(c) * o.box.length + std::abs(s) * o.box.width) + h - kOverlapEpsilon &&
                  std::abs(dy) < 0.5 * (std::abs(s) * o.box.length + std::abs(c) * o.box.width) + h - kOverlapEpsilon &&
                  std::abs(dx * c + dy * s) < 0.5 * o.box.length + reach - kOverlapEpsilon &&
                  std::abs(-dx * s + dy * c) < 0.5 * o.box.width + reach - kOverlapEpsilon;
      }
      if (overlap) setMax(cells, g.index(q, r), value);
    }
}

StaticClassRaster::StaticClassRaster(const std::vector<WorldBuilding>& buildings, double resolution)
{
  double x0 = kNoHit, y0 = kNoHit, x1 = -kNoHit, y1 = -kNoHit;
  for (const auto& b : buildings)
    for (const auto& p : b.footprint.outer)
    {
      x0 = std::min(x0, p.x);
      y0 = std::min(y0, p.y);
      x1 = std::max(x1, p.x);
      y1 = std::max(y1, p.y);
    }
  geometry_.resolution = resolution;
  if (!(x0 <= x1))
  {
    geometry_.width = geometry_.height = 1;
    cells_.assign(1, static_cast<std::int8_t>(core::CellClass::kFree));
    return;
  }
  geometry_.origin_x = std::floor((x0 - kStaticMargin) / resolution) * resolution;
  geometry_.origin_y = std::floor((y0 - kStaticMargin) / resolution) * resolution;
  geometry_.width = static_cast<int>(std::ceil((x1 + kStaticMargin - geometry_.origin_x) / resolution));
  geometry_.height = static_cast<int>(std::ceil((y1 + kStaticMargin - geometry_.origin_y) / resolution));
  cells_.assign(geometry_.numCells(), static_cast<std::int8_t>(core::CellClass::kFree));
  for (const auto& b : buildings) rasterizePolygon(b.footprint, geometry_, static_cast<std::int8_t>(b.cell_class), cells_);
}

core::GridGeometry StaticClassRaster::window(double cx, double cy, double size_x, double size_y) const
{
  core::GridGeometry w;
  const double res = geometry_.resolution;
  w.resolution = res;
  w.width = std::max(1, static_cast<int>(std::lround(size_x / res)));
  w.height = std::max(1, static_cast<int>(std::lround(size_y / res)));
  w.origin_x = std::round((cx - 0.5 * w.width * res) / res) * res;
  w.origin_y = std::round((cy - 0.5 * w.height * res) / res) * res;
  return w;
}

void StaticClassRaster::classes(const core::GridGeometry& w, const std::vector<WorldObject>& objects,
                                std::vector<std::int8_t>& out) const
{
  out.assign(w.numCells(), static_cast<std::int8_t>(core::CellClass::kFree));
  const double res = geometry_.resolution;
  const int off_x = static_cast<int>(std::lround((w.origin_x - geometry_.origin_x) / res));
  const int off_y = static_cast<int>(std::lround((w.origin_y - geometry_.origin_y) / res));
  for (int r = 0; r < w.height; ++r)
  {
    const int sr = r + off_y;
    if (sr < 0 || sr >= geometry_.height) continue;
    const int q0 = std::max(0, -off_x), q1 = std::min(w.width, geometry_.width - off_x);
    if (q0 >= q1) continue;
    std::copy_n(cells_.begin() + static_cast<std::ptrdiff_t>(geometry_.index(q0 + off_x, sr)), q1 - q0,
                out.begin() + static_cast<std::ptrdiff_t>(w.index(q0, r)));
  }
  for (const auto& o : objects) rasterizeObject(o, w, out);
}

}  // namespace sim
}  // namespace map_aided_fusion

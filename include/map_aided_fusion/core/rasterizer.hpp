/**
 * @file rasterizer.hpp
 * @brief Exact cell-centre polygon filling by scanlines (edge crossings per row, sorted, paired).
 *
 * A cell belongs to a polygon when its centre does, by the even-odd rule over all of the polygon's rings
 * (so holes are excluded). Boundaries are half-open: a centre exactly on a left or lower edge is inside, on a
 * right or upper edge outside, so polygons sharing an edge never both claim a cell and tile without gaps.
 * The cost is proportional to the number of rows crossed by the edges plus the cells filled, not to the
 * number of cells times the number of polygons.
 */
#pragma once

#include <cmath>
#include <utility>
#include <vector>

#include "map_aided_fusion/core/grid_geometry.hpp"
#include "map_aided_fusion/core/vector_map.hpp"

namespace map_aided_fusion {
namespace core {

/// A run of cells of one row: columns [col_begin, col_end).
struct CellSpan
{
  int row = 0;
  int col_begin = 0;
  int col_end = 0;
};

/**
 * Scanline filler over a grid; reuse one instance to avoid reallocations. Rows are swept with an active
 * edge list: memory is O(edges), whatever the number of rows an edge spans (a zig-zag ring of 10^6
 * vertices needs tens of MB, not one entry per edge per row).
 */
class ScanlineRasterizer
{
public:
  explicit ScanlineRasterizer(const GridGeometry& geometry) : geometry_(geometry) {}

  const GridGeometry& geometry() const { return geometry_; }

  /**
   * @brief Spans of the cells whose centres are inside the rings (even-odd rule), clipped to the grid.
   * @param rings closed rings (closing vertex not repeated; a repeated one is harmless); non-finite vertices
   *        make the call a no-op
   * @param spans replaced by the spans, sorted by row then column
   */
  void fill(const std::vector<const Ring*>& rings, std::vector<CellSpan>& spans);

  /// Spans of a polygon with holes.
  void fill(const Polygon& polygon, std::vector<CellSpan>& spans);

  /// Spans of a single ring.
  void fill(const Ring& ring, std::vector<CellSpan>& spans);

private:
  /// An edge crossing the centre lines of rows [row_begin, row_end).
  struct Edge
  {
    long row_begin;
    long row_end;
    double ax, ay, slope;  ///< x at a row centre yc is ax + (yc − ay)·slope
  };
  void addRing(const Ring& ring);

  GridGeometry geometry_;
  std::vector<Edge> edges_;
  std::vector<std::size_t> active_;
  std::vector<double> row_x_;
};

/// Polygons covering a road centre line buffered by half its width: one rectangle per segment and a regular
/// polygon approximating a disc at every vertex (round joins and caps). Appends to @p out.
void bufferRoadLine(const RoadLine& line, std::vector<Ring>& out);

/**
 * @brief Calls @p visit(index) for every cell of @p grid that the 2D segment from @p origin along the unit
 *        direction (dx, dy) over [0, length] passes through, in order (Amanatides & Woo).
 */
template <class Visit>
void traverseCells(const GridGeometry& grid, Point2 origin, double dx, double dy, double length,
                   Visit&& visit)
{
  const double res = grid.resolution;
  double fx = (origin.x - grid.origin_x) / res, fy = (origin.y - grid.origin_y) / res;
  int ix = static_cast<int>(std::floor(fx)), iy = static_cast<int>(std::floor(fy));
  const int step_x = dx > 0.0 ? 1 : -1, step_y = dy > 0.0 ? 1 : -1;
  constexpr double kInf = 1e300;
  double t_max_x = dx != 0.0 ? ((ix + (dx > 0.0 ? 1 : 0)) - fx) * res / dx : kInf;
  double t_max_y = dy != 0.0 ? ((iy + (dy > 0.0 ? 1 : 0)) - fy) * res / dy : kInf;
  const double dt_x = dx != 0.0 ? res / std::abs(dx) : kInf;
  const double dt_y = dy != 0.0 ? res / std::abs(dy) : kInf;
  double t = 0.0;
  while (t <= length)
  {
    if (ix >= 0 && iy >= 0 && ix < grid.width && iy < grid.height)
      visit(static_cast<std::size_t>(iy) * static_cast<std::size_t>(grid.width) + static_cast<std::size_t>(ix));
    else if ((ix < 0 && step_x < 0) || (iy < 0 && step_y < 0) || (ix >= grid.width && step_x > 0) ||
             (iy >= grid.height && step_y > 0))
      return;  // outside and moving away
    if (t_max_x < t_max_y)
    {
      t = t_max_x;
      t_max_x += dt_x;
      ix += step_x;
    }
    else
    {
      t = t_max_y;
      t_max_y += dt_y;
      iy += step_y;
    }
  }
}

}  // namespace core
}  // namespace map_aided_fusion

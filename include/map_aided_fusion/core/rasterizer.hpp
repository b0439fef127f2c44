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

}  // namespace core
}  // namespace map_aided_fusion

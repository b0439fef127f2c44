/**
 * @file grid_geometry.hpp
 * @brief Geometry of a regular 2D grid: resolution, size, origin, world ↔ cell conversions.
 *
 * Axes follow REP-103: x forward/east, y left/north, cells stored row-major with x fastest, row 0 at the
 * lowest y, exactly like nav_msgs/OccupancyGrid (whose info.origin is the corner of cell (0, 0)).
 */
#pragma once

#include <cmath>
#include <cstddef>

#include "map_aided_fusion/core/parameters.hpp"

namespace map_aided_fusion {
namespace core {

/// Integer cell coordinates: column (along x) and row (along y).
struct CellIndex
{
  int x = 0;
  int y = 0;
  bool operator==(const CellIndex& o) const { return x == o.x && y == o.y; }
};

/// A 2D point in the grid's frame, metres.
struct Point2
{
  double x = 0.0;
  double y = 0.0;
};

/// Geometry of an axis-aligned grid.
struct GridGeometry
{
  double resolution = 0.5;  ///< cell side, metres (> 0)
  int width = 0;            ///< number of columns (along x)
  int height = 0;           ///< number of rows (along y)
  double origin_x = 0.0;    ///< x of the outer corner of cell (0, 0), metres
  double origin_y = 0.0;    ///< y of the outer corner of cell (0, 0), metres

  /// A grid of @p size_x × @p size_y metres centred on (cx, cy).
  static GridGeometry centred(double size_x, double size_y, double resolution, double cx = 0.0, double cy = 0.0)
  {
    GridGeometry g;
    g.resolution = resolution;
    g.width = static_cast<int>(std::lround(size_x / resolution));
    g.height = static_cast<int>(std::lround(size_y / resolution));
    g.origin_x = cx - 0.5 * g.width * resolution;
    g.origin_y = cy - 0.5 * g.height * resolution;
    return g;
  }

  std::size_t numCells() const { return static_cast<std::size_t>(width) * static_cast<std::size_t>(height); }
  double sizeX() const { return width * resolution; }
  double sizeY() const { return height * resolution; }

  bool contains(CellIndex c) const { return c.x >= 0 && c.y >= 0 && c.x < width && c.y < height; }

  /// Row-major linear index of a cell (no bounds check).
  std::size_t index(CellIndex c) const
  {
    return static_cast<std::size_t>(c.y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(c.x);
  }
  std::size_t index(int x, int y) const { return index(CellIndex{ x, y }); }

  /// Cell coordinates of a linear index.
  CellIndex cellOf(std::size_t i) const
  {
    return CellIndex{ static_cast<int>(i % static_cast<std::size_t>(width)),
                      static_cast<int>(i / static_cast<std::size_t>(width)) };
  }

  /// The cell that holds a world point (floor), which may lie outside the grid.
  CellIndex cellAt(Point2 p) const
  {
    return CellIndex{ static_cast<int>(std::floor((p.x - origin_x) / resolution)),
                      static_cast<int>(std::floor((p.y - origin_y) / resolution)) };
  }

  /// World → cell; false when the point is outside the grid (or not finite).
  bool worldToCell(Point2 p, CellIndex& c) const
  {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) return false;
    const double fx = (p.x - origin_x) / resolution;
    const double fy = (p.y - origin_y) / resolution;
    if (fx < 0.0 || fy < 0.0 || fx >= width || fy >= height) return false;
    c = CellIndex{ static_cast<int>(fx), static_cast<int>(fy) };
    return true;
  }

  /// Centre (x̃, ỹ) of a cell in world coordinates.
  Point2 cellCentre(CellIndex c) const
  {
    return Point2{ origin_x + (c.x + 0.5) * resolution, origin_y + (c.y + 0.5) * resolution };
  }

  bool operator==(const GridGeometry& o) const
  {
    return resolution == o.resolution && width == o.width && height == o.height && origin_x == o.origin_x &&
           origin_y == o.origin_y;
  }
  bool operator!=(const GridGeometry& o) const { return !(*this == o); }

  /// @throws ParameterError when the resolution is not > 0 or the size is not ≥ 1 × 1 cells.
  void validate() const;
};

/// A planar pose: position (metres) and heading (radians, counter-clockwise from +x), REP-103.
struct Pose2
{
  double x = 0.0;
  double y = 0.0;
  double yaw = 0.0;
};

/// A borrowed list of 2D points, interleaved x0, y0, x1, y1, … metres (count points).
struct ObstaclePoints
{
  const float* xy = nullptr;
  std::size_t count = 0;
};

}  // namespace core
}  // namespace map_aided_fusion

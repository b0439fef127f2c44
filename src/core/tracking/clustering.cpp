#include "map_aided_fusion/core/tracking/clustering.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <utility>

namespace map_aided_fusion {
namespace core {

namespace {

constexpr double kMaxCellCoordinate = 1e15;  // cell indices beyond: out of range (the return skipped)
constexpr double kMaxDenseCells = 4e6;       // cells of the dense index (16 MB) before a hash map

std::int64_t cellKey(std::int64_t x, std::int64_t y)
{
  return static_cast<std::int64_t>((static_cast<std::uint64_t>(x) << 32) ^ (static_cast<std::uint64_t>(y) & 0xffffffffULL));
}

/// The occupied cells of the returns and, per cell, its number (in the order of its first return). Indexed in a
/// dense local grid over the returns' bounding box, or a hash map when that box is too large (far outliers).
class OccupiedCells
{
public:
  using Coord = std::pair<std::int64_t, std::int64_t>;

  /// The cells of @p points; returns out of reach (clusterable() false) have none (cellOf() −1).
  OccupiedCells(const std::vector<Point2>& points, double cell) : reach_(kMaxCellCoordinate * cell)
  {
    double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
    for (const Point2& q : points)
      if (clusterable(q))
      {
        x0 = std::min(x0, q.x);
        y0 = std::min(y0, q.y);
        x1 = std::max(x1, q.x);
        y1 = std::max(y1, q.y);
      }
    cell_of_.assign(points.size(), -1);
    if (x0 > x1) return;
    // Cells on the world lattice (the same cells from scan to scan), offset by a free border of one cell.
    const double span_x = (x1 - x0) / cell + 4.0, span_y = (y1 - y0) / cell + 4.0;
    dense_ = span_x * span_y <= kMaxDenseCells;
    if (dense_)
    {
      cx0_ = static_cast<std::int64_t>(std::floor(x0 / cell)) - 1;
      cy0_ = static_cast<std::int64_t>(std::floor(y0 / cell)) - 1;
      w_ = static_cast<std::int64_t>(span_x);
      h_ = static_cast<std::int64_t>(span_y);
      dense_index_.assign(static_cast<std::size_t>(w_ * h_), -1);
    }
    for (int i = 0; i < static_cast<int>(points.size()); ++i)
    {
      const Point2 q = points[i];
      if (!clusterable(q)) continue;
      const auto cx = static_cast<std::int64_t>(std::floor(q.x / cell));
      const auto cy = static_cast<std::int64_t>(std::floor(q.y / cell));
      // Inside the bounding box and its border: a dense offset always exists.
      int& s = dense_ ? dense_index_[static_cast<std::size_t>(denseOffset(cx, cy))]
                      : sparse_index_.emplace(cellKey(cx, cy), -1).first->second;
      if (s < 0)
      {
        s = static_cast<int>(coords_.size());
        coords_.emplace_back(cx, cy);
      }
      cell_of_[i] = s;
    }
  }

  /// A return this far out (a pose of 10¹⁵ m) has no cell index: skipped, as a non-finite one.
  bool clusterable(Point2 q) const { return std::abs(q.x) < reach_ && std::abs(q.y) < reach_; }
  /// The number of cell (@p cx, @p cy), or −1 when no return lies in it.
  int numberOf(std::int64_t cx, std::int64_t cy) const
  {
    if (dense_)
    {
      const std::int64_t k = denseOffset(cx, cy);
      return k < 0 ? -1 : dense_index_[static_cast<std::size_t>(k)];
    }
    const auto it = sparse_index_.find(cellKey(cx, cy));
    return it == sparse_index_.end() ? -1 : it->second;
  }
  const std::vector<Coord>& coords() const { return coords_; }
  const std::vector<int>& cellOf() const { return cell_of_; }

private:
  /// The dense index's offset of cell (@p cx, @p cy), −1 outside it.
  std::int64_t denseOffset(std::int64_t cx, std::int64_t cy) const
  {
    cx -= cx0_;
    cy -= cy0_;
    return cx < 0 || cy < 0 || cx >= w_ || cy >= h_ ? -1 : cy * w_ + cx;
  }

  double reach_;
  bool dense_ = false;
  std::int64_t cx0_ = 0, cy0_ = 0, w_ = 0, h_ = 0;
  std::vector<int> dense_index_;
  std::unordered_map<std::int64_t, int> sparse_index_;
  std::vector<Coord> coords_;
  std::vector<int> cell_of_;
};

/// Per occupied cell, the smallest cell of its 8-connected component (union-find, each pair of touching cells once).
std::vector<int> componentRoots(const OccupiedCells& cells)
{
  const std::vector<OccupiedCells::Coord>& coords = cells.coords();
  std::vector<int> parent(coords.size());
  for (std::size_t k = 0; k < parent.size(); ++k) parent[k] = static_cast<int>(k);
  auto root = [&](int a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  constexpr int kAhead[4][2] = { { 1, 0 }, { -1, 1 }, { 0, 1 }, { 1, 1 } };  // the four neighbours ahead
  for (std::size_t k = 0; k < coords.size(); ++k)
    for (const auto& d : kAhead)
    {
      const int n = cells.numberOf(coords[k].first + d[0], coords[k].second + d[1]);
      if (n < 0) continue;
      const int a = root(static_cast<int>(k)), b = root(n);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  for (std::size_t k = 0; k < coords.size(); ++k) parent[k] = root(static_cast<int>(k));
  return parent;
}

}  // namespace

std::vector<std::vector<int>> connectedClusters(const std::vector<Point2>& points, double cell)
{
  const OccupiedCells cells(points, cell);
  const std::vector<int>& cell_of = cells.cellOf();
  const std::vector<int> root = componentRoots(cells);
  // Points per cluster, in point order; clusters numbered by the first point of each (counted, then filled).
  std::vector<int> cluster_of_root(root.size(), -1);
  std::vector<int> cluster_size;
  for (int i = 0; i < static_cast<int>(points.size()); ++i)
  {
    if (cell_of[i] < 0) continue;
    int& c = cluster_of_root[root[cell_of[i]]];
    if (c < 0)
    {
      c = static_cast<int>(cluster_size.size());
      cluster_size.push_back(0);
    }
    ++cluster_size[c];
  }
  std::vector<std::vector<int>> clusters(cluster_size.size());
  for (std::size_t c = 0; c < clusters.size(); ++c) clusters[c].reserve(static_cast<std::size_t>(cluster_size[c]));
  for (int i = 0; i < static_cast<int>(points.size()); ++i)
    if (cell_of[i] >= 0) clusters[cluster_of_root[root[cell_of[i]]]].push_back(i);
  return clusters;
}

}  // namespace core
}  // namespace map_aided_fusion

#include "map_aided_fusion/core/tracking/association.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <Eigen/Cholesky>

namespace map_aided_fusion {
namespace core {

namespace {

constexpr double kMaxCellCoordinate = 1e15;  // cell indices beyond are clamped

/// The cells of a grid of side @p cell that the square around a disc covers, as a range of indices per axis; wide
/// when it spans more than kMaxGateCells cells or is not finite.
struct CellSpan
{
  std::int64_t x0 = 0, x1 = -1, y0 = 0, y1 = -1;
  bool wide = false;
};

CellSpan cellSpan(const GateDisc& d, double cell)
{
  const auto index = [&](double v) {
    return static_cast<std::int64_t>(std::floor(std::clamp(v / cell, -kMaxCellCoordinate, kMaxCellCoordinate)));
  };
  CellSpan s;
  if (!std::isfinite(d.radius) || !(d.radius / cell < kMaxGateCells))
  {
    s.wide = true;
    return s;
  }
  s.x0 = index(d.centre.x - d.radius);
  s.x1 = index(d.centre.x + d.radius);
  s.y0 = index(d.centre.y - d.radius);
  s.y1 = index(d.centre.y + d.radius);
  s.wide = (s.x1 - s.x0 + 1) * (s.y1 - s.y0 + 1) > kMaxGateCells;
  return s;
}

/// A cell's key; distinct cells may share one (a hash): that only adds candidates, which the distance test judges.
std::uint64_t cellKey(std::int64_t cx, std::int64_t cy)
{
  return (static_cast<std::uint64_t>(cx) << 32) ^ (static_cast<std::uint64_t>(cy) & 0xffffffffULL);
}

/// The columns' index: (cell key, column) sorted, and the columns too wide for it.
struct ColumnIndex
{
  std::vector<std::pair<std::uint64_t, int>> cells;
  std::vector<int> wide;
};

ColumnIndex indexColumns(const std::vector<GateDisc>& cols, double cell)
{
  ColumnIndex index;
  for (int j = 0; j < static_cast<int>(cols.size()); ++j)
  {
    const CellSpan span = cellSpan(cols[j], cell);
    if (span.wide) index.wide.push_back(j);
    for (std::int64_t cx = span.x0; cx <= span.x1 && !span.wide; ++cx)
      for (std::int64_t cy = span.y0; cy <= span.y1; ++cy) index.cells.emplace_back(cellKey(cx, cy), j);
  }
  std::sort(index.cells.begin(), index.cells.end());
  return index;
}

}  // namespace

std::vector<std::pair<int, int>> spatialGate(const std::vector<GateDisc>& rows, const std::vector<GateDisc>& cols,
                                             double cell)
{
  std::vector<std::pair<int, int>> pairs;
  if (rows.empty() || cols.empty() || !(cell > 0.0)) return pairs;
  const ColumnIndex index = indexColumns(cols, cell);
  std::vector<int> seen_by(cols.size(), -1);
  int row = 0;
  const auto consider = [&](int j) {
    if (seen_by[j] == row) return;
    seen_by[j] = row;
    // The grid's cells are coarser than the discs: the exact test (a distance that is not a number fails it).
    const double dx = rows[row].centre.x - cols[j].centre.x, dy = rows[row].centre.y - cols[j].centre.y;
    const double r = cols[j].radius + rows[row].radius;
    if (!(dx * dx + dy * dy <= r * r)) return;
    pairs.emplace_back(row, j);
  };
  for (; row < static_cast<int>(rows.size()); ++row)
  {
    const CellSpan span = cellSpan(rows[row], cell);
    for (const int j : index.wide) consider(j);
    if (span.wide)
    {
      for (int j = 0; j < static_cast<int>(cols.size()); ++j) consider(j);
      continue;
    }
    for (std::int64_t cx = span.x0; cx <= span.x1; ++cx)
      for (std::int64_t cy = span.y0; cy <= span.y1; ++cy)
      {
        const std::uint64_t k = cellKey(cx, cy);
        auto it = std::lower_bound(index.cells.begin(), index.cells.end(), k,
                                   [](const std::pair<std::uint64_t, int>& e, std::uint64_t v) { return e.first < v; });
        for (; it != index.cells.end() && it->first == k; ++it) consider(it->second);
      }
  }
  return pairs;
}

std::optional<double> mahalanobisGate(const Eigen::Vector2d& y, const Eigen::Matrix2d& s, double max_distance,
                                      double gate)
{
  if (y.norm() > max_distance) return std::nullopt;
  const double d2 = y.dot(s.ldlt().solve(y));
  if (std::isfinite(d2) && d2 >= 0.0 && d2 <= gate) return d2;
  return std::nullopt;
}

}  // namespace core
}  // namespace map_aided_fusion

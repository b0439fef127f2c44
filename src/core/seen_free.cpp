#include "map_aided_fusion/core/seen_free.hpp"

#include <algorithm>
#include <cmath>

namespace map_aided_fusion {
namespace core {

namespace {

constexpr double kCellRounding = 1e-9;  // a margin of exactly k cells is k cells, not k + 1

/// Per cell of a width × height grid, 1 where some cell of @p marked within @p r cells (square) is 1.
std::vector<std::uint8_t> dilate(const std::vector<std::uint8_t>& marked, int width, int height, int r)
{
  if (r <= 0) return marked;
  std::vector<std::uint8_t> rows(marked.size(), 0), out(marked.size(), 0);
  std::vector<int> prefix(static_cast<std::size_t>(std::max(width, height)) + 1);
  auto window = [&](int i, int n) { return prefix[std::min(n, i + r + 1)] - prefix[std::max(0, i - r)] > 0; };
  for (int y = 0; y < height; ++y)
  {
    const std::size_t row = static_cast<std::size_t>(y) * width;
    for (int x = 0; x < width; ++x) prefix[x + 1] = prefix[x] + marked[row + x];
    for (int x = 0; x < width; ++x) rows[row + x] = window(x, width);
  }
  for (int x = 0; x < width; ++x)
  {
    for (int y = 0; y < height; ++y) prefix[y + 1] = prefix[y] + rows[static_cast<std::size_t>(y) * width + x];
    for (int y = 0; y < height; ++y) out[static_cast<std::size_t>(y) * width + x] = window(y, height);
  }
  return out;
}

}  // namespace

SeenFree::SeenFree(const ScanMassGrid& scan, const Pose2& pose, double stamp, double margin, double small_margin)
  : geometry_(scan.geometry()), pose_(pose), cos_(std::cos(pose.yaw)), sin_(std::sin(pose.yaw)), stamp_(stamp)
{
  const std::size_t n = geometry_.numCells();
  const float* f = scan.plane(FrameSG::kF);
  std::vector<std::uint8_t> not_free(n);
  for (std::size_t i = 0; i < n; ++i) not_free[i] = !(f[i] >= kSeenFreeMass);
  auto cells = [&](double m) {
    return std::max(0, static_cast<int>(std::ceil(m / geometry_.resolution - kCellRounding)));
  };
  auto clearAt = [&](int r) {
    std::vector<std::uint8_t> out = dilate(not_free, geometry_.width, geometry_.height, r);
    for (std::uint8_t& c : out) c = !c;
    return out;
  };
  const int r = cells(margin);
  clear_ = clearAt(r);
  for (std::uint8_t c : clear_) clear_count_ += c;
  // The same whole cells as the margin: clear(p, true) falls back to clear_.
  if (small_margin >= 0.0 && cells(small_margin) != r) clear_small_ = clearAt(cells(small_margin));
}

bool SeenFree::clear(Point2 p, bool small) const
{
  const std::vector<std::uint8_t>& cells = small && !clear_small_.empty() ? clear_small_ : clear_;
  if (cells.empty() || !std::isfinite(p.x) || !std::isfinite(p.y)) return false;
  const double dx = p.x - pose_.x, dy = p.y - pose_.y;
  CellIndex c;
  if (!geometry_.worldToCell(Point2{ cos_ * dx + sin_ * dy, -sin_ * dx + cos_ * dy }, c)) return false;
  return cells[geometry_.index(c)] != 0;
}

double SeenFree::clearShare(const std::vector<Point2>& points, bool small) const
{
  if (points.empty()) return 0.0;
  std::size_t n = 0;
  for (const Point2& p : points) n += clear(p, small);
  return static_cast<double>(n) / static_cast<double>(points.size());
}

}  // namespace core
}  // namespace map_aided_fusion

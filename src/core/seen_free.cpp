#include "map_aided_fusion/core/seen_free.hpp"

#include <algorithm>
#include <cmath>

namespace map_aided_fusion {
namespace core {

namespace {

constexpr double kCellRounding = 1e-9;  // a margin of exactly k cells is k cells, not k + 1
/// Up to this margin (cells), a row's neighbourhood is the OR of its shifted copies; wider, the distances to the
/// nearest blocked cells on either side.
constexpr int kMaxShiftedMargin = 8;

/// 1 where the cell was not seen free.
inline std::uint8_t blocked(float f) { return !(f >= SeenFree::kSeenFreeMass); }

/// @p out (width × height): 1 where the cell and every cell within @p r cells (square) were seen free (m(F) in @p f).
/// Along each row, which cells have a blocked cell within r; then down each column, a running count of those rows.
void clearWithin(const float* f, int width, int height, int r, std::vector<std::uint8_t>& out)
{
  const std::size_t w = static_cast<std::size_t>(width), n = w * static_cast<std::size_t>(height);
  out.resize(n);
  if (r <= 0)
  {
    for (std::size_t i = 0; i < n; ++i) out[i] = !blocked(f[i]);
    return;
  }
  std::vector<std::uint8_t> near(n);  // some blocked cell within r along the row
  std::vector<std::uint8_t> padded(w + 2 * static_cast<std::size_t>(r), 0);
  for (std::size_t y = 0; y < static_cast<std::size_t>(height); ++y)
  {
    const float* row = f + y * w;
    std::uint8_t* o = near.data() + y * w;
    if (r <= kMaxShiftedMargin)
    {
      for (std::size_t x = 0; x < w; ++x) padded[x + static_cast<std::size_t>(r)] = blocked(row[x]);
      for (std::size_t x = 0; x < w; ++x) o[x] = padded[x];
      for (int d = 1; d <= 2 * r; ++d)
        for (std::size_t x = 0; x < w; ++x) o[x] |= padded[x + static_cast<std::size_t>(d)];
    }
    else
    {
      int last = -r - 1;
      for (int x = 0; x < width; ++x)
      {
        last = blocked(row[x]) ? x : last;
        o[x] = x - last <= r;
      }
      int next = width + r;
      for (int x = width - 1; x >= 0; --x)
      {
        next = blocked(row[x]) ? x : next;
        o[x] |= next - x <= r;
      }
    }
  }
  std::vector<std::int32_t> count(w, 0);  // rows of the window [y − r, y + r] with a blocked cell near, per column
  auto add = [&](int y, std::int32_t sign) {
    const std::uint8_t* row = near.data() + static_cast<std::size_t>(y) * w;
    for (std::size_t x = 0; x < w; ++x) count[x] += sign * row[x];
  };
  for (int y = 0; y < std::min(r, height); ++y) add(y, 1);
  for (int y = 0; y < height; ++y)
  {
    if (y + r < height) add(y + r, 1);
    if (y - r - 1 >= 0) add(y - r - 1, -1);
    std::uint8_t* o = out.data() + static_cast<std::size_t>(y) * w;
    for (std::size_t x = 0; x < w; ++x) o[x] = count[x] == 0;
  }
}

}  // namespace

SeenFree::SeenFree(const ScanMassGrid& scan, const Pose2& pose, double stamp, double margin, double small_margin)
  : geometry_(scan.geometry()), pose_(pose), cos_(std::cos(pose.yaw)), sin_(std::sin(pose.yaw)), stamp_(stamp)
{
  const float* f = scan.plane(FrameSG::kF);
  auto cells = [&](double m) {
    return std::max(0, static_cast<int>(std::ceil(m / geometry_.resolution - kCellRounding)));
  };
  const int r = cells(margin);
  clearWithin(f, geometry_.width, geometry_.height, r, clear_);
  for (std::uint8_t c : clear_) clear_count_ += c;
  // The same whole cells as the margin: clear(p, true) falls back to clear_.
  if (small_margin >= 0.0 && cells(small_margin) != r)
    clearWithin(f, geometry_.width, geometry_.height, cells(small_margin), clear_small_);
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

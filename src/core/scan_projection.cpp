#include "map_aided_fusion/core/scan_projection.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "cell_kernels.hpp"

namespace map_aided_fusion {
namespace core {

namespace {

constexpr std::size_t kRowBand = 32;        // window rows per chunk of the rows' intervals and occupancy
constexpr std::size_t kClearanceRows = 64;  // window rows per chunk of the clearance's passes
constexpr std::size_t kMarkChunk = 32768;   // scan cells or returns per chunk of the occupancy marks

struct ScanPlanes
{
  const float* f;
  const float* o;
  const float* omega;
};

/// The scan cell under (fxr + x dfx, fyr + x dfy) (scan cells), which the row's interval puts inside the scan grid.
/// The interval's test rounds the products without FMA; a clone that contracts them may land one rounding past the
/// last column or row, so the index is kept inside. Both samplers below inline this one expression.
MAF_INLINE int scanCell(double fxr, double fyr, double dfx, double dfy, int x, int scan_width, int scan_height)
{
  const double fx = fxr + x * dfx, fy = fyr + x * dfy;
  const int ix = std::min(static_cast<int>(fx), scan_width - 1), iy = std::min(static_cast<int>(fy), scan_height - 1);
  return iy * scan_width + ix;
}

/// Window cells [x0, x1) of one row, all inside the scan grid, into @p f, @p o, @p omega [0, x1 − x0): each takes the
/// scan cell under it; with @p points the occupied mass goes to Ω (point occupancy marks it later).
MAF_TARGET_CLONES
void sampleRun(ScanPlanes scan, int scan_width, int scan_height, double fxr, double fyr, double dfx, double dfy, int x0,
               int x1, bool points, float* __restrict f, float* __restrict o, float* __restrict omega)
{
  for (int x = x0; x < x1; ++x)
  {
    const int i = scanCell(fxr, fyr, dfx, dfy, x, scan_width, scan_height);
    f[x - x0] = scan.f[i];
    o[x - x0] = points ? 0.0f : scan.o[i];
    omega[x - x0] = points ? scan.omega[i] + scan.o[i] : scan.omega[i];
  }
}

/// sampleRun()'s cells [x0, x1) whose scan cell holds occupied mass, into @p occupied [0, x1 − x0).
MAF_TARGET_CLONES
void sampleOccupied(const float* __restrict scan_o, int scan_width, int scan_height, double fxr, double fyr, double dfx,
                    double dfy, int x0, int x1, std::uint8_t* __restrict occupied)
{
  for (int x = x0; x < x1; ++x)
    occupied[x - x0] = scan_o[scanCell(fxr, fyr, dfx, dfy, x, scan_width, scan_height)] > 0.0f;
}

/// The free mass of the cells [0, n) whose @p near is set goes to Ω.
void clearFree(const std::uint8_t* __restrict near, std::size_t n, float* __restrict f, float* __restrict omega)
{
  for (std::size_t x = 0; x < n; ++x)
  {
    const bool clear = near[x] != 0;
    omega[x] = clear ? omega[x] + f[x] : omega[x];
    f[x] = clear ? 0.0f : f[x];
  }
}

/// out[x] |= row[x] for x in [0, n).
void orRow(const std::uint8_t* __restrict row, std::size_t n, std::uint8_t* __restrict out)
{
  for (std::size_t x = 0; x < n; ++x) out[x] |= row[x];
}

}  // namespace

void ScanProjection::plan(const ScanMassGrid& scan, const Pose2& pose, const GridGeometry& window,
                          const ObstaclePoints* obstacles, int clearance_cells, const Parallel& par)
{
  scan_ = &scan;
  window_ = window;
  points_ = obstacles != nullptr;
  clearance_ = clearance_cells > 0;
  const GridGeometry& sg = scan.geometry();
  const double c = std::cos(pose.yaw), s = std::sin(pose.yaw);
  const double inv_res = 1.0 / sg.resolution;
  const double dfx = c * window.resolution * inv_res, dfy = -s * window.resolution * inv_res;
  dfx_ = dfx;
  dfy_ = dfy;
  const int w = window.width;
  const std::size_t ws = static_cast<std::size_t>(w), h = static_cast<std::size_t>(window.height);
  const std::size_t n = window.numCells();
  // Inverse mapping: window cell centre → vehicle frame → scan cell.
  const Point2 corner = window.cellCentre(CellIndex{ 0, 0 });
  const double dx0 = corner.x - pose.x, dy0 = corner.y - pose.y;
  const double fx00 = (c * dx0 + s * dy0 - sg.origin_x) * inv_res, fy00 = (-s * dx0 + c * dy0 - sg.origin_y) * inv_res;
  const double drx = s * window.resolution * inv_res, dry = c * window.resolution * inv_res;  // per window row
  const double sw_max = sg.width, sh_max = sg.height;
  // Each predicate of "inside the scan grid" is monotone along a row (fx, fy are linear in x and rounding is monotone),
  // so the window cells that sample the scan grid are one interval per row: it is bracketed from the exact bounds
  // and then trimmed with the very test a per-cell check would use, so the samples are those of a per-cell check.
  auto inside = [&](double fxr, double fyr, int x) {
    const double fx = fxr + x * dfx, fy = fyr + x * dfy;
    return fx >= 0.0 && fy >= 0.0 && fx < sw_max && fy < sh_max;
  };
  auto row_interval = [&](double fxr, double fyr, int& x0, int& x1) {
    double lo = 0.0, hi = w;
    auto clip = [&](double f0, double df, double max) {  // 0 <= f0 + x df < max
      if (df == 0.0)
      {
        if (!(f0 >= 0.0 && f0 < max)) hi = lo;
        return;
      }
      const double a = (0.0 - f0) / df, b = (max - f0) / df;
      lo = std::max(lo, std::min(a, b));
      hi = std::min(hi, std::max(a, b));
    };
    clip(fxr, dfx, sw_max);
    clip(fyr, dfy, sh_max);
    constexpr int kBracket = 2;
    x0 = hi <= lo ? 0 : static_cast<int>(std::clamp(std::floor(lo) - kBracket, 0.0, static_cast<double>(w)));
    x1 = hi <= lo ? 0 : static_cast<int>(std::clamp(std::ceil(hi) + kBracket, 0.0, static_cast<double>(w)));
    while (x0 < x1 && !inside(fxr, fyr, x0)) ++x0;
    while (x1 > x0 && !inside(fxr, fyr, x1 - 1)) --x1;
  };
  fxr_.resize(h);
  fyr_.resize(h);
  lo_.resize(h);
  hi_.resize(h);
  occupied_.resize(n);
  const float* const s_o = scan.plane(FrameSG::kO);
  // Each row's interval, and the cells whose sample is occupied (none with point occupancy: its O goes to Ω).
  par.forRange(h, kRowBand, [&](std::size_t y0, std::size_t y1) {
    for (std::size_t y = y0; y < y1; ++y)
    {
      fxr_[y] = fx00 + static_cast<double>(y) * drx;
      fyr_[y] = fy00 + static_cast<double>(y) * dry;
      row_interval(fxr_[y], fyr_[y], lo_[y], hi_[y]);
      std::uint8_t* const occ = occupied_.data() + y * ws;
      std::fill(occ, occ + ws, std::uint8_t{ 0 });
      if (!points_ && lo_[y] < hi_[y])
        sampleOccupied(s_o, sg.width, sg.height, fxr_[y], fyr_[y], dfx, dfy, lo_[y], hi_[y], occ + lo_[y]);
    }
  });
  // Occupancy marks: the occupied cells (or returns) and the window cell under each are found by fixed chunks in
  // parallel, then listed per chunk of window cells in that order, so ties resolve as in one serial pass whatever the
  // thread count. A mark always leaves its cell occupied (it carries occupied mass, and applies only when more).
  const std::size_t sources = points_ ? obstacles->count : scan.numCells();
  const std::size_t mark_chunks = chunkCount(sources, kMarkChunk);
  if (found_.size() < mark_chunks) found_.resize(mark_chunks);
  auto window_cell = [&](double vx, double vy, std::size_t& j) {
    CellIndex wc;
    if (!window.worldToCell(Point2{ pose.x + c * vx - s * vy, pose.y + s * vx + c * vy }, wc)) return false;
    j = window.index(wc);
    return true;
  };
  par.forChunks(mark_chunks, [&](std::size_t chunk) {
    std::vector<Mark>& out = found_[chunk];
    out.clear();
    std::size_t j = 0;
    for (std::size_t k = chunk * kMarkChunk, end = std::min(sources, k + kMarkChunk); k < end; ++k)
    {
      if (points_)
      {
        const double vx = obstacles->xy[2 * k], vy = obstacles->xy[2 * k + 1];
        CellIndex sc;
        if (!sg.worldToCell(Point2{ vx, vy }, sc)) continue;
        const std::size_t i = sg.index(sc);
        if (s_o[i] > 0.0f && window_cell(vx, vy, j)) out.push_back(Mark{ i, j });
      }
      else if (s_o[k] > 0.0f)
      {
        const Point2 v = sg.cellCentre(sg.cellOf(k));
        if (window_cell(v.x, v.y, j)) out.push_back(Mark{ k, j });
      }
    }
  });
  const std::size_t chunks = chunkCount(n, kFusionChunkCells);
  if (marks_.size() < chunks) marks_.resize(chunks);
  for (std::vector<Mark>& m : marks_) m.clear();
  for (std::size_t chunk = 0; chunk < mark_chunks; ++chunk)
    for (const Mark& m : found_[chunk])
    {
      marks_[m.to / kFusionChunkCells].push_back(m);
      occupied_[m.to] = 1;
    }
  if (!clearance_) return;
  // Obstacle clearance: no free evidence within clearance_cells (square) of an occupied cell. Separable: a row pass
  // marks the cells within k columns of an occupied cell (an OR of 2k + 1 shifted rows of bytes), then a column pass
  // ORs the 2k + 1 marked rows around each row. Both vectorise, are linear in the window whatever the number of
  // occupied cells, and take bands of rows as independent chunks; fill() moves the free mass of the cells near one.
  row_near_.resize(n);
  near_.resize(n);
  const int k = clearance_cells;
  par.forRange(h, kClearanceRows, [&](std::size_t y0, std::size_t y1) {
    for (std::size_t y = y0; y < y1; ++y)
    {
      const std::uint8_t* const occ = occupied_.data() + y * ws;
      std::uint8_t* const r = row_near_.data() + y * ws;
      std::fill(r, r + ws, std::uint8_t{ 0 });
      for (int d = -k; d <= k; ++d)
        for (int x = std::max(0, -d), x1 = std::min(w, w - d); x < x1; ++x) r[x] |= occ[x + d];
    }
  });
  par.forRange(h, kClearanceRows, [&](std::size_t y0, std::size_t y1) {
    for (std::size_t y = y0; y < y1; ++y)
    {
      std::uint8_t* const out = near_.data() + y * ws;
      std::fill(out, out + ws, std::uint8_t{ 0 });
      const std::size_t from = y >= static_cast<std::size_t>(k) ? y - static_cast<std::size_t>(k) : 0;
      const std::size_t to = std::min(h, y + static_cast<std::size_t>(k) + 1);
      for (std::size_t r = from; r < to; ++r) orRow(row_near_.data() + r * ws, ws, out);
    }
  });
}

void ScanProjection::fillRun(std::size_t begin, std::size_t end, float* f, float* o, float* omega) const
{
  const std::size_t ws = static_cast<std::size_t>(window_.width);
  const GridGeometry& sg = scan_->geometry();
  const ScanPlanes planes{ scan_->plane(FrameSG::kF), scan_->plane(FrameSG::kO), scan_->plane(FrameSG::kOmega) };
  for (std::size_t i = begin; i < end;)
  {
    const std::size_t y = i / ws, row = y * ws;
    const std::size_t xa = i - row, xb = std::min(end, row + ws) - row;
    const std::size_t lo = std::clamp(static_cast<std::size_t>(lo_[y]), xa, xb);
    const std::size_t hi = std::clamp(static_cast<std::size_t>(hi_[y]), lo, xb);
    for (const auto& [x0, x1] : { std::pair{ xa, lo }, std::pair{ hi, xb } })  // vacuous outside the scan grid
    {
      const std::size_t k0 = row + x0 - begin, k1 = row + x1 - begin;
      std::fill(f + k0, f + k1, 0.0f);
      std::fill(o + k0, o + k1, 0.0f);
      std::fill(omega + k0, omega + k1, 1.0f);
    }
    if (lo < hi)
    {
      const std::size_t k = row + lo - begin;
      sampleRun(planes, sg.width, sg.height, fxr_[y], fyr_[y], dfx_, dfy_, static_cast<int>(lo), static_cast<int>(hi),
                points_, f + k, o + k, omega + k);
    }
    i = row + xb;
  }
}

void ScanProjection::fill(std::size_t begin, std::size_t end, float* f, float* o, float* omega) const
{
  fill(begin, end, f, o, omega, nullptr);
}

void ScanProjection::fill(std::size_t begin, std::size_t end, float* f, float* o, float* omega, float* empty) const
{
  if (end <= begin) return;
  fillRun(begin, end, f, o, omega);
  if (empty) std::fill(empty, empty + (end - begin), 0.0f);
  const float* const sf = scan_->plane(FrameSG::kF);
  const float* const s_o = scan_->plane(FrameSG::kO);
  const float* const sw = scan_->plane(FrameSG::kOmega);
  const float* const s_empty = scan_->plane(FrameSG::kEmpty);
  for (std::size_t c = begin / kFusionChunkCells; c <= (end - 1) / kFusionChunkCells && c < marks_.size(); ++c)
    for (const Mark& m : marks_[c])
    {
      if (m.to < begin || m.to >= end) continue;
      const std::size_t k = m.to - begin;
      const float occupied = s_o[m.from];
      if (!(occupied > o[k])) continue;
      if (points_)
      {
        // Point occupancy: the window cell under the return takes its scan cell's occupied mass.
        f[k] = 0.0f;
        o[k] = occupied;
        omega[k] = 1.0f - occupied;
      }
      else
      {
        // Forward pass: the window cell under an occupied scan cell's centre takes that cell.
        f[k] = sf[m.from];
        o[k] = occupied;
        omega[k] = sw[m.from];
        if (empty) empty[k] = s_empty[m.from];
      }
    }
  if (clearance_) clearFree(near_.data() + begin, end - begin, f, omega);
}

void projectScan(const ScanMassGrid& scan, const Pose2& pose, const GridGeometry& window, ScanMassGrid& out)
{
  projectScan(scan, pose, window, out, nullptr, 0);
}

void projectScan(const ScanMassGrid& scan, const Pose2& pose, const GridGeometry& window, ScanMassGrid& out,
                 const ObstaclePoints* obstacles, int clearance_cells, const Parallel* parallel)
{
  const Parallel& par = orSerial(parallel);
  const GridGeometry& had = out.geometry();
  if (had != window && had.width == window.width && had.height == window.height &&
      had.resolution == window.resolution && out.stride() > 0)
    out.setOrigin(window.origin_x, window.origin_y);  // every plane of every cell is written below
  else if (had != window)
    out.reset(window);
  thread_local ScanProjection calling_thread_projection;  // its buffers, kept from call to call
  ScanProjection& projection = calling_thread_projection;  // the workers fill the caller's (not their own)
  projection.plan(scan, pose, window, obstacles, clearance_cells, par);
  const std::size_t n = window.numCells();
  par.forChunks(chunkCount(n, kFusionChunkCells), [&](std::size_t c) {
    const std::size_t b = c * kFusionChunkCells, e = std::min(n, b + kFusionChunkCells);
    projection.fill(b, e, out.plane(FrameSG::kF) + b, out.plane(FrameSG::kO) + b, out.plane(FrameSG::kOmega) + b,
                    out.plane(FrameSG::kEmpty) + b);
  });
}

}  // namespace core
}  // namespace map_aided_fusion

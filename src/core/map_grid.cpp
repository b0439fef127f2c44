#include "map_aided_fusion/core/map_grid.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <stdexcept>

#include "map_aided_fusion/core/parameters.hpp"
#include "map_aided_fusion/core/prior_uncertainty.hpp"
#include "cell_kernels.hpp"

namespace map_aided_fusion {
namespace core {

namespace {

/// Largest window side, in cells (a 8192 × 8192 MapGrid already needs 8.6 GB).
constexpr int kMaxWindowCells = 8192;
constexpr std::size_t kCellChunk = 16384;      // cells per chunk of the per-cell passes (whole MapGrid blocks)
static_assert(kCellChunk % MapMassGrid::kBlockCells == 0, "chunks start on a block");
constexpr std::size_t kPriorRows = 32;         // rows per chunk of the prior window's copy
constexpr std::size_t kSpreadChunk = 256;      // cells per chunk of motion spreading's cell pass
constexpr std::size_t kSpreadAhead = 4;        // cells ahead whose blocks that pass prefetches
constexpr std::size_t kFloatsPerLine = 16;     // floats per cache line
constexpr std::size_t kShiftBandRows = 32;     // least window rows per band of a shift (moved in parallel)
constexpr std::size_t kShiftEdgeRatio = 8;     // a shift's bands hold at least this many times |dy| rows
/// Bounds of memory_budget_mb, MiB.
constexpr double kMinBudgetMb = 1.0;
constexpr double kMaxBudgetMb = 1048576.0;
constexpr double kBytesPerMb = 1048576.0;
/// Upper bound of the object shape limits (m).
constexpr double kMaxObjectExtent = 1000.0;
/// Largest obstacle_clearance, m.
constexpr double kMaxObstacleClearance = 5.0;

double secondsSince(std::chrono::steady_clock::time_point t0)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// The window origin (multiple of the resolution) that centres a window of @p g's size on @p p.
Point2 snappedOrigin(const GridGeometry& g, Point2 p)
{
  return Point2{ std::round((p.x - 0.5 * g.sizeX()) / g.resolution) * g.resolution,
                 std::round((p.y - 0.5 * g.sizeY()) / g.resolution) * g.resolution };
}

/// The 8-connected region of @p start (which @p member must accept) among the cells @p member accepts, depth first,
/// into @p region; its cells are marked in @p seen.
template <class Member>
void growRegion(const GridGeometry& g, std::size_t start, Member&& member, std::vector<std::uint8_t>& seen,
                std::vector<std::size_t>& stack, std::vector<std::size_t>& region)
{
  region.clear();
  stack.assign(1, start);
  seen[start] = 1;
  while (!stack.empty())
  {
    const std::size_t i = stack.back();
    stack.pop_back();
    region.push_back(i);
    const CellIndex c = g.cellOf(i);
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx)
      {
        const CellIndex nb{ c.x + dx, c.y + dy };
        if (!g.contains(nb)) continue;
        const std::size_t j = g.index(nb);
        if (!seen[j] && member(j))
        {
          seen[j] = 1;
          stack.push_back(j);
        }
      }
  }
}

}  // namespace

void MapGridParams::validate() const
{
  requirePositive("resolution", resolution);
  requirePositive("size_x", size_x);
  requirePositive("size_y", size_y);
  if (size_x / resolution > kMaxWindowCells)
    throw ParameterError("size_x", "more than " + std::to_string(kMaxWindowCells) + " cells at this resolution");
  if (size_y / resolution > kMaxWindowCells)
    throw ParameterError("size_y", "more than " + std::to_string(kMaxWindowCells) + " cells at this resolution");
  if (std::lround(size_x / resolution) < 1) throw ParameterError("size_x", "smaller than one cell");
  if (std::lround(size_y / resolution) < 1) throw ParameterError("size_y", "smaller than one cell");
  requireInRange("memory_budget_mb", memory_budget_mb, kMinBudgetMb, kMaxBudgetMb);
  const double needed = bytesNeeded();
  if (needed > memory_budget_mb * kBytesPerMb)
    throw ParameterError("size_x", "a window of " + std::to_string(std::lround(size_x / resolution)) + " x " +
                                       std::to_string(std::lround(size_y / resolution)) + " cells needs " +
                                       std::to_string(static_cast<long long>(needed)) + " bytes (" +
                                       std::to_string(bytesPerCell()) + " per cell), more than memory_budget_mb = " +
                                       std::to_string(memory_budget_mb) + " MiB; reduce size_x/size_y, raise "
                                       "resolution or raise memory_budget_mb");
  requireInRange("recentre_distance", recentre_distance, 0.0, 0.5 * std::min(size_x, size_y));
  requireUnit("decision_threshold", decision_threshold);
  requireInRange("obstacle_clearance", obstacle_clearance, 0.0, kMaxObstacleClearance);
  requireUnit("motion_share", motion_share);
  requireUnit("motion_margin", motion_margin);
  requireUnit("map_conflict_gain", map_conflict_gain);
  requireInRange("position_sigma", position_sigma, 0.0, kMaxPositionSigma);
  validateThreads("threads", threads);
  if (motion_max_cells < 1) throw ParameterError("motion_max_cells", "must be at least 1");
  if (min_object_cells < 1) throw ParameterError("min_object_cells", "must be at least 1");
  requireInRange("max_object_length", max_object_length, std::numeric_limits<double>::min(), kMaxObjectExtent);
  requireInRange("max_object_area", max_object_area, std::numeric_limits<double>::min(),
                 kMaxObjectExtent * kMaxObjectExtent);
  requireInRange("thin_structure_width", thin_structure_width, 0.0, kMaxObjectExtent);
  requireInRange("thin_structure_length", thin_structure_length, std::numeric_limits<double>::min(), kMaxObjectExtent);
  fusion.validate();
}

std::size_t MapGridParams::bytesPerCell()
{
  const std::size_t planes = (MapMassGrid::kNumPlanes + 1)  // the stored masses and ζ
                             + FrameMG::kSize              // BetP
                             + 4                           // the prior window (building, road, other, wall)
                             + 1                           // the map doubt η
                             + 4;                          // skip_unchanged: the prior each stable block kept
  constexpr std::size_t kProjectionMasks = 3;              // ScanProjection: occupied, near by row, near
  constexpr std::size_t kStableFlag = 1;                   // skip_unchanged: one flag per block, counted per cell
  return planes * sizeof(float) + sizeof(std::int8_t) /* the decision */ + kProjectionMasks + kStableFlag;
}

double MapGridParams::bytesNeeded() const
{
  return std::round(size_x / resolution) * std::round(size_y / resolution) * static_cast<double>(bytesPerCell());
}

namespace {

/// The step map_conflict on the cells [i0, i1) of @p prior (see applyMapConflict).
void conflictCells(PriorWindow& prior, const float* __restrict sf, const float* __restrict so, float g,
                   float* __restrict eta_out, std::size_t i0, std::size_t i1)
{
  float* __restrict b = prior.building.data();
  float* __restrict r = prior.road.data();
  float* __restrict t = prior.other.data();
  float* __restrict wall = prior.wall.data();
  for (std::size_t i = i0; i < i1; ++i) kernels::mapConflict(sf[i], so[i], g, eta_out[i], b[i], r[i], t[i], wall[i]);
}

void extractPriorRows(const PriorWindow& prior, const GridGeometry& window, PriorWindow& out,
                      const MapConflict* conflict, const Parallel* parallel)
{
  const Parallel& par = orSerial(parallel);
  if (out.building.size() != window.numCells() || out.wall.size() != window.numCells())
    out.reset(window);
  if (conflict && conflict->doubt->size() != window.numCells()) conflict->doubt->assign(window.numCells(), 0.0f);
  const float* const csf = conflict ? conflict->scan->plane(FrameSG::kF) : nullptr;
  const float* const cso = conflict ? conflict->scan->plane(FrameSG::kO) : nullptr;
  float* const ceta = conflict ? conflict->doubt->data() : nullptr;
  const float cgain = conflict ? static_cast<float>(conflict->gain) : 0.0f;
  out.geometry = window;
  std::vector<int> column(static_cast<std::size_t>(window.width));
  int first = -1, last = -1;  // window columns inside the prior
  bool contiguous = true;     // ... mapped to consecutive prior columns (aligned lattices): rows copy as blocks
  for (int x = 0; x < window.width; ++x)
  {
    const double wx = window.cellCentre(CellIndex{ x, 0 }).x;
    const double fx = std::floor((wx - prior.geometry.origin_x) / prior.geometry.resolution);
    const int px = fx >= 0 && fx < prior.geometry.width ? static_cast<int>(fx) : -1;
    column[static_cast<std::size_t>(x)] = px;
    if (px < 0) continue;
    if (first < 0) first = x;
    contiguous = contiguous && (last < 0 || (last == x - 1 && px == column[static_cast<std::size_t>(last)] + 1));
    last = x;
  }
  const std::size_t ww = static_cast<std::size_t>(window.width);
  float* const dst[4] = { out.building.data(), out.road.data(), out.other.data(), out.wall.data() };
  const float* const src[4] = { prior.building.data(), prior.road.data(), prior.other.data(), prior.wall.data() };
  par.forRange(static_cast<std::size_t>(window.height), kPriorRows, [&](std::size_t y0, std::size_t y1) {
    for (std::size_t y = y0; y < y1; ++y)
    {
      const double wy = window.cellCentre(CellIndex{ 0, static_cast<int>(y) }).y;
      const double fy = std::floor((wy - prior.geometry.origin_y) / prior.geometry.resolution);
      const bool row_inside = fy >= 0 && fy < prior.geometry.height && first >= 0;
      const std::size_t row = y * ww;
      for (int k = 0; k < 4; ++k)
      {
        float* d = dst[k] + row;
        if (!row_inside)
        {
          std::fill(d, d + ww, 0.0f);
          continue;
        }
        const float* s = src[k] + prior.geometry.index(0, static_cast<int>(fy));
        if (contiguous)
        {
          std::fill(d, d + first, 0.0f);
          std::copy(s + column[static_cast<std::size_t>(first)], s + column[static_cast<std::size_t>(last)] + 1, d + first);
          std::fill(d + last + 1, d + ww, 0.0f);
          continue;
        }
        for (std::size_t x = 0; x < ww; ++x) d[x] = column[x] < 0 ? 0.0f : s[column[x]];
      }
      if (conflict) conflictCells(out, csf, cso, cgain, ceta, row, row + ww);
    }
  });
}

}  // namespace

void extractPriorWindow(const PriorWindow& prior, const GridGeometry& window, PriorWindow& out,
                        const Parallel* parallel)
{
  extractPriorRows(prior, window, out, nullptr, parallel);
}

void extractPriorWindow(const PriorWindow& prior, const GridGeometry& window, PriorWindow& out,
                        const MapConflict& conflict, const Parallel* parallel)
{
  if (!conflict.scan || !conflict.doubt || conflict.scan->geometry().width != window.width ||
      conflict.scan->geometry().height != window.height)
    throw std::invalid_argument("extractPriorWindow: the map conflict needs a scan and a doubt of the window's size");
  extractPriorRows(prior, window, out, &conflict, parallel);
}

namespace {

/// m(Ω) of the cells [i0, i1) of @p grid (@p i0 starts a block), into @p out[0, i1 − i0).
void gatherOmega(const MapMassGrid& grid, std::size_t i0, std::size_t i1, float* __restrict out)
{
  constexpr std::size_t kB = MapMassGrid::kBlockCells;
  const float* __restrict omega = grid.planes() + grid.stride() * MapMassGrid::slot(FrameMG::kOmega);
  std::size_t i = i0;
  for (; i + kB <= i1; i += kB) std::memcpy(out + (i - i0), omega + MapMassGrid::blockOffset(i), kB * sizeof(float));
  for (; i < i1; ++i) out[i - i0] = omega[MapMassGrid::blockOffset(i)];
}

/// The calling thread's buffer for gatherOmega() over one chunk of kCellChunk cells.
float* omegaBuffer()
{
  thread_local AlignedVector<float> buffer(kCellChunk);
  return buffer.data();
}

/// decide() on the cells [i0, i1), whose m(Ω) are @p omega[0, i1 − i0).
void decideCells(const float* __restrict omega, const float* const* p, const kernels::DecisionRule& rule,
                 std::int8_t* __restrict d, std::size_t i0, std::size_t i1)
{
  static_assert(FrameMG::kSize == 5, "one pointer per element of Ω");
  kernels::forEachCell(i1 - i0, [&](auto lane, std::size_t k) {
    using T = decltype(lane);
    const std::size_t i = i0 + k;
    const T q[FrameMG::kSize] = { kernels::load<T>(p[0] + i), kernels::load<T>(p[1] + i), kernels::load<T>(p[2] + i),
                                  kernels::load<T>(p[3] + i), kernels::load<T>(p[4] + i) };
    kernels::storeClass(d + i, kernels::decideCell(q, kernels::load<T>(omega + k), rule));
  });
}

kernels::DecisionRule decisionRule(double threshold, double motion_margin)
{
  return kernels::DecisionRule{ static_cast<float>(threshold), motion_margin > 0.0, static_cast<float>(motion_margin) };
}

/// decide() again on the listed cells only (those motion spreading changed).
void redecide(const MapMassGrid& grid, const PignisticPlanes& betp, const MapGridParams& params,
              const std::vector<std::size_t>& cells, std::vector<std::int8_t>& out)
{
  const kernels::DecisionRule rule = decisionRule(params.decision_threshold, params.motion_margin);
  const int omega = MapMassGrid::slot(FrameMG::kOmega);
  for (const std::size_t i : cells)
  {
    const float q[FrameMG::kSize] = { betp[0][i], betp[1][i], betp[2][i], betp[3][i], betp[4][i] };
    kernels::storeClass(out.data() + i, kernels::decideCell(q, grid.value(omega, i), rule));
  }
}

}  // namespace

void decide(const MapMassGrid& grid, const PignisticPlanes& betp, double threshold, std::vector<std::int8_t>& out,
            const Parallel* parallel)
{
  MapGridParams params;
  params.decision_threshold = threshold;
  params.motion_margin = 0.0;
  decide(grid, betp, params, out, parallel);
}

void decide(const MapMassGrid& grid, const PignisticPlanes& betp, const MapGridParams& params,
            std::vector<std::int8_t>& out, const Parallel* parallel)
{
  const std::size_t n = grid.numCells();
  out.resize(n);
  const float* p[FrameMG::kSize] = { betp[0].data(), betp[1].data(), betp[2].data(), betp[3].data(), betp[4].data() };
  const kernels::DecisionRule rule = decisionRule(params.decision_threshold, params.motion_margin);
  std::int8_t* const d = out.data();
  orSerial(parallel).forRange(n, kCellChunk, [&](std::size_t i0, std::size_t i1) {
    float* const omega = omegaBuffer();
    gatherOmega(grid, i0, i1, omega);
    decideCells(omega, p, rule, d, i0, i1);
  });
}

namespace {

/// spreadMotion() with the scan's occupied cells as @p occupied (non-zero where m(O) > 0), also giving the cells it
/// changed (the calling thread's buffer, valid until its next call). With @p found_seeds (the fused step's,
/// StepDecisions::motion_seeds, per chunk in index order) the seeds are not looked for again.
std::size_t spreadMotionCells(MapMassGrid& grid, PignisticPlanes& betp, const std::uint8_t* occupied, double share,
                              int max_cells, double threshold, double margin, const Parallel* parallel,
                              const std::vector<std::vector<std::size_t>>* found_seeds,
                              const std::vector<std::size_t>*& changed)
{
  thread_local std::vector<std::size_t> calling_thread_cells;
  std::vector<std::size_t>& cells = calling_thread_cells;
  cells.clear();
  changed = &cells;
  if (share <= 0.0) return 0;
  const GridGeometry& g = grid.geometry();
  const std::size_t n = g.numCells();
  const float* ps = betp[FrameMG::kSize - 2].data();
  const float* pv = betp[FrameMG::kSize - 1].data();
  const float t = static_cast<float>(threshold);
  const float m = static_cast<float>(margin);
  auto is_moving = [&](std::size_t i) { return kernels::isMoving(pv[i], ps[i], t, m) != 0; };
  static_assert(kCellChunk == kFusionChunkCells, "the step's seed lists are the chunks of this pass");
  // A region without a moving cell is left alone: only the occupied moving cells seed one. They are found by fixed
  // chunks in parallel and taken in index order, so the regions (disjoint) are the same for any thread count.
  // The calling thread's buffers, kept from scan to scan (no allocation per scan). References to them are what the
  // lambdas capture: a thread_local named inside a lambda would be the worker's own.
  thread_local std::vector<std::vector<std::size_t>> calling_thread_seeds;
  thread_local std::vector<std::uint8_t> calling_thread_seen;
  thread_local std::vector<std::size_t> calling_thread_stack, calling_thread_region, calling_thread_visited;
  std::vector<std::vector<std::size_t>>& seeds = calling_thread_seeds;
  std::vector<std::uint8_t>& seen = calling_thread_seen;
  std::vector<std::size_t>& stack = calling_thread_stack;
  std::vector<std::size_t>& region = calling_thread_region;
  std::vector<std::size_t>& visited = calling_thread_visited;  // the cells of every region grown last time
  const std::size_t chunks = chunkCount(n, kCellChunk);
  if (!found_seeds)
  {
    if (seeds.size() < chunks) seeds.resize(chunks);
    orSerial(parallel).forChunks(chunks, [&](std::size_t c) {
      seeds[c].clear();
      for (std::size_t i = c * kCellChunk, end = std::min(n, i + kCellChunk); i < end; ++i)
        if (kernels::isMovingSeed(static_cast<float>(occupied[i]), pv[i], ps[i], t, m)) seeds[c].push_back(i);
    });
  }
  const std::vector<std::vector<std::size_t>>& starts = found_seeds ? *found_seeds : seeds;
  // Only the cells marked last time are cleared (a window of cells otherwise).
  if (seen.size() == n)
    for (const std::size_t i : visited) seen[i] = 0;
  else
    seen.assign(n, 0);
  visited.clear();
  std::size_t spread = 0;
  for (std::size_t c = 0; c < chunks && c < starts.size(); ++c)
    for (const std::size_t start : starts[c])
    {
      if (seen[start]) continue;
      growRegion(g, start, [occupied](std::size_t j) { return occupied[j] != 0; }, seen, stack, region);
      visited.insert(visited.end(), region.begin(), region.end());
      std::size_t moving = 0;
      for (const std::size_t i : region) moving += is_moving(i);
      if (static_cast<int>(region.size()) > max_cells ||
          static_cast<double>(moving) < share * static_cast<double>(region.size()))
        continue;
      ++spread;
      cells.insert(cells.end(), region.begin(), region.end());
    }
  // The regions are disjoint and each cell's new masses depend on that cell alone: fixed chunks of the cells in
  // parallel, each cell's planes asked for a few cells ahead (they are scattered over the window).
  float* const base = grid.planes();
  orSerial(parallel).forRange(cells.size(), kSpreadChunk, [&](std::size_t k0, std::size_t k1) {
    for (std::size_t k = k0; k < k1; ++k)
    {
      if (k + kSpreadAhead < k1)
      {
        const std::size_t ahead = cells[k + kSpreadAhead];
        const float* block = base + MapMassGrid::blockOffset(ahead - ahead % MapMassGrid::kBlockCells);
        for (std::size_t f = 0; f < MapMassGrid::kBlockFloats; f += kFloatsPerLine) __builtin_prefetch(block + f, 1);
        for (int e = 0; e < FrameMG::kSize; ++e) __builtin_prefetch(betp.p[e].data() + ahead, 1);
      }
      const std::size_t i = cells[k];
      float mass[kernels::kSubsets];
      kernels::loadMasses(base, i, mass);
      for (int a = 0; a < kernels::kSubsets; ++a)
        if ((a & FrameMG::kV) && a != FrameMG::kV && !(a & FrameMG::kF))
        {
          mass[FrameMG::kV] += mass[a];
          mass[a] = 0.0f;
        }
      kernels::renormalise(mass);
      kernels::storeMasses(base, i, mass);
      float p[FrameMG::kSize];
      kernels::pignistic(mass, p);
      for (int e = 0; e < FrameMG::kSize; ++e) betp.p[e][i] = p[e];
    }
  });
  return spread;
}

}  // namespace

std::size_t spreadMotion(MapMassGrid& grid, PignisticPlanes& betp, const ScanMassGrid& scan, double share,
                         int max_cells, double threshold, double margin, const Parallel* parallel)
{
  const std::size_t n = scan.numCells();
  if (scan.geometry() != grid.geometry()) throw std::invalid_argument("spreadMotion: scan grid and map grid differ");
  std::vector<std::uint8_t> occupied(n);
  const float* const so = scan.plane(FrameSG::kO);
  for (std::size_t i = 0; i < n; ++i) occupied[i] = so[i] > 0.0f;
  const std::vector<std::size_t>* changed = nullptr;
  return spreadMotionCells(grid, betp, occupied.data(), share, max_cells, threshold, margin, parallel, nullptr,
                           changed);
}

std::vector<GridObject> extractObjects(const GridGeometry& g, const std::vector<std::int8_t>& decision,
                                       const PignisticPlanes& betp, const MapGridParams& params)
{
  const int min_cells = params.min_object_cells;
  std::vector<GridObject> objects;
  std::vector<std::uint8_t> seen(decision.size(), 0);
  std::vector<std::size_t> stack, region;
  for (std::size_t start = 0; start < decision.size(); ++start)
  {
    const auto cls = static_cast<CellClass>(decision[start]);
    if (seen[start] || (cls != CellClass::kMoving && cls != CellClass::kStopped)) continue;
    growRegion(g, start, [&](std::size_t j) { return decision[j] == decision[start]; }, seen, stack, region);
    if (static_cast<int>(region.size()) < min_cells) continue;
    GridObject o;
    o.cell_class = cls;
    o.cells = static_cast<int>(region.size());
    const int element = static_cast<int>(cls);
    double sx = 0, sy = 0, sb = 0;
    for (std::size_t i : region)
    {
      const Point2 p = g.cellCentre(g.cellOf(i));
      sx += p.x;
      sy += p.y;
      sb += betp[element][i];
    }
    const double n = static_cast<double>(region.size());
    o.centroid = Point2{ sx / n, sy / n };
    o.mean_betp = sb / n;
    double cxx = 0, cyy = 0, cxy = 0;
    for (std::size_t i : region)
    {
      const Point2 p = g.cellCentre(g.cellOf(i));
      const double dx = p.x - o.centroid.x, dy = p.y - o.centroid.y;
      cxx += dx * dx;
      cyy += dy * dy;
      cxy += dx * dy;
    }
    o.yaw = 0.5 * std::atan2(2.0 * cxy, cxx - cyy);
    const double ux = std::cos(o.yaw), uy = std::sin(o.yaw);
    double lo_u = std::numeric_limits<double>::max(), hi_u = -lo_u, lo_v = lo_u, hi_v = -lo_u;
    for (std::size_t i : region)
    {
      const Point2 p = g.cellCentre(g.cellOf(i));
      const double dx = p.x - o.centroid.x, dy = p.y - o.centroid.y;
      const double u = dx * ux + dy * uy, v = -dx * uy + dy * ux;
      lo_u = std::min(lo_u, u);
      hi_u = std::max(hi_u, u);
      lo_v = std::min(lo_v, v);
      hi_v = std::max(hi_v, v);
    }
    o.length = hi_u - lo_u + g.resolution;
    o.width = hi_v - lo_v + g.resolution;
    const double area = n * g.resolution * g.resolution;
    if (o.length > params.max_object_length || area > params.max_object_area) continue;
    if (cls == CellClass::kStopped && o.width <= params.thin_structure_width && o.length > params.thin_structure_length)
      continue;
    objects.push_back(o);
  }
  return objects;
}

MapGrid::MapGrid(const MapGridParams& params)
{
  setParams(params);
}

void MapGrid::setParams(const MapGridParams& params)
{
  params.validate();
  const GridGeometry g = GridGeometry::centred(params.size_x, params.size_y, params.resolution);
  const bool realloc =
      grid_.geometry().width != g.width || grid_.geometry().height != g.height || grid_.geometry().resolution != g.resolution;
  if (!parallel_ || parallel_->threads() != resolveThreads(params.threads))
    parallel_ = std::make_shared<const Parallel>(params.threads);
  params_ = params;
  forgetStable();
  if (realloc)
  {
    grid_.reset(g);
    map_doubt_.assign(g.numCells(), 0.0f);
    pignisticGrid(grid_, betp_);
    scans_ = 0;
  }
  decide(grid_, betp_, params_, decision_, parallel_.get());
}

void MapGrid::reset()
{
  forgetStable();
  grid_.fillVacuous();
  std::fill(map_doubt_.begin(), map_doubt_.end(), 0.0f);
  pignisticGrid(grid_, betp_);
  decide(grid_, betp_, params_, decision_, parallel_.get());
  scans_ = 0;
  last_stamp_ = 0.0;
}

namespace {

/// Moves one plane of a @p g-sized window by whole cells (see MapGrid::shift), filling vacated cells with @p fill.
template <typename T>
void shiftPlane(T* p, const GridGeometry& g, int dx, int dy, T fill)
{
  const std::size_t w = static_cast<std::size_t>(g.width);
  const int x0 = std::max(0, -dx), x1 = std::min(g.width, g.width - dx);
  const std::size_t count = static_cast<std::size_t>(x1 - x0);
  const bool forward = dy > 0 || (dy == 0 && dx > 0);
  for (int k = 0; k < g.height; ++k)
  {
    const int y = forward ? k : g.height - 1 - k;
    T* row = p + static_cast<std::size_t>(y) * w;
    const int sy = y + dy;
    if (sy < 0 || sy >= g.height)
    {
      std::fill(row, row + w, fill);
      continue;
    }
    const T* src = p + static_cast<std::size_t>(sy) * w;
    std::memmove(row + x0, src + x0 + dx, count * sizeof(T));
    std::fill(row, row + x0, fill);
    std::fill(row + x1, row + w, fill);
  }
}

/// shiftPlane() of the cells of the blocks @p stable flags after the move (MapMassGrid::kBlockCells cells each, all
/// of whose sources lie inside the window), run by run of flagged blocks: the values a skipped block keeps. The other
/// cells are left as they are, for the next step to write.
template <typename T>
void shiftStableBlocks(T* p, const GridGeometry& g, int dx, int dy, const std::uint8_t* stable)
{
  constexpr std::size_t kB = MapMassGrid::kBlockCells;
  const std::size_t w = static_cast<std::size_t>(g.width), blocks = w / kB;
  const bool forward = dy > 0 || (dy == 0 && dx > 0);
  const bool backward_in_row = dy == 0 && dx < 0;  // the row reads itself: right to left
  const auto move = [&](T* row, std::size_t sy, std::size_t b, std::size_t e) {
    const T* const src = p + sy * w + static_cast<std::ptrdiff_t>(b * kB) + dx;
    std::memmove(row + b * kB, src, (e - b) * kB * sizeof(T));
  };
  for (int k = 0; k < g.height; ++k)
  {
    const int y = forward ? k : g.height - 1 - k;
    const std::uint8_t* const f = stable + static_cast<std::size_t>(y) * blocks;
    T* const row = p + static_cast<std::size_t>(y) * w;
    const auto sy = static_cast<std::size_t>(y + dy);  // inside wherever a block is flagged
    if (!backward_in_row)
    {
      for (std::size_t b = 0; b < blocks;)
      {
        if (!f[b])
        {
          ++b;
          continue;
        }
        std::size_t e = b + 1;
        while (e < blocks && f[e]) ++e;
        move(row, sy, b, e);
        b = e;
      }
      continue;
    }
    for (std::size_t e = blocks; e > 0;)
    {
      if (!f[e - 1])
      {
        --e;
        continue;
      }
      std::size_t b = e - 1;
      while (b > 0 && f[b - 1]) --b;
      move(row, sy, b, e);
      e = b;
    }
  }
}

/// The value a vacated cell takes in slot @p s (ζ: MapMassGrid::kNumPlanes): vacuous, ζ = 0.
float vacatedValue(int s) { return s == MapMassGrid::slot(FrameMG::kOmega) ? 1.0f : 0.0f; }

/// MapGrid::shift on any width, one cell after another: cell j takes cell j + dx + dy · width (linear in j), in the
/// order that reads every source before it is overwritten.
void shiftCells(MapMassGrid& grid, int dx, int dy)
{
  const GridGeometry& g = grid.geometry();
  const std::ptrdiff_t d = dx + static_cast<std::ptrdiff_t>(dy) * g.width;
  const std::ptrdiff_t n = static_cast<std::ptrdiff_t>(g.numCells());
  for (std::ptrdiff_t k = 0; k < n; ++k)
  {
    const std::ptrdiff_t j = d > 0 ? k : n - 1 - k;
    const int x = static_cast<int>(j % g.width) + dx, y = static_cast<int>(j / g.width) + dy;
    const bool inside = x >= 0 && x < g.width && y >= 0 && y < g.height;
    const auto dst = static_cast<std::size_t>(j);
    for (int s = 0; s <= MapMassGrid::kNumPlanes; ++s)
      grid.value(s, dst) = inside ? grid.value(s, static_cast<std::size_t>(j + d)) : vacatedValue(s);
  }
}

/// Rows of whole blocks in one pass: destination row y takes source row y + dy, its cells moved by dx through @p tmp
/// (per slot, the row between two rows of vacated values, so that eight cells move at a time). The rows are cut into
/// bands, moved in parallel: each band goes in the order that reads its own rows before it overwrites them, and the
/// (at most |dy|) source rows it reads from other bands are copied into @p edge first. Moving data only, bit-exact.
void shiftBlockRows(MapMassGrid& grid, int dx, int dy, const Parallel& par, AlignedVector<float>& edge)
{
  const GridGeometry& g = grid.geometry();
  constexpr std::size_t kB = MapMassGrid::kBlockCells;
  constexpr int kSlots = MapMassGrid::kNumPlanes + 1;
  const std::size_t w = static_cast<std::size_t>(g.width), h = static_cast<std::size_t>(g.height);
  const std::size_t row_floats = w / kB * MapMassGrid::kBlockFloats;
  const std::size_t reach = static_cast<std::size_t>(std::abs(dy));
  // Bands of at least kShiftEdgeRatio · |dy| rows: the edge rows stay a small share of the window.
  const std::size_t band_rows = std::max(kShiftBandRows, kShiftEdgeRatio * reach);
  const std::size_t bands = (h + band_rows - 1) / band_rows;
  const std::ptrdiff_t hh = static_cast<std::ptrdiff_t>(h);
  float* const data = grid.planes();
  auto band = [&](std::size_t k) {
    return std::pair{ static_cast<std::ptrdiff_t>(k * band_rows), static_cast<std::ptrdiff_t>(std::min(h, (k + 1) * band_rows)) };
  };
  // The source rows band k reads outside itself: [e0, e1), at most |dy| of them.
  auto outside = [&](std::size_t k) {
    const auto [y0, y1] = band(k);
    return dy > 0 ? std::pair{ std::max(y1, y0 + dy), std::min(hh, y1 + dy) }
                  : std::pair{ std::max<std::ptrdiff_t>(0, y0 + dy), std::min(y0, y1 + dy) };
  };
  // Saved before anything is written: another band overwrites them.
  if (reach > 0)
  {
    edge.resize(bands * reach * row_floats);
    par.forChunks(bands, [&](std::size_t k) {
      const auto [e0, e1] = outside(k);
      for (std::ptrdiff_t r = e0; r < e1; ++r)
        std::memcpy(edge.data() + (k * reach + static_cast<std::size_t>(r - e0)) * row_floats,
                    data + static_cast<std::size_t>(r) * row_floats, row_floats * sizeof(float));
    });
  }
  par.forChunks(bands, [&](std::size_t k) {
    thread_local std::vector<float> tmp;
    if (dx != 0)
    {
      tmp.resize(kSlots * 3 * w);
      for (int s = 0; s < kSlots; ++s)
      {
        std::fill_n(tmp.data() + s * 3 * w, w, vacatedValue(s));
        std::fill_n(tmp.data() + s * 3 * w + 2 * w, w, vacatedValue(s));
      }
    }
    const auto [y0, y1] = band(k);
    const std::ptrdiff_t e0 = reach > 0 ? outside(k).first : 0;
    for (std::ptrdiff_t n = 0; n < y1 - y0; ++n)
    {
      const std::ptrdiff_t y = dy >= 0 ? y0 + n : y1 - 1 - n;
      float* const row = data + static_cast<std::size_t>(y) * row_floats;
      const std::ptrdiff_t sy = y + dy;
      if (sy < 0 || sy >= hh)
      {
        for (std::size_t b = 0; b < w; b += kB)
          for (int s = 0; s < kSlots; ++s)
            std::fill_n(row + b / kB * MapMassGrid::kBlockFloats + s * kB, kB, vacatedValue(s));
        continue;
      }
      const float* const src = sy >= y0 && sy < y1
                                   ? data + static_cast<std::size_t>(sy) * row_floats
                                   : edge.data() + (k * reach + static_cast<std::size_t>(sy - e0)) * row_floats;
      if (dx == 0)
      {
        if (src != row) std::memcpy(row, src, row_floats * sizeof(float));
        continue;
      }
      for (std::size_t x = 0; x < w; x += kB)
        for (int s = 0; s < kSlots; ++s)
          std::memcpy(tmp.data() + s * 3 * w + w + x, src + x / kB * MapMassGrid::kBlockFloats + s * kB, kB * sizeof(float));
      for (std::size_t x = 0; x < w; x += kB)
        for (int s = 0; s < kSlots; ++s)
          std::memcpy(row + x / kB * MapMassGrid::kBlockFloats + s * kB,
                      tmp.data() + s * 3 * w + w + static_cast<std::ptrdiff_t>(x) + dx, kB * sizeof(float));
    }
  });
}

}  // namespace

void MapGrid::shiftStable(int dx, int dy)
{
  const GridGeometry& g = grid_.geometry();
  constexpr std::size_t kB = MapMassGrid::kBlockCells;
  const std::size_t n = g.numCells();
  const bool whole_rows = g.width % static_cast<int>(kB) == 0 && std::abs(dx) < g.width && std::abs(dy) < g.height;
  if (stable_.empty() || !whole_rows || kept_[0].size() != n || betp_.p[0].size() != n || decision_.size() != n)
  {
    forgetStable();  // BetP and the decisions stay where they were until the next step writes them
    return;
  }
  // A block stays stable when every one of its cells comes from a stable block: the flag holds cell by cell.
  const std::vector<std::uint8_t> was = stable_;
  const std::size_t w = static_cast<std::size_t>(g.width), blocks_per_row = w / kB;
  for (int y = 0; y < g.height; ++y)
  {
    const int sy = y + dy;
    for (std::size_t bx = 0; bx < blocks_per_row; ++bx)
    {
      const long x0 = static_cast<long>(bx * kB) + dx, x1 = x0 + static_cast<long>(kB) - 1;
      bool stable = sy >= 0 && sy < g.height && x0 >= 0 && x1 < g.width;
      if (stable)
      {
        const std::size_t row = static_cast<std::size_t>(sy) * w;
        stable = was[(row + static_cast<std::size_t>(x0)) / kB] && was[(row + static_cast<std::size_t>(x1)) / kB];
      }
      stable_[static_cast<std::size_t>(y) * blocks_per_row + bx] = stable;
    }
  }
  // What a skipped block keeps moves with it: its kept prior, BetP and decision. The next step computes every other
  // cell (those of blocks no longer stable, vacated cells) and writes its BetP and decision.
  constexpr int kPlanes = 4 + FrameMG::kSize;
  const std::uint8_t* const flags = stable_.data();
  parallel_->forChunks(kPlanes + 1, [&](std::size_t k) {
    if (k < 4)
      shiftStableBlocks(kept_[k].data(), g, dx, dy, flags);
    else if (k < kPlanes)
      shiftStableBlocks(betp_.p[k - 4].data(), g, dx, dy, flags);
    else
      shiftStableBlocks(decision_.data(), g, dx, dy, flags);
  });
}

void MapGrid::shift(int dx, int dy)
{
  if (dx == 0 && dy == 0) return;
  shiftStable(dx, dy);
  const GridGeometry g = grid_.geometry();
  grid_.setOrigin(g.origin_x + dx * g.resolution, g.origin_y + dy * g.resolution);
  if (std::abs(dx) >= g.width || std::abs(dy) >= g.height)
  {
    grid_.fillVacuous();
    std::fill(map_doubt_.begin(), map_doubt_.end(), 0.0f);
    return;
  }
  if (g.width % static_cast<int>(MapMassGrid::kBlockCells) == 0)
    shiftBlockRows(grid_, dx, dy, *parallel_, shift_edge_);
  else
    shiftCells(grid_, dx, dy);
  if (map_doubt_.size() == g.numCells()) shiftPlane(map_doubt_.data(), g, dx, dy, 0.0f);
}

void navigableLayer(const std::vector<std::int8_t>& decision, const PriorWindow& prior, std::vector<std::int8_t>& out)
{
  constexpr std::int8_t kNavigableRoad = 0, kNotNavigable = 100, kUnknownSpace = -1;
  out.resize(decision.size());
  const bool has_prior = prior.road.size() == decision.size();
  for (std::size_t i = 0; i < decision.size(); ++i)
  {
    const auto d = static_cast<CellClass>(decision[i]);
    if (d == CellClass::kUnknown)
      out[i] = kUnknownSpace;
    else if (d != CellClass::kFree)
      out[i] = kNotNavigable;
    else
      out[i] = has_prior && prior.road[i] > prior.other[i] + prior.building[i] + prior.wall[i] ? kNavigableRoad
                                                                                                : kNavigableOffRoad;
  }
}

void applyMapConflict(PriorWindow& prior, const ScanMassGrid& scan, double gain, AlignedVector<float>& doubt,
                      const Parallel* parallel)
{
  const Parallel& par = orSerial(parallel);
  const std::size_t n = prior.geometry.numCells();
  if (doubt.size() != n) doubt.assign(n, 0.0f);
  const float g = static_cast<float>(gain);
  const float* sf = scan.plane(FrameSG::kF);
  const float* so = scan.plane(FrameSG::kO);
  float* const eta_out = doubt.data();
  par.forRange(n, kCellChunk,
               [&](std::size_t i0, std::size_t i1) { conflictCells(prior, sf, so, g, eta_out, i0, i1); });
}

namespace {

/// The column (or row) of @p prior's lattice under the centre of cell @p k of a window starting at @p window_origin.
long priorLine(double window_origin, double window_res, int k, double prior_origin, double prior_res)
{
  const double c = window_origin + (k + 0.5) * window_res;
  return static_cast<long>(std::floor((c - prior_origin) / prior_res));
}

}  // namespace

std::optional<std::size_t> alignedPriorStart(const GridGeometry& prior, const GridGeometry& window)
{
  if (window.width <= 0 || window.height <= 0) return std::nullopt;
  // extractPriorWindow's nearest-neighbour sampling, cell by cell: every column and row must map to consecutive ones.
  auto consecutive = [](double wo, double wr, int n, double po, double pr, int pn) -> std::optional<long> {
    const long first = priorLine(wo, wr, 0, po, pr);
    if (first < 0 || first + n > pn) return std::nullopt;
    for (int k = 1; k < n; ++k)
      if (priorLine(wo, wr, k, po, pr) != first + k) return std::nullopt;
    return first;
  };
  const auto x0 = consecutive(window.origin_x, window.resolution, window.width, prior.origin_x, prior.resolution,
                              prior.width);
  const auto y0 = x0 ? consecutive(window.origin_y, window.resolution, window.height, prior.origin_y, prior.resolution,
                                   prior.height)
                     : std::nullopt;
  if (!y0) return std::nullopt;
  return static_cast<std::size_t>(*y0) * static_cast<std::size_t>(prior.width) + static_cast<std::size_t>(*x0);
}

void MapGrid::priorWindow(const PriorWindow* prior, PriorWindow& out) const
{
  const GridGeometry& g = grid_.geometry();
  if (!prior)
  {
    out.reset(g);
    return;
  }
  extractPriorWindow(*prior, g, out, parallel_.get());
  if (params_.map_conflict_gain <= 0.0 || map_doubt_.size() != g.numCells()) return;
  const float* const eta = map_doubt_.data();
  float* const planes[4] = { out.building.data(), out.road.data(), out.other.data(), out.wall.data() };
  parallel_->forRange(g.numCells(), kCellChunk, [&](std::size_t i0, std::size_t i1) {
    for (float* p : planes)
      for (std::size_t i = i0; i < i1; ++i) p[i] *= 1.0f - eta[i];
  });
}

void MapGrid::recentre(Point2 p)
{
  const GridGeometry& g = grid_.geometry();
  const Point2 target = snappedOrigin(g, p);
  const int dx = static_cast<int>(std::lround((target.x - g.origin_x) / g.resolution));
  const int dy = static_cast<int>(std::lround((target.y - g.origin_y) / g.resolution));
  shift(dx, dy);
}

bool MapGrid::follow(Point2 p)
{
  if (scans_ == 0) return false;
  const GridGeometry& g = grid_.geometry();
  const double cx = g.origin_x + 0.5 * g.sizeX(), cy = g.origin_y + 0.5 * g.sizeY();
  if (std::max(std::abs(p.x - cx), std::abs(p.y - cy)) <= params_.recentre_distance) return false;
  const double x0 = g.origin_x, y0 = g.origin_y;
  recentre(p);
  return grid_.geometry().origin_x != x0 || grid_.geometry().origin_y != y0;
}

FusionStepStats MapGrid::update(const ScanMassGrid& scan, const Pose2& pose, double stamp, const PriorWindow* prior,
                                StageTimes* times, const ObstaclePoints* obstacles)
{
  StageTimes t;
  auto t0 = std::chrono::steady_clock::now();
  if (scans_ == 0)
  {
    forgetStable();
    grid_.fillVacuous();
    const Point2 o = snappedOrigin(grid_.geometry(), Point2{ pose.x, pose.y });
    grid_.setOrigin(o.x, o.y);
  }
  else
    follow(Point2{ pose.x, pose.y });
  t.shift = secondsSince(t0);

  t0 = std::chrono::steady_clock::now();
  const int clearance = static_cast<int>(std::lround(params_.obstacle_clearance / params_.resolution));
  projection_.plan(scan, pose, grid_.geometry(), params_.point_occupancy ? obstacles : nullptr, clearance, *parallel_);
  t.project_scan = secondsSince(t0);

  t0 = std::chrono::steady_clock::now();
  const GridGeometry& window = grid_.geometry();
  StepPrior step_prior;
  if (prior)
  {
    // The step reads the prior's own rows when the window lies inside it on its lattice; otherwise its window is
    // sampled first (the same values: a nearest-neighbour copy of the same cells).
    const std::optional<std::size_t> at = alignedPriorStart(prior->geometry, window);
    if (at && (prior->geometry.width == window.width || window.width % MapMassGrid::kBlockCells == 0))
    {
      step_prior.grid = prior;
      step_prior.first = *at;
      step_prior.row_stride = static_cast<std::size_t>(prior->geometry.width);
    }
    else
    {
      extractPriorWindow(*prior, window, prior_window_, parallel_.get());
      step_prior.grid = &prior_window_;
      step_prior.row_stride = static_cast<std::size_t>(window.width);
    }
    if (params_.map_conflict_gain > 0.0)
    {
      step_prior.doubt = map_doubt_.data();
      step_prior.conflict_gain = params_.map_conflict_gain;
    }
  }
  t.prior_window = secondsSince(t0);

  t0 = std::chrono::steady_clock::now();
  FusionParams fp = params_.fusion;
  if (params_.rates_per_second && scans_ > 0) fp.discount = fp.discount.compounded(std::max(0.0, stamp - last_stamp_));
  FusionStepStats stats;
  StepDecisions decisions;
  decisions.out = &decision_;
  decisions.threshold = params_.decision_threshold;
  decisions.motion_margin = params_.motion_margin;
  if (params_.motion_share > 0.0) decisions.motion_seeds = &motion_seeds_;
  StepSkip skip;
  decisions.skip = prepareSkip(step_prior.grid != nullptr, step_prior.doubt != nullptr, skip);
  fusionStep(grid_, projection_, step_prior, fp, &stats, &betp_, parallel_.get(), &decisions);
  skipped_share_ = grid_.numCells() > 0 ? static_cast<double>(stats.num_skipped) / grid_.numCells() : 0.0;
  observed_share_ = grid_.numCells() > 0 ? static_cast<double>(stats.num_observed) / grid_.numCells() : 0.0;
  changing_share_ = decisions.skip ? std::max(0.0, 1.0 - skipped_share_ - observed_share_)
                                   : std::numeric_limits<double>::quiet_NaN();
  const std::vector<std::size_t>* spread = nullptr;
  spreadMotionCells(grid_, betp_, projection_.occupied().data(), params_.motion_share, params_.motion_max_cells,
                    params_.decision_threshold, params_.motion_margin, parallel_.get(), &motion_seeds_, spread);
  forgetStable(*spread);
  redecide(grid_, betp_, params_, *spread, decision_);
  t.fusion = secondsSince(t0);

  last_stamp_ = stamp;
  ++scans_;
  if (times) *times = t;
  return stats;
}

const StepSkip* MapGrid::prepareSkip(bool has_prior, bool has_doubt, StepSkip& skip)
{
  if (!params_.skip_unchanged || params_.rates_per_second)
  {
    stable_.clear();
    for (auto& k : kept_) AlignedVector<float>().swap(k);
    skip_inputs_ = -1;
    return nullptr;
  }
  const std::size_t n = grid_.numCells();
  const std::size_t blocks = (n + MapMassGrid::kBlockCells - 1) / MapMassGrid::kBlockCells;
  const int inputs = (has_prior ? 2 : 0) + (has_doubt ? 1 : 0);
  if (stable_.size() != blocks || inputs != skip_inputs_)
  {
    stable_.assign(blocks, 0);
    for (auto& k : kept_) k.resize(n);
    skip_inputs_ = inputs;
  }
  skip.stable = stable_.data();
  for (int k = 0; k < 4; ++k) skip.kept[k] = kept_[k].data();
  return &skip;
}

void MapGrid::forgetStable(const std::vector<std::size_t>& cells)
{
  if (stable_.empty()) return;
  for (const std::size_t i : cells)
    if (i / MapMassGrid::kBlockCells < stable_.size()) stable_[i / MapMassGrid::kBlockCells] = 0;
}

void MapGrid::applyTrackedMotion(const std::vector<CellMotion>& cells)
{
  if (cells.empty()) return;
  float* const base = grid_.planes();
  std::vector<std::size_t> changed;
  changed.reserve(cells.size());
  const std::size_t n = grid_.numCells();
  for (const CellMotion& c : cells)
  {
    if (c.cell >= n) continue;
    changed.push_back(c.cell);
    if (c.motion != CellClass::kMoving && c.motion != CellClass::kStopped) continue;
    const float beta = std::clamp(c.weight, 0.0f, 1.0f);
    if (!(beta > 0.0f)) continue;
    const unsigned target = c.motion == CellClass::kMoving ? FrameMG::kV : FrameMG::kS;
    const unsigned other = c.motion == CellClass::kMoving ? FrameMG::kS : FrameMG::kV;
    // Only sets within {F, S, V}: the static classes stay the prior's and the counter's (a false moving track on a
    // pole must not take its N); a small mover's (take_n) also within {F, N, S, V}, and without a map (take_c) any.
    const unsigned dynamic =
        FrameMG::kF | FrameMG::kS | FrameMG::kV | (c.take_n ? FrameMG::kN : 0u) | (c.take_c ? FrameMG::kC : 0u);
    // Sets within {F, other} go to the target, except in a box cell the scan saw free; a small mover's within {N, S}
    // too (step small specialised).
    const unsigned agreeing = (c.interior && !c.hidden ? 0u : FrameMG::kF | other) |
                              (c.take_specialised && c.motion == CellClass::kMoving ? FrameMG::kN | other : 0u);
    float mass[kernels::kSubsets];
    kernels::loadMasses(base, c.cell, mass);
    float to_target = 0.0f;
    for (unsigned a = 1; a < static_cast<unsigned>(kernels::kSubsets); ++a)
    {
      if (a == target || mass[a] == 0.0f || (a & ~dynamic) != 0 || !((a & target) || (a & ~agreeing) == 0)) continue;
      const float moved = beta * mass[a];
      mass[a] -= moved;
      to_target += moved;
    }
    mass[target] += to_target;
    kernels::renormalise(mass);
    kernels::storeMasses(base, c.cell, mass);
    float p[FrameMG::kSize];
    kernels::pignistic(mass, p);
    for (int e = 0; e < FrameMG::kSize; ++e) betp_.p[e][c.cell] = p[e];
  }
  forgetStable(changed);
  redecide(grid_, betp_, params_, changed, decision_);
  const auto stopped = static_cast<std::int8_t>(CellClass::kStopped), moving = static_cast<std::int8_t>(CellClass::kMoving);
  for (const CellMotion& c : cells)
    if (c.motion == CellClass::kOccupied && c.cell < n && (decision_[c.cell] == stopped || decision_[c.cell] == moving))
      decision_[c.cell] = static_cast<std::int8_t>(CellClass::kOccupied);
}

}  // namespace core
}  // namespace map_aided_fusion

#include "map_aided_fusion/ros/conversions.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace map_aided_fusion {

using core::FrameMG;
using core::Subset;

namespace {

constexpr float kOccupancyScale = 100.0f;
constexpr std::int8_t kUnknownOccupancy = -1;

std::int8_t toOccupancyValue(float p)
{
  return static_cast<std::int8_t>(std::lround(std::clamp(p, 0.0f, 1.0f) * kOccupancyScale));
}

template <class Frame>
void checkClasses(const EvidentialGrid& msg)
{
  bool ok = msg.classes.size() == Frame::kNames.size();
  for (std::size_t i = 0; ok && i < msg.classes.size(); ++i) ok = msg.classes[i] == Frame::kNames[i];
  if (!ok)
  {
    std::string expected, got;
    for (const auto& n : Frame::kNames) expected += std::string(n) + " ";
    for (const auto& n : msg.classes) got += n + " ";
    throw ConversionError("EvidentialGrid: classes [" + got + "] are not the expected [" + expected + "]");
  }
}

void checkSizes(const EvidentialGrid& msg, std::size_t n)
{
  if (msg.masses.size() != msg.focal_sets.size() * n)
    throw ConversionError("EvidentialGrid: masses has " + std::to_string(msg.masses.size()) + " values, expected " +
                          std::to_string(msg.focal_sets.size()) + " layers x " + std::to_string(n) + " cells");
  if (!msg.counter.empty() && msg.counter.size() != n)
    throw ConversionError("EvidentialGrid: counter has " + std::to_string(msg.counter.size()) + " values, expected " +
                          std::to_string(n));
}

void fillHeader(const std_msgs::Header& header, const core::GridGeometry& g, nav_msgs::OccupancyGrid& out)
{
  out.header = header;
  GridConversions::toMapMetaData(g, out.info);
  out.info.map_load_time = header.stamp;
  out.data.resize(g.numCells());
}

}  // namespace

void GridConversions::toMapMetaData(const core::GridGeometry& g, nav_msgs::MapMetaData& info)
{
  info.resolution = static_cast<float>(g.resolution);
  info.width = static_cast<std::uint32_t>(g.width);
  info.height = static_cast<std::uint32_t>(g.height);
  info.origin.position.x = g.origin_x;
  info.origin.position.y = g.origin_y;
  info.origin.position.z = 0.0;
  info.origin.orientation.x = 0.0;
  info.origin.orientation.y = 0.0;
  info.origin.orientation.z = 0.0;
  info.origin.orientation.w = 1.0;
}

core::GridGeometry GridConversions::fromMapMetaData(const nav_msgs::MapMetaData& info)
{
  const auto& q = info.origin.orientation;
  const double yaw_tolerance = 1e-6;
  if (std::abs(q.x) > yaw_tolerance || std::abs(q.y) > yaw_tolerance || std::abs(q.z) > yaw_tolerance)
    throw ConversionError("MapMetaData: rotated grid origins are not supported");
  if (!(info.resolution > 0.0f) || !std::isfinite(info.resolution))
    throw ConversionError("MapMetaData: resolution must be > 0");
  core::GridGeometry g;
  g.resolution = info.resolution;
  g.width = static_cast<int>(info.width);
  g.height = static_cast<int>(info.height);
  g.origin_x = info.origin.position.x;
  g.origin_y = info.origin.position.y;
  return g;
}

namespace {

/// Slot @p s of every cell of @p grid, appended to @p out (for either layout of MassGrid; a planar slot is one
/// contiguous copy, without zero-filling first).
template <class Frame>
void appendSlot(const core::MassGrid<Frame>& grid, int s, std::vector<float>& out)
{
  const std::size_t n = grid.numCells();
  if constexpr (!core::MassGrid<Frame>::kInterleaved)
  {
    const float* const src = grid.planes() + grid.stride() * static_cast<std::size_t>(s);
    out.insert(out.end(), src, src + n);
  }
  else
  {
    const std::size_t first = out.size();
    out.resize(first + n);
    float* const dst = out.data() + first;
    for (std::size_t i = 0; i < n; ++i) dst[i] = grid.value(s, i);
  }
}

/// Slot @p s of every cell of @p grid from @p src (nullptr: zeros).
template <class Frame>
void writeSlot(core::MassGrid<Frame>& grid, int s, const float* src)
{
  const std::size_t n = grid.numCells();
  if constexpr (!core::MassGrid<Frame>::kInterleaved)
  {
    float* const dst = grid.planes() + grid.stride() * static_cast<std::size_t>(s);
    if (src)
      std::copy(src, src + n, dst);
    else
      std::fill(dst, dst + n, 0.0f);
  }
  else
  {
    for (std::size_t i = 0; i < n; ++i) grid.value(s, i) = src ? src[i] : 0.0f;
  }
}

/// True when slot @p s of some cell of @p grid is not zero (a NaN counts; planar slots: core::anyNonZero()).
template <class Frame>
bool anyNonZero(const core::MassGrid<Frame>& grid, int s)
{
  const std::size_t n = grid.numCells();
  if constexpr (!core::MassGrid<Frame>::kInterleaved)
  {
    return core::anyNonZero(grid.planes() + grid.stride() * static_cast<std::size_t>(s), n);
  }
  else
  {
    for (std::size_t i = 0; i < n; ++i)
      if (grid.value(s, i) != 0.0f) return true;
    return false;
  }
}

}  // namespace

template <class Frame>
void GridConversions::toMessage(const core::MassGrid<Frame>& grid, const std_msgs::Header& header,
                                EvidentialGrid& msg, PlaneSelection planes, bool with_counter)
{
  const std::size_t n = grid.numCells();
  msg.header = header;
  toMapMetaData(grid.geometry(), msg.info);
  msg.info.map_load_time = header.stamp;
  msg.classes.assign(Frame::kNames.begin(), Frame::kNames.end());
  msg.focal_sets.clear();
  for (int a = 0; a < Frame::kNumSubsets; ++a)
  {
    if (!grid.stored(static_cast<Subset>(a))) continue;  // mass 0 in every cell
    const int s = grid.slot(static_cast<Subset>(a));
    if (planes == PlaneSelection::kAll || anyNonZero(grid, s)) msg.focal_sets.push_back(static_cast<std::uint8_t>(a));
  }
  msg.masses.clear();  // appended plane by plane: no zero fill first
  msg.masses.reserve(msg.focal_sets.size() * n);
  for (const std::uint8_t a : msg.focal_sets) appendSlot(grid, grid.slot(a), msg.masses);
  msg.counter.clear();
  if (with_counter) appendSlot(grid, core::MassGrid<Frame>::kNumPlanes, msg.counter);
}

namespace {

/// fromMessage()'s checks; then @p grid takes the message's geometry. Returns, per slot of @p grid (the counter
/// last), the message's layer to copy, or nullptr for zeros.
template <class Frame>
std::array<const float*, core::MassGrid<Frame>::kNumPlanes + 1> sourcesOf(const EvidentialGrid& msg,
                                                                          core::MassGrid<Frame>& grid)
{
  checkClasses<Frame>(msg);
  const core::GridGeometry g = GridConversions::fromMapMetaData(msg.info);
  const std::size_t n = g.numCells();
  checkSizes(msg, n);
  std::uint64_t seen = 0;
  for (auto a : msg.focal_sets)
  {
    if (a >= Frame::kNumSubsets)
      throw ConversionError("EvidentialGrid: focal set " + std::to_string(a) + " is outside the frame");
    if (seen & (1ull << a))
      throw ConversionError("EvidentialGrid: focal set " + core::subsetName<Frame>(a) + " appears twice");
    seen |= 1ull << a;
  }
  for (std::size_t k = 0; k < msg.focal_sets.size(); ++k)
  {
    const auto first = msg.masses.begin() + static_cast<std::ptrdiff_t>(k * n);
    const auto nonzero = [](float v) { return v != 0.0f; };
    if (!grid.stored(msg.focal_sets[k]) && std::any_of(first, first + static_cast<std::ptrdiff_t>(n), nonzero))
      throw ConversionError("EvidentialGrid: mass on focal set " + core::subsetName<Frame>(msg.focal_sets[k]) +
                            ", which this grid never holds");
  }
  if (grid.geometry() != g)
    grid.reset(g);
  std::array<const float*, core::MassGrid<Frame>::kNumPlanes + 1> sources{};  // each stored slot: absent, zeros
  for (std::size_t k = 0; k < msg.focal_sets.size(); ++k)
    if (grid.stored(msg.focal_sets[k]))
      sources[static_cast<std::size_t>(grid.slot(msg.focal_sets[k]))] = msg.masses.data() + k * n;
  sources[core::MassGrid<Frame>::kNumPlanes] = msg.counter.empty() ? nullptr : msg.counter.data();
  return sources;
}

}  // namespace

template <class Frame>
void GridConversions::fromMessage(const EvidentialGrid& msg, core::MassGrid<Frame>& grid)
{
  const auto sources = sourcesOf(msg, grid);
  for (std::size_t s = 0; s < sources.size(); ++s) writeSlot(grid, static_cast<int>(s), sources[s]);
}

void GridConversions::scanFromMessage(const EvidentialGrid& msg, core::ScanMassGrid& grid)
{
  static_assert(!core::ScanMassGrid::kInterleaved, "a ScanGrid's layers are planes");
  const auto sources = sourcesOf(msg, grid);
  const std::size_t n = grid.numCells();
  float* const planes = grid.planes();
  const float *e = grid.plane(core::FrameSG::kEmpty), *f = grid.plane(core::FrameSG::kF),
              *o = grid.plane(core::FrameSG::kO), *w = grid.plane(core::FrameSG::kOmega);
  // Bitwise, not short-circuit, and counted: the check vectorises. A NaN fails every comparison.
  const auto invalid = [&](std::size_t i) -> unsigned {
    const float d = e[i] + f[i] + o[i] + w[i] - 1.0f;
    return !((d < kScanMassTolerance) & (d > -kScanMassTolerance) & (e[i] >= 0.0f) & (f[i] >= 0.0f) &
             (o[i] >= 0.0f) & (w[i] >= 0.0f));
  };
  // Chunk by chunk, so that the check reads what the copy has just written.
  for (std::size_t i0 = 0; i0 < n; i0 += kScanCheckChunk)
  {
    const std::size_t i1 = std::min(n, i0 + kScanCheckChunk);
    for (std::size_t s = 0; s < sources.size(); ++s)
    {
      float* const dst = planes + grid.stride() * s;
      if (sources[s])
        std::copy(sources[s] + i0, sources[s] + i1, dst + i0);
      else
        std::fill(dst + i0, dst + i1, 0.0f);
    }
    unsigned invalid_cells = 0;  // one pass; only then the first bad cell, to name it
    for (std::size_t i = i0; i < i1; ++i) invalid_cells += invalid(i);
    if (invalid_cells > 0)
      for (std::size_t i = i0; i < i1; ++i)
        if (invalid(i))
          throw ConversionError("cell " + std::to_string(i) + " is not a mass function (sum " +
                                std::to_string(e[i] + f[i] + o[i] + w[i]) + ")");
  }
}

template void GridConversions::toMessage(const core::MassGrid<FrameMG>&, const std_msgs::Header&, EvidentialGrid&,
                                         PlaneSelection, bool);
template void GridConversions::toMessage(const core::MassGrid<core::FrameSG>&, const std_msgs::Header&,
                                         EvidentialGrid&, PlaneSelection, bool);
template void GridConversions::fromMessage(const EvidentialGrid&, core::MassGrid<FrameMG>&);
template void GridConversions::fromMessage(const EvidentialGrid&, core::MassGrid<core::FrameSG>&);

void GridConversions::fromMessage(const EvidentialGrid& msg, core::PriorWindow& prior)
{
  checkClasses<FrameMG>(msg);
  const core::GridGeometry g = fromMapMetaData(msg.info);
  const std::size_t n = g.numCells();
  checkSizes(msg, n);
  prior.reset(g);
  for (std::size_t k = 0; k < msg.focal_sets.size(); ++k)
  {
    const auto a = msg.focal_sets[k];
    const auto first = msg.masses.begin() + static_cast<std::ptrdiff_t>(k * n);
    if (a == FrameMG::kBuilding)
      std::copy_n(first, n, prior.building.begin());
    else if (a == FrameMG::kRoad)
      std::copy_n(first, n, prior.road.begin());
    else if (a == FrameMG::kOther)
      std::copy_n(first, n, prior.other.begin());
    else if (a == FrameMG::kWall)
      std::copy_n(first, n, prior.wall.begin());
    else if (a != FrameMG::kOmega && a != FrameMG::kEmpty && std::any_of(first, first + n, [](float v) { return v != 0.0f; }))
      throw ConversionError("EvidentialGrid: a prior grid cannot carry mass on " + core::subsetName<FrameMG>(a) +
                            " (only B, R, T, W = {F, C} and Omega)");
  }
}

void GridConversions::toMessage(const core::PriorWindow& prior, const std_msgs::Header& header, EvidentialGrid& msg)
{
  const std::size_t n = prior.geometry.numCells();
  msg.header = header;
  toMapMetaData(prior.geometry, msg.info);
  msg.info.map_load_time = header.stamp;
  msg.classes.assign(FrameMG::kNames.begin(), FrameMG::kNames.end());
  const bool wall = prior.hasWall();
  msg.focal_sets = { FrameMG::kBuilding, FrameMG::kRoad, FrameMG::kOther, FrameMG::kOmega };
  if (wall) msg.focal_sets.push_back(FrameMG::kWall);
  msg.masses.resize(msg.focal_sets.size() * n);
  auto out = msg.masses.begin();
  out = std::copy(prior.building.begin(), prior.building.end(), out);
  out = std::copy(prior.road.begin(), prior.road.end(), out);
  out = std::copy(prior.other.begin(), prior.other.end(), out);
  for (std::size_t i = 0; i < n; ++i)
    *out++ = 1.0f - prior.building[i] - prior.road[i] - prior.other[i] - (wall ? prior.wall[i] : 0.0f);
  if (wall) std::copy(prior.wall.begin(), prior.wall.end(), out);
  msg.counter.clear();
}

void GridConversions::pignisticToOccupancy(const core::MapMassGrid& grid, const core::PignisticPlanes& betp,
                                           int element, const std_msgs::Header& header, nav_msgs::OccupancyGrid& out,
                                           float vacuous_tolerance)
{
  if (element < 0 || element >= FrameMG::kSize)
    throw ConversionError("pignisticToOccupancy: element " + std::to_string(element) + " is not in the frame");
  fillHeader(header, grid.geometry(), out);
  const auto& p = betp[element];
  const int omega = core::MapMassGrid::slot(FrameMG::kOmega);
  for (std::size_t i = 0; i < grid.numCells(); ++i)
    out.data[i] = grid.value(omega, i) >= 1.0f - vacuous_tolerance ? kUnknownOccupancy : toOccupancyValue(p[i]);
}

void GridConversions::scanToOccupancy(const core::ScanMassGrid& grid, const std_msgs::Header& header,
                                      nav_msgs::OccupancyGrid& out, float vacuous_tolerance)
{
  fillHeader(header, grid.geometry(), out);
  const float* f = grid.plane(core::FrameSG::kF);
  const float* o = grid.plane(core::FrameSG::kO);
  const float* omega = grid.plane(core::FrameSG::kOmega);
  for (std::size_t i = 0; i < grid.numCells(); ++i)
  {
    const float norm = f[i] + o[i] + omega[i];
    out.data[i] = omega[i] >= 1.0f - vacuous_tolerance || norm <= 0.0f
                      ? kUnknownOccupancy
                      : toOccupancyValue((o[i] + 0.5f * omega[i]) / norm);
  }
}

}  // namespace map_aided_fusion

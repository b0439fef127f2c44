#include "map_aided_fusion/core/scan_grid.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "map_aided_fusion/core/parameters.hpp"

namespace map_aided_fusion {
namespace core {

namespace {

constexpr double kFullTurnDeg = 360.0;
constexpr double kMinAzimuthResolutionDeg = 0.01;
constexpr double kMaxAzimuthResolutionDeg = 45.0;
constexpr double kSectorCountSlack = 1e-9;     // 360 / 0.25 is 1440 sectors, not 1441
/// Bounds that keep every cell index, range and angle far inside float and int: a vehicle-frame grid,
/// ranges and heights of at most 10 km, a sensor at most 1 km from base_link.
constexpr double kMaxExtent = 10000.0;       // m
constexpr double kMinGridResolution = 0.01;  // m
constexpr double kMaxSensorOffset = 1000.0;  // m
constexpr double kSensorMoveTolerance = 1e-3;  // m; a smaller (x, y) change keeps the table
constexpr double kMaxSweepDuration = 10.0;     // s
constexpr int kMaxGroundSectors = 64;
constexpr double kMaxGroundSlopeDeg = 60.0;
constexpr int kMaxGroundMinPoints = 100000;
constexpr double kMaxGroundBand = 10.0;  // m
constexpr float kPi = 3.14159265358979323846f;
constexpr float kHalfPi = 0.5f * kPi;
constexpr float kTwoPi = 2.0f * kPi;
constexpr float kInfinity = std::numeric_limits<float>::infinity();
/// Points (or valid returns) per chunk of build()'s point passes.
constexpr std::size_t kPointChunk = 16384;
/// Azimuth sectors per chunk of the free-space fill.
constexpr std::size_t kSectorChunk = 64;
/// Cells per chunk of the plane fills.
constexpr std::size_t kFillChunk = 65536;

// Minimax polynomial for atan(a), a in [0, 1]; absolute error below 1e-5 rad.
constexpr float kAtan1 = 0.99997726f;
constexpr float kAtan3 = -0.33262347f;
constexpr float kAtan5 = 0.19354346f;
constexpr float kAtan7 = -0.11643287f;
constexpr float kAtan9 = 0.05265332f;
constexpr float kAtan11 = -0.01172120f;

inline float fastAtan2(float y, float x)
{
  const float ax = std::fabs(x);
  const float ay = std::fabs(y);
  const float mx = std::max(ax, ay);
  if (mx == 0.0f) return 0.0f;
  const float a = std::min(ax, ay) / mx;
  const float s = a * a;
  float r = ((((kAtan11 * s + kAtan9) * s + kAtan7) * s + kAtan5) * s + kAtan3) * s * a + kAtan1 * a;
  if (ay > ax) r = kHalfPi - r;
  if (x < 0.0f) r = kPi - r;
  return y < 0.0f ? -r : r;
}

/// A monotonic stand-in for the direction of (dx, dy) as a fraction of the turn, in [0, 1): the "diamond angle",
/// exact at every multiple of 45° and within 4° of the true angle between them, without an arctangent.
inline float turnFraction(float dx, float dy)
{
  const float s = std::fabs(dx) + std::fabs(dy);
  if (s == 0.0f) return 0.0f;
  float d;
  if (dy >= 0.0f) d = dx >= 0.0f ? dy / s : 1.0f - dx / s;
  else d = dx < 0.0f ? 2.0f - dy / s : 3.0f + dx / s;
  return std::min(0.25f * d, 0.99999994f);
}

inline int sectorIndex(float dx, float dy, float scale, int num_sectors)
{
  const int s = static_cast<int>((fastAtan2(dy, dx) + kPi) * scale);
  return s >= num_sectors ? s - num_sectors : (s < 0 ? 0 : s);
}

/// Moves @p count records of @p width values from index @p from to index @p to ≤ from (the chunks' lists together).
template <typename T>
void moveSegment(T* data, std::size_t width, std::size_t from, std::size_t count, std::size_t to)
{
  if (from != to && count > 0) std::memmove(data + to * width, data + from * width, count * width * sizeof(T));
}

/// *p = min(*p, v), for threads sharing p: the result is that of any order.
void atomicMin(float* p, float v)
{
  float current;
  __atomic_load(p, &current, __ATOMIC_RELAXED);
  while (v < current)
    if (__atomic_compare_exchange(p, &current, &v, true, __ATOMIC_RELAXED, __ATOMIC_RELAXED)) return;
}

inline float readFloat(const std::uint8_t* p)
{
  float v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

constexpr std::uint32_t kOutside = std::numeric_limits<std::uint32_t>::max();  // an obstacle return off the grid
/// A return the two ground models of step ground consensus dispute: it bounds its sector's free space, marks no cell.
constexpr std::uint32_t kDisputed = kOutside - 1;
/// The bands of a height above the ground (PointPass::band()).
enum HeightBand : int
{
  kBandBelow,
  kBandGround,
  kBandGap,
  kBandObstacle,
  kBandAbove,
};

/// What the point passes of ScanGridBuilder::build() read (the sensor model and the grid, as values) and where they
/// write. Each chunk works on its own copy.
struct PointPass
{
  float rot[9];  // sensor → base_link rotation, row-major
  float shift_x, shift_y, trans_z, min2, max2, inv_res, cx0, cy0, fwidth, fheight, sector_scale;
  float self_min_x, self_max_x, self_min_y, self_max_y, tolerance, obstacle_min, obstacle_max, relative_limit;
  int width, num_sectors;
  bool relative, shared;
  std::uint32_t* ground_sector;
  float* ground_range2;
  std::uint32_t* obstacle_sector;
  float* obstacle_range2;
  std::uint32_t* obstacle_cell;
  float* obstacle_xy;
  float* obstacle_z;
  float* cell_min_z;
  // The cloud, and the valid returns of the `planes` ground model.
  const std::uint8_t* data;
  std::size_t cols, point_step, row_step, x_offset, y_offset, z_offset;
  float ground;  // flat ground height
  bool planes;
  float* valid_dx;
  float* valid_dy;
  float* valid_z;
  std::uint16_t* valid_zone;
  const GroundPlaneFitter* fitter;
  // Step "ground consensus": the second model's zone of each valid return and its fitter (nullptr when off).
  std::uint16_t* valid_zone2;
  const GroundPlaneFitter* second;
  // Step "ambiguous unknown": per cell, set when it holds a return neither ground nor obstacle (nullptr when off).
  std::uint8_t* ambiguous;
  // Step "ground cells free": per cell, set when it holds a ground return (nullptr when off).
  std::uint8_t* ground_seen;
  // recordReturnClasses(): per point its class, per obstacle and valid return its point (nullptr when off).
  ReturnClass* point_class;
  std::uint32_t* obstacle_point;
  std::uint32_t* valid_point;

  void record(std::size_t point, ReturnClass c) const
  {
    if (point_class) point_class[point] = c;
  }

  /// Flags the cell of a return at (dx, dy) from the sensor as holding an ambiguous return (any thread).
  void markAmbiguous(float dx, float dy) const { markCell(ambiguous, dx, dy); }

  /// Sets @p flags' entry of the cell of a return at (dx, dy) from the sensor, when it is on the grid (any thread).
  void markCell(std::uint8_t* flags, float dx, float dy) const
  {
    const float fx = cx0 + dx * inv_res;
    const float fy = cy0 + dy * inv_res;
    if ((fx >= 0.0f) & (fy >= 0.0f) & (fx < fwidth) & (fy < fheight))
      __atomic_store_n(flags + static_cast<int>(fy) * width + static_cast<int>(fx), std::uint8_t{ 1 },
                       __ATOMIC_RELAXED);
  }

  /// The band of a height @p h above the ground.
  int band(float h) const
  {
    if (h < -tolerance) return kBandBelow;
    if (h <= tolerance) return kBandGround;
    if (h < obstacle_min) return kBandGap;
    return h <= obstacle_max ? kBandObstacle : kBandAbove;
  }

  /// Step "ground consensus": classifies a return against the ground heights @p g of the first model and @p g2 of
  /// the second. Ground for one and obstacle for the other: disputed (it bounds the free space of its sector, gives
  /// no mass, and its cell is ambiguous). Otherwise an obstacle for either is an obstacle, and the first model
  /// decides the rest.
  template <class Out>
  void classifyBoth(std::size_t point, float dx, float dy, float z, float r2, float g, float g2, Out& out) const
  {
    const int b1 = band(z - g), b2 = band(z - g2);
    if ((b1 == kBandGround && b2 == kBandObstacle) || (b1 == kBandObstacle && b2 == kBandGround))
    {
      ++out.counts.disputed;
      const std::size_t k = out.first + out.obstacle++;
      obstacle_sector[k] = static_cast<std::uint32_t>(sectorIndex(dx, dy, sector_scale, num_sectors));
      obstacle_range2[k] = r2;
      obstacle_cell[k] = kDisputed;
      obstacle_xy[2 * k] = dx;
      obstacle_xy[2 * k + 1] = dy;
      if (relative) obstacle_z[k] = kInfinity;
      if (point_class)
      {
        point_class[point] = ReturnClass::kDisputed;
        obstacle_point[k] = static_cast<std::uint32_t>(point);
      }
      if (ambiguous) markAmbiguous(dx, dy);
      return;
    }
    classify(point, dx, dy, z, r2, b2 == kBandObstacle ? g2 : g, out);
  }

  /// Classifies a valid return (point @p point of the view) at (dx, dy) from the sensor, height z, over ground
  /// height g, into @p out.
  template <class Out>
  void classify(std::size_t point, float dx, float dy, float z, float r2, float g, Out& out) const
  {
    if (relative)
    {
      const float fx = cx0 + dx * inv_res;
      const float fy = cy0 + dy * inv_res;
      if ((fx >= 0.0f) & (fy >= 0.0f) & (fx < fwidth) & (fy < fheight))
      {
        float* const lowest = cell_min_z + static_cast<int>(fy) * width + static_cast<int>(fx);
        if (shared)  // chunks on other threads may lower the same cell's lowest return
          atomicMin(lowest, z);
        else
          *lowest = std::min(*lowest, z);
      }
    }
    const float h = z - g;
    if (h < -tolerance)
    {
      ++out.counts.below_ground;
      record(point, ReturnClass::kBelowGround);
    }
    else if (h <= tolerance)
    {
      record(point, ReturnClass::kGround);
      const std::size_t k = out.first + out.ground++;
      ground_sector[k] = static_cast<std::uint32_t>(sectorIndex(dx, dy, sector_scale, num_sectors));
      ground_range2[k] = r2;
      if (ground_seen) markCell(ground_seen, dx, dy);
    }
    else if (h < obstacle_min)
    {
      ++out.counts.gap;
      record(point, ReturnClass::kHeightGap);
      if (ambiguous) markAmbiguous(dx, dy);
    }
    else if (h <= obstacle_max)
    {
      const float fx = cx0 + dx * inv_res;
      const float fy = cy0 + dy * inv_res;
      const bool inside = (fx >= 0.0f) & (fy >= 0.0f) & (fx < fwidth) & (fy < fheight);
      const std::size_t k = out.first + out.obstacle++;
      obstacle_sector[k] = static_cast<std::uint32_t>(sectorIndex(dx, dy, sector_scale, num_sectors));
      obstacle_range2[k] = r2;
      obstacle_cell[k] =
          inside ? static_cast<std::uint32_t>(static_cast<int>(fy) * width + static_cast<int>(fx)) : kOutside;
      obstacle_xy[2 * k] = dx;
      obstacle_xy[2 * k + 1] = dy;
      if (relative) obstacle_z[k] = h < relative_limit ? z : kInfinity;
      if (point_class)
      {
        point_class[point] = ReturnClass::kObstacle;
        obstacle_point[k] = static_cast<std::uint32_t>(point);
      }
    }
    else
    {
      ++out.counts.above;
      record(point, ReturnClass::kAboveClearance);
    }
  }
};

}  // namespace

void ScanGridParams::validate() const
{
  requireInRange("grid_resolution", grid_resolution, kMinGridResolution, kMaxExtent);
  requireInRange("grid_size_x", grid_size_x, grid_resolution, kMaxExtent);
  requireInRange("grid_size_y", grid_size_y, grid_resolution, kMaxExtent);
  requireInRange("grid_offset_x", grid_offset_x, -kMaxExtent, kMaxExtent);
  requireInRange("grid_offset_y", grid_offset_y, -kMaxExtent, kMaxExtent);
  requireInRange("azimuth_resolution_deg", azimuth_resolution_deg, kMinAzimuthResolutionDeg,
                 kMaxAzimuthResolutionDeg);
  requireInRange("min_range", min_range, 0.0, kMaxExtent);
  requireInRange("max_range", max_range, std::numeric_limits<double>::min(), kMaxExtent);
  if (!(max_range > min_range)) throw ParameterError("max_range", "must be > min_range");
  requireInRange("self_box_min_x", self_box_min_x, -kMaxExtent, kMaxExtent);
  requireInRange("self_box_max_x", self_box_max_x, self_box_min_x, kMaxExtent);
  requireInRange("self_box_min_y", self_box_min_y, -kMaxExtent, kMaxExtent);
  requireInRange("self_box_max_y", self_box_max_y, self_box_min_y, kMaxExtent);
  requireInRange("ground_height", ground_height, -kMaxExtent, kMaxExtent);
  requireInRange("ground_tolerance", ground_tolerance, 0.0, kMaxExtent);
  requireInRange("obstacle_min_height", obstacle_min_height, ground_tolerance, kMaxExtent);
  requireInRange("obstacle_max_height", obstacle_max_height, obstacle_min_height, kMaxExtent);
  if (!(obstacle_max_height > obstacle_min_height))
    throw ParameterError("obstacle_max_height", "must be > obstacle_min_height");
  requireUnit("mu_free", mu_free);
  requireUnit("mu_occupied", mu_occupied);
  requireInRange("free_decay_length", free_decay_length, 0.0, kMaxExtent);
  requireInRange("free_margin", free_margin, 0.0, max_range);
  requireInRange("relative_height_limit", relative_height_limit, 0.0, kMaxExtent);
  validateThreads("threads", threads);
  if (!(deskew_max_sweep_duration > 0.0)) throw ParameterError("deskew_max_sweep_duration", "must be > 0");
  requireInRange("deskew_max_sweep_duration", deskew_max_sweep_duration, 0.0, kMaxSweepDuration);
  groundModel();
  requireInRange("ground_sectors", ground_sectors, 1, kMaxGroundSectors);
  requireInRange("ground_max_slope_deg", ground_max_slope_deg, 0.0, kMaxGroundSlopeDeg);
  requireInRange("ground_zones_max_slope_deg", ground_zones_max_slope_deg, 0.0, kMaxGroundSlopeDeg);
  requireInRange("ground_min_points", ground_min_points, 3, kMaxGroundMinPoints);
  if (!(ground_search_band > 0.0)) throw ParameterError("ground_search_band", "must be > 0");
  requireInRange("ground_search_band", ground_search_band, 0.0, kMaxGroundBand);
  if (!(ground_fit_tolerance > 0.0)) throw ParameterError("ground_fit_tolerance", "must be > 0");
  requireInRange("ground_fit_tolerance", ground_fit_tolerance, 0.0, ground_search_band);
  const double cells = std::round(grid_size_x / grid_resolution) * std::round(grid_size_y / grid_resolution);
  if (!(cells <= static_cast<double>(kScanGridMaxCells)))
    throw ParameterError("grid_size_x", "grid of " + std::to_string(cells) + " cells exceeds the limit of " +
                                            std::to_string(kScanGridMaxCells));
}

PointCloudView PointCloudView::packed(const void* data, std::size_t count, std::size_t point_step,
                                      std::size_t x_offset, std::size_t y_offset, std::size_t z_offset)
{
  PointCloudView v;
  v.data = static_cast<const std::uint8_t*>(data);
  v.width = count;
  v.height = 1;
  v.point_step = point_step;
  v.row_step = count * point_step;
  v.x_offset = x_offset;
  v.y_offset = y_offset;
  v.z_offset = z_offset;
  return v;
}

bool PointCloudView::consistent() const
{
  if (size() == 0) return true;
  if (data == nullptr) return false;
  const std::size_t last = std::max({ x_offset, y_offset, z_offset }) + sizeof(float);
  if (last > point_step) return false;
  if (height > 1 && row_step < width * point_step) return false;
  return true;
}

ScanGridBuilder::ScanGridBuilder(const ScanGridParams& params, const Eigen::Isometry3d& sensor_pose)
{
  configure(params, sensor_pose);
}

void ScanGridBuilder::configure(const ScanGridParams& params, const Eigen::Isometry3d& sensor_pose)
{
  params.validate();
  const GridGeometry geometry = params.geometry();
  geometry.validate();
  if (!sensor_pose.matrix().allFinite())
    throw ParameterError("sensor_pose", "the sensor → base_link transform is not finite");
  if (sensor_pose.translation().cwiseAbs().maxCoeff() > kMaxSensorOffset)
    throw ParameterError("sensor_pose", "the sensor is more than " + std::to_string(kMaxSensorOffset) +
                                            " m from base_link");

  const bool same_table = configured_ && geometry == geometry_ &&
                          params.azimuth_resolution_deg == params_.azimuth_resolution_deg &&
                          params.min_range == params_.min_range && params.max_range == params_.max_range &&
                          params.mu_free == params_.mu_free &&
                          params.free_decay_length == params_.free_decay_length &&
                          std::abs(sensor_pose.translation().x() - table_sensor_x_) <= kSensorMoveTolerance &&
                          std::abs(sensor_pose.translation().y() - table_sensor_y_) <= kSensorMoveTolerance;
  params_ = params;
  geometry_ = geometry;
  sensor_pose_ = sensor_pose;
  configured_ = true;
  ground_kind_ = params.groundModel();
  ground_.configure(params.groundModelParams());
  GroundModelParams other = params.groundModelParams();
  other.model = ground_kind_ == GroundModel::kZones ? GroundModel::kPlanes : GroundModel::kZones;
  second_.configure(other);
  if (!parallel_ || parallel_->threads() != resolveThreads(params.threads))
    parallel_ = std::make_shared<const Parallel>(params.threads);
  if (!same_table) buildTable();
}

void ScanGridBuilder::setSensorPose(const Eigen::Isometry3d& sensor_pose)
{
  if (!configured_) throw ParameterError("sensor_pose", "configure() the builder first");
  configure(params_, sensor_pose);
}

void ScanGridBuilder::prepareStepBuffers(std::size_t n_points, bool fitted)
{
  if (fitted && params_.ground_consensus && valid_zone2_.size() < n_points) valid_zone2_.resize(n_points);
  if (params_.ambiguous_unknown)
  {
    ambiguous_.resize(geometry_.numCells());
    std::uint8_t* const amb = ambiguous_.data();
    parallel_->forRange(ambiguous_.size(), kFillChunk,
                        [amb](std::size_t i0, std::size_t i1) { std::fill(amb + i0, amb + i1, std::uint8_t{ 0 }); });
  }
  if (params_.ground_cells_free)
  {
    ground_seen_.resize(geometry_.numCells());
    std::uint8_t* const seen = ground_seen_.data();
    parallel_->forRange(ground_seen_.size(), kFillChunk,
                        [seen](std::size_t i0, std::size_t i1) { std::fill(seen + i0, seen + i1, std::uint8_t{ 0 }); });
  }
  if (!record_classes_)
  {
    return_classes_.clear();
    return;
  }
  // Every point starts rejected; classify() overwrites the valid returns.
  return_classes_.assign(n_points, ReturnClass::kRejected);
  obstacle_point_.resize(n_points + 1);
  if (fitted) valid_point_.resize(n_points + 1);
}

std::size_t ScanGridBuilder::clearAmbiguousFree(float* m_f, float* m_omega) const
{
  // A cell holding a return that is neither ground nor obstacle is not free. Each chunk counts its own cells.
  const std::uint8_t* const amb = ambiguous_.data();
  std::vector<std::size_t> chunk_cleared(chunkCount(ambiguous_.size(), kFillChunk), 0);
  parallel_->forRange(ambiguous_.size(), kFillChunk, [&](std::size_t i0, std::size_t i1) {
    std::size_t cleared = 0;
    for (std::size_t i = i0; i < i1; ++i)
      if (amb[i] && m_f[i] > 0.0f)
      {
        m_f[i] = 0.0f;
        m_omega[i] = 1.0f;
        ++cleared;
      }
    chunk_cleared[i0 / kFillChunk] = cleared;
  });
  std::size_t cleared = 0;
  for (const std::size_t c : chunk_cleared) cleared += c;
  return cleared;
}

std::size_t ScanGridBuilder::fillGroundCells(float* m_f, float* m_omega) const
{
  // A cell holding a ground return and no free mass yet (beyond its sector's nearest obstacle) is free. μ_F is that of
  // its centre's range, as in the table; a centre outside [min_range, max_range] stays unknown, as there.
  const std::uint8_t* const seen = ground_seen_.data();
  const bool decay = params_.free_decay_length > 0.0;
  const double min2 = params_.min_range * params_.min_range, max2 = params_.max_range * params_.max_range;
  std::vector<std::size_t> chunk_filled(chunkCount(ground_seen_.size(), kFillChunk), 0);
  parallel_->forRange(ground_seen_.size(), kFillChunk, [&](std::size_t i0, std::size_t i1) {
    std::size_t filled = 0;
    for (std::size_t i = i0; i < i1; ++i)
    {
      if (!seen[i] || m_f[i] > 0.0f) continue;
      const Point2 c = geometry_.cellCentre(geometry_.cellOf(i));
      const double dx = c.x - table_sensor_x_, dy = c.y - table_sensor_y_;
      const double r2 = dx * dx + dy * dy;
      if (r2 < min2 || r2 > max2) continue;
      const double mu = decay ? params_.mu_free * std::exp(-std::sqrt(r2) / params_.free_decay_length) : params_.mu_free;
      m_f[i] = static_cast<float>(mu);
      m_omega[i] = 1.0f - m_f[i];
      filled += m_f[i] > 0.0f;
    }
    chunk_filled[i0 / kFillChunk] = filled;
  });
  std::size_t filled = 0;
  for (const std::size_t c : chunk_filled) filled += c;
  return filled;
}

int ScanGridBuilder::sectorOf(double dx, double dy) const
{
  return sectorIndex(static_cast<float>(dx), static_cast<float>(dy), sector_scale_, num_sectors_);
}

void ScanGridBuilder::buildTable()
{
  num_sectors_ = static_cast<int>(std::ceil(kFullTurnDeg / params_.azimuth_resolution_deg - kSectorCountSlack));
  sector_scale_ = static_cast<float>(num_sectors_) / kTwoPi;
  table_sensor_x_ = sensor_pose_.translation().x();
  table_sensor_y_ = sensor_pose_.translation().y();
  const bool decay = params_.free_decay_length > 0.0;
  const std::size_t sectors = static_cast<std::size_t>(num_sectors_);

  std::vector<TableEntry> entries;
  std::vector<std::uint32_t> entry_sector;
  entries.reserve(geometry_.numCells());
  entry_sector.reserve(geometry_.numCells());
  for (int y = 0; y < geometry_.height; ++y)
    for (int x = 0; x < geometry_.width; ++x)
    {
      const Point2 c = geometry_.cellCentre(CellIndex{ x, y });
      const double dx = c.x - table_sensor_x_;
      const double dy = c.y - table_sensor_y_;
      const double r = std::hypot(dx, dy);
      if (r < params_.min_range || r > params_.max_range) continue;  // never free
      const double mu = decay ? params_.mu_free * std::exp(-r / params_.free_decay_length) : params_.mu_free;
      entries.push_back({ static_cast<float>(r * r), static_cast<std::uint32_t>(geometry_.index(x, y)),
                          static_cast<float>(mu) });
      entry_sector.push_back(static_cast<std::uint32_t>(sectorOf(dx, dy)));
    }

  sector_begin_.assign(sectors + 1, 0);
  for (const std::uint32_t s : entry_sector) ++sector_begin_[s + 1];
  for (std::size_t s = 0; s < sectors; ++s) sector_begin_[s + 1] += sector_begin_[s];
  table_.resize(entries.size());
  std::vector<std::uint32_t> next(sector_begin_.begin(), sector_begin_.end() - 1);
  for (std::size_t k = 0; k < entries.size(); ++k) table_[next[entry_sector[k]]++] = entries[k];
  for (std::size_t s = 0; s < sectors; ++s)
    std::sort(table_.begin() + sector_begin_[s], table_.begin() + sector_begin_[s + 1],
              [](const TableEntry& a, const TableEntry& b) { return a.range2 < b.range2; });

  sector_obstacle2_.assign(sectors, kInfinity);
  sector_free2_.assign(sectors, 0.0f);
  ++table_builds_;
}

bool ScanGridBuilder::build(const PointCloudView& points, ScanMassGrid& grid, ScanGridStats* stats)
{
  ScanGridStats st;
  st.points = points.size();
  if (!configured_ || !points.consistent())
  {
    if (stats) *stats = st;
    return false;
  }
  if (grid.geometry() != geometry_ || grid.stride() == 0) grid.reset(geometry_);

  const std::size_t n_points = points.size();
  if (ground_sector_.size() < n_points + 1)
  {
    ground_sector_.resize(n_points + 1);
    ground_range2_.resize(n_points + 1);
    obstacle_sector_.resize(n_points + 1);
    obstacle_range2_.resize(n_points + 1);
    obstacle_cell_.resize(n_points + 1);
  }
  if (obstacle_points_.size() < 2 * (n_points + 1)) obstacle_points_.resize(2 * (n_points + 1));
  const bool relative = params_.relative_height_limit > 0.0;
  if (relative)
  {
    if (obstacle_z_.size() < n_points + 1) obstacle_z_.resize(n_points + 1);
    cell_min_z_.resize(geometry_.numCells());
    float* const lowest = cell_min_z_.data();
    parallel_->forRange(cell_min_z_.size(), kFillChunk,
                        [lowest](std::size_t i0, std::size_t i1) { std::fill(lowest + i0, lowest + i1, kInfinity); });
  }
  // Pass 1: classify every point and compact the ground and obstacle returns. With the `planes` ground model the
  // valid returns are first kept with their zones, the model fitted, and then they are classified. The points are
  // cut into chunks (kPointChunk with several threads); each chunk writes its returns from its own first index on, and the chunks'
  // returns are then moved together in chunk order, so the lists are those of one pass in point order.
  const Parallel& par = *parallel_;
  PointPass pass;
  const Eigen::Matrix3f rot = sensor_pose_.rotation().cast<float>();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) pass.rot[3 * r + c] = rot(r, c);
  // Points relative to the table's sensor position (within kSensorMoveTolerance of the current one).
  pass.shift_x = static_cast<float>(sensor_pose_.translation().x() - table_sensor_x_);
  pass.shift_y = static_cast<float>(sensor_pose_.translation().y() - table_sensor_y_);
  pass.trans_z = static_cast<float>(sensor_pose_.translation().z());
  pass.min2 = static_cast<float>(params_.min_range * params_.min_range);
  pass.max2 = static_cast<float>(params_.max_range * params_.max_range);
  pass.inv_res = static_cast<float>(1.0 / geometry_.resolution);
  // Cell coordinates of a point relative to the sensor: (d + sensor − origin) / resolution.
  pass.cx0 = static_cast<float>((table_sensor_x_ - geometry_.origin_x) / geometry_.resolution);
  pass.cy0 = static_cast<float>((table_sensor_y_ - geometry_.origin_y) / geometry_.resolution);
  pass.width = geometry_.width;
  pass.fwidth = static_cast<float>(geometry_.width);
  pass.fheight = static_cast<float>(geometry_.height);
  pass.sector_scale = sector_scale_;
  pass.num_sectors = num_sectors_;
  // Self box relative to the table's sensor position.
  pass.self_min_x = static_cast<float>(params_.self_box_min_x - table_sensor_x_);
  pass.self_max_x = static_cast<float>(params_.self_box_max_x - table_sensor_x_);
  pass.self_min_y = static_cast<float>(params_.self_box_min_y - table_sensor_y_);
  pass.self_max_y = static_cast<float>(params_.self_box_max_y - table_sensor_y_);
  pass.tolerance = static_cast<float>(params_.ground_tolerance);
  pass.obstacle_min = static_cast<float>(params_.obstacle_min_height);
  pass.obstacle_max = static_cast<float>(params_.obstacle_max_height);
  pass.relative_limit = static_cast<float>(params_.relative_height_limit);
  pass.relative = relative;
  pass.shared = par.threads() > 1;
  pass.ground_sector = ground_sector_.data();
  pass.ground_range2 = ground_range2_.data();
  pass.obstacle_sector = obstacle_sector_.data();
  pass.obstacle_range2 = obstacle_range2_.data();
  pass.obstacle_cell = obstacle_cell_.data();
  pass.obstacle_xy = obstacle_points_.data();
  pass.obstacle_z = obstacle_z_.data();
  pass.cell_min_z = cell_min_z_.data();
  pass.ground = static_cast<float>(params_.ground_height);
  pass.data = points.data;
  pass.cols = points.width;
  pass.point_step = points.point_step;
  pass.row_step = points.row_step;
  pass.x_offset = points.x_offset;
  pass.y_offset = points.y_offset;
  pass.z_offset = points.z_offset;

  const bool planes = ground_kind_ != GroundModel::kFlat;  // a fitted model: `planes` or `zones`
  pass.planes = planes;
  if (planes && valid_dx_.size() < n_points)
  {
    valid_dx_.resize(n_points);
    valid_dy_.resize(n_points);
    valid_z_.resize(n_points);
    valid_zone_.resize(n_points);
  }
  float* const valid_dx = pass.valid_dx = valid_dx_.data();
  float* const valid_dy = pass.valid_dy = valid_dy_.data();
  float* const valid_z = pass.valid_z = valid_z_.data();
  std::uint16_t* const valid_zone = pass.valid_zone = valid_zone_.data();
  pass.fitter = &ground_;
  prepareStepBuffers(n_points, planes);
  const bool consensus = planes && params_.ground_consensus;
  pass.second = consensus ? &second_ : nullptr;
  pass.valid_zone2 = consensus ? valid_zone2_.data() : nullptr;
  pass.ambiguous = params_.ambiguous_unknown ? ambiguous_.data() : nullptr;
  pass.ground_seen = params_.ground_cells_free ? ground_seen_.data() : nullptr;
  pass.point_class = record_classes_ ? return_classes_.data() : nullptr;
  pass.obstacle_point = record_classes_ ? obstacle_point_.data() : nullptr;
  pass.valid_point = record_classes_ && planes ? valid_point_.data() : nullptr;
  // The lists do not depend on the chunks (each chunk's returns are in point order, and chunks are joined in order),
  // so one thread takes all the points in one chunk, with nothing to move.
  const std::size_t chunk_points = pass.shared ? kPointChunk : std::max<std::size_t>(1, n_points);
  const std::size_t point_chunks = chunkCount(n_points, chunk_points);
  chunk_returns_.assign(point_chunks, ChunkReturns{});
  ChunkReturns* const chunk_out = chunk_returns_.data();
  par.forChunks(point_chunks, [&](std::size_t c) {
    const PointPass m = pass;  // a local copy, kept in registers: a float store could alias the shared one
    ChunkReturns out;
    const std::size_t k0 = c * chunk_points, k1 = std::min(n_points, k0 + chunk_points);
    out.first = k0;
    std::size_t row = k0 / m.cols, col = k0 % m.cols;
    const std::uint8_t* p = m.data + row * m.row_step + col * m.point_step;
    for (std::size_t k = k0; k < k1; ++k)
    {
      const std::uint8_t* const point = p;
      if (++col == m.cols)
      {
        col = 0;
        ++row;
        p = m.data + row * m.row_step;
      }
      else
      {
        p += m.point_step;
      }
      const float px = readFloat(point + m.x_offset);
      const float py = readFloat(point + m.y_offset);
      const float pz = readFloat(point + m.z_offset);
      if (!(std::isfinite(px) && std::isfinite(py) && std::isfinite(pz)))
      {
        ++out.counts.non_finite;
        continue;
      }
      if (px == 0.0f && py == 0.0f && pz == 0.0f)
      {
        ++out.counts.no_return;
        continue;
      }
      const float dx = m.rot[0] * px + m.rot[1] * py + m.rot[2] * pz + m.shift_x;
      const float dy = m.rot[3] * px + m.rot[4] * py + m.rot[5] * pz + m.shift_y;
      const float z = m.rot[6] * px + m.rot[7] * py + m.rot[8] * pz + m.trans_z;
      const float r2 = dx * dx + dy * dy;
      if (r2 < m.min2)
      {
        ++out.counts.below_min;
        continue;
      }
      if (r2 > m.max2)
      {
        ++out.counts.beyond_max;
        continue;
      }
      if (dx > m.self_min_x && dx < m.self_max_x && dy > m.self_min_y && dy < m.self_max_y)
      {
        ++out.counts.self;
        continue;
      }
      if (m.planes)
      {
        const std::size_t v = k0 + out.valid++;
        m.valid_dx[v] = dx;
        m.valid_dy[v] = dy;
        m.valid_z[v] = z;
        m.valid_zone[v] = static_cast<std::uint16_t>(m.fitter->zoneOf(r2, turnFraction(dx, dy)));
        if (m.second) m.valid_zone2[v] = static_cast<std::uint16_t>(m.second->zoneOf(r2, turnFraction(dx, dy)));
        if (m.valid_point) m.valid_point[v] = static_cast<std::uint32_t>(k);
        continue;
      }
      m.classify(k, dx, dy, z, r2, m.ground, out);
    }
    chunk_out[c] = out;
  });
  ReturnCounts counts;
  std::size_t n_valid = 0;
  for (std::size_t c = 0; c < point_chunks; ++c)
  {
    const ChunkReturns& out = chunk_out[c];
    counts += out.counts;
    if (!planes) continue;
    moveSegment(valid_dx, 1, out.first, out.valid, n_valid);
    moveSegment(valid_dy, 1, out.first, out.valid, n_valid);
    moveSegment(valid_z, 1, out.first, out.valid, n_valid);
    moveSegment(valid_zone, 1, out.first, out.valid, n_valid);
    if (pass.second) moveSegment(pass.valid_zone2, 1, out.first, out.valid, n_valid);
    if (pass.valid_point) moveSegment(pass.valid_point, 1, out.first, out.valid, n_valid);
    n_valid += out.valid;
  }
  std::size_t n_chunks = point_chunks;
  if (planes)
  {
    st.ground_fit = ground_.fit(valid_dx, valid_dy, valid_z, valid_zone, n_valid, &par);
    if (pass.second) second_.fit(valid_dx, valid_dy, valid_z, pass.valid_zone2, n_valid, &par);
    const std::size_t chunk_valid = pass.shared ? kPointChunk : std::max<std::size_t>(1, n_valid);
    n_chunks = chunkCount(n_valid, chunk_valid);
    valid_returns_.assign(n_chunks, ChunkReturns{});
    ChunkReturns* const valid_out = valid_returns_.data();
    par.forChunks(n_chunks, [&](std::size_t c) {
      const PointPass m = pass;
      ChunkReturns out;
      const std::size_t v0 = c * chunk_valid, v1 = std::min(n_valid, v0 + chunk_valid);
      out.first = v0;
      for (std::size_t i = v0; i < v1; ++i)
      {
        const float dx = m.valid_dx[i], dy = m.valid_dy[i];
        const std::size_t point = m.valid_point ? m.valid_point[i] : 0;
        const float g = m.fitter->plane(m.valid_zone[i]).at(dx, dy);
        if (m.second && m.second->fitted(m.valid_zone2[i]))  // a zone the second model did not fit has no say
          m.classifyBoth(point, dx, dy, m.valid_z[i], dx * dx + dy * dy, g,
                         m.second->plane(m.valid_zone2[i]).at(dx, dy), out);
        else
          m.classify(point, dx, dy, m.valid_z[i], dx * dx + dy * dy, g, out);
      }
      valid_out[c] = out;
    });
    for (std::size_t c = 0; c < n_chunks; ++c) counts += valid_out[c].counts;
  }
  std::uint32_t* const ground_sector = pass.ground_sector;
  float* const ground_range2 = pass.ground_range2;
  std::uint32_t* const obstacle_sector = pass.obstacle_sector;
  float* const obstacle_range2 = pass.obstacle_range2;
  std::uint32_t* const obstacle_cell = pass.obstacle_cell;
  float* const obstacle_xy = pass.obstacle_xy;
  float* const obstacle_z = pass.obstacle_z;
  float* const cell_min_z = pass.cell_min_z;
  const int width = pass.width;
  const ChunkReturns* const classified = planes ? valid_returns_.data() : chunk_out;
  std::size_t n_ground = 0, n_obstacle = 0;
  for (std::size_t c = 0; c < n_chunks; ++c)
  {
    const ChunkReturns& out = classified[c];
    moveSegment(ground_sector, 1, out.first, out.ground, n_ground);
    moveSegment(ground_range2, 1, out.first, out.ground, n_ground);
    moveSegment(obstacle_sector, 1, out.first, out.obstacle, n_obstacle);
    moveSegment(obstacle_range2, 1, out.first, out.obstacle, n_obstacle);
    moveSegment(obstacle_cell, 1, out.first, out.obstacle, n_obstacle);
    moveSegment(obstacle_xy, 2, out.first, out.obstacle, n_obstacle);
    if (relative) moveSegment(obstacle_z, 1, out.first, out.obstacle, n_obstacle);
    if (pass.point_class) moveSegment(pass.obstacle_point, 1, out.first, out.obstacle, n_obstacle);
    n_ground += out.ground;
    n_obstacle += out.obstacle;
  }
  std::size_t low_relief = 0;
  if (relative)
  {
    // Relative obstacle height: keep a return only when it stands obstacle_min_height above the local lowest return.
    const float relief = static_cast<float>(params_.obstacle_min_height);
    const int height = geometry_.height;
    std::size_t kept = 0;
    for (std::size_t k = 0; k < n_obstacle; ++k)
    {
      const std::uint32_t cell = obstacle_cell[k];
      if (cell != kOutside && obstacle_z[k] < kInfinity)
      {
        const int x = static_cast<int>(cell % static_cast<std::uint32_t>(width));
        const int y = static_cast<int>(cell / static_cast<std::uint32_t>(width));
        float lowest = kInfinity;
        for (int ny = std::max(0, y - 1); ny <= std::min(height - 1, y + 1); ++ny)
          for (int nx = std::max(0, x - 1); nx <= std::min(width - 1, x + 1); ++nx)
            lowest = std::min(lowest, cell_min_z[ny * width + nx]);
        if (obstacle_z[k] - lowest < relief)
        {
          ++low_relief;
          if (pass.point_class) pass.point_class[pass.obstacle_point[k]] = ReturnClass::kLowRelief;
          if (pass.ambiguous) pass.ambiguous[cell] = 1;
          continue;
        }
      }
      if (pass.point_class) pass.obstacle_point[kept] = pass.obstacle_point[k];
      obstacle_sector[kept] = obstacle_sector[k];
      obstacle_range2[kept] = obstacle_range2[k];
      obstacle_cell[kept] = cell;
      obstacle_xy[2 * kept] = obstacle_xy[2 * k];
      obstacle_xy[2 * kept + 1] = obstacle_xy[2 * k + 1];
      ++kept;
    }
    n_obstacle = kept;
  }
  st.low_relief = low_relief;
  st.non_finite = counts.non_finite;
  st.no_return = counts.no_return;
  st.below_min_range = counts.below_min;
  st.beyond_max_range = counts.beyond_max;
  st.self_returns = counts.self;
  st.below_ground = counts.below_ground;
  st.height_gap = counts.gap;
  st.above_clearance = counts.above;
  st.ground = n_ground;
  st.disputed = counts.disputed;
  st.obstacle = n_obstacle - counts.disputed;

  // Pass 2: per sector, the nearest obstacle; the free limit is it or the farthest ground return before it.
  float* const obstacle2 = sector_obstacle2_.data();
  float* const free2 = sector_free2_.data();
  std::fill(sector_obstacle2_.begin(), sector_obstacle2_.end(), kInfinity);
  for (std::size_t k = 0; k < n_obstacle; ++k)
    obstacle2[obstacle_sector_[k]] = std::min(obstacle2[obstacle_sector_[k]], obstacle_range2_[k]);
  const float margin = static_cast<float>(params_.free_margin);
  for (std::size_t s = 0; s < sector_free2_.size(); ++s)
  {
    if (std::isinf(obstacle2[s]))
    {
      free2[s] = 0.0f;
      continue;
    }
    const float limit = std::max(0.0f, std::sqrt(obstacle2[s]) - margin);
    free2[s] = limit * limit;
  }
  for (std::size_t k = 0; k < n_ground; ++k)
  {
    const std::uint32_t s = ground_sector_[k];
    const float r2 = ground_range2_[k];
    if (r2 < obstacle2[s] && r2 > free2[s] && (margin == 0.0f || std::sqrt(r2) < std::sqrt(obstacle2[s]) - margin))
      free2[s] = r2;
  }

  float* const m_empty = grid.plane(FrameSG::kEmpty);
  float* const m_f = grid.plane(FrameSG::kF);
  float* const m_o = grid.plane(FrameSG::kO);
  float* const m_omega = grid.plane(FrameSG::kOmega);
  const std::size_t n = geometry_.numCells();
  par.forRange(n, kFillChunk, [&](std::size_t i0, std::size_t i1) {
    std::fill(m_empty + i0, m_empty + i1, 0.0f);
    std::fill(m_f + i0, m_f + i1, 0.0f);
    std::fill(m_o + i0, m_o + i1, 0.0f);
    std::fill(m_omega + i0, m_omega + i1, 1.0f);
  });
  // Every cell is in one sector's group, so the sectors' chunks write disjoint cells.
  const TableEntry* const table = table_.data();
  const std::size_t sectors = sector_free2_.size();
  sector_chunk_free_.assign(chunkCount(sectors, kSectorChunk), 0);
  std::size_t* const chunk_free = sector_chunk_free_.data();
  par.forRange(sectors, kSectorChunk, [&](std::size_t s0, std::size_t s1) {
    std::size_t count = 0;
    for (std::size_t s = s0; s < s1; ++s)
    {
      const float limit = free2[s];
      const std::uint32_t end = sector_begin_[s + 1];
      for (std::uint32_t k = sector_begin_[s]; k < end && table[k].range2 < limit; ++k)
      {
        const float f = table[k].mu_free;
        m_f[table[k].cell] = f;
        m_omega[table[k].cell] = 1.0f - f;
        count += f > 0.0f;
      }
    }
    chunk_free[s0 / kSectorChunk] = count;
  });
  std::size_t free_cells = 0;
  for (const std::size_t c : sector_chunk_free_) free_cells += c;
  if (pass.ground_seen) free_cells += fillGroundCells(m_f, m_omega);
  if (pass.ambiguous) free_cells -= clearAmbiguousFree(m_f, m_omega);

  const float mu_o = static_cast<float>(params_.mu_occupied);
  std::size_t occupied = 0;
  if (mu_o > 0.0f)
    for (std::size_t k = 0; k < n_obstacle; ++k)
    {
      const std::uint32_t i = obstacle_cell_[k];
      if (i == kOutside || i == kDisputed) continue;
      if (m_o[i] != 0.0f) continue;
      if (m_f[i] > 0.0f) --free_cells;
      m_f[i] = 0.0f;
      m_o[i] = mu_o;
      m_omega[i] = 1.0f - mu_o;
      ++occupied;
    }
  std::size_t kept = 0;
  const float sensor_x = static_cast<float>(table_sensor_x_), sensor_y = static_cast<float>(table_sensor_y_);
  for (std::size_t k = 0; k < n_obstacle; ++k)
  {
    if (obstacle_cell_[k] == kDisputed) continue;  // bounds free space only
    if (obstacle_cell_[k] == kOutside)
    {
      ++st.obstacle_outside_grid;
      continue;
    }
    obstacle_xy[2 * kept] = obstacle_xy[2 * k] + sensor_x;
    obstacle_xy[2 * kept + 1] = obstacle_xy[2 * k + 1] + sensor_y;
    ++kept;
  }
  obstacle_count_ = kept;
  st.occupied_cells = occupied;
  st.free_cells = free_cells;
  if (stats) *stats = st;
  return true;
}

}  // namespace core
}  // namespace map_aided_fusion

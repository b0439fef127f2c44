/**
 * @file scan_grid.hpp
 * @brief The ScanGrid sensor model (paper section 2.2, after Moras et al. 2010/2011): one lidar scan →
 *        masses m(F), m(O), m(Ω) per cell of a grid in the vehicle frame (`base_link`).
 *
 * Polar model, per azimuth sector seen from the sensor's position:
 * - every **obstacle** return (height above the ground within the obstacle band) marks its own cell
 *   occupied, m(O) = μ_O, so thin obstacles never vanish between sectors or cells;
 * - the nearest obstacle return of a sector bounds the free space of that sector: cells of the sector
 *   closer than it get m(F) = μ_F(r); cells beyond it stay unknown (m(Ω) = 1);
 * - **ground** returns (|z − ground| ≤ tolerance) are evidence of free space up to their range, when
 *   they are closer than the sector's nearest obstacle;
 * - returns above the clearance height (canopies, bridges), below the ground band, or in the gap
 *   between the ground band and the obstacle band are neither;
 * - invalid returns (NaN/inf, the (0, 0, 0) "no return" point, horizontal range outside
 *   [min_range, max_range], returns from the vehicle's own body inside the self-filter box) are never
 *   obstacles and are counted in ScanGridStats.
 *
 * Sectors tile the full turn from azimuth −180° (base_link axes), ceil(360 / azimuth_resolution_deg) of
 * them. Cells closer to the sensor than min_range are never free (the sensor cannot see there); a cell
 * holding an obstacle return is occupied even when the polar model calls it free.
 *
 * The Cartesian grid samples the polar model at each cell centre; the cell → (sector, range, μ_F(r))
 * table is computed once per (parameters, geometry, sensor position), not per scan. It lists the cells of
 * each sector by increasing range, so a scan only writes its free cells after resetting the planes.
 * The heights above are measured from the ground: z = ground_height with the paper's flat model, the plane of the
 * return's zone with the `planes` ground model (core/ground_model.hpp, the one place PCL is used).
 * ROS-free: Eigen and the standard library in this header.
 */
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "map_aided_fusion/core/parameters.hpp"
#include "map_aided_fusion/core/grid_geometry.hpp"
#include "map_aided_fusion/core/ground_model.hpp"
#include "map_aided_fusion/core/mass_grid.hpp"
#include "map_aided_fusion/core/parallel.hpp"
#include "map_aided_fusion/core/return_class.hpp"

namespace map_aided_fusion {
namespace core {

/// Parameters of the ScanGrid sensor model and of its grid; names as in config/scan_grid.yaml.
struct ScanGridParams
{
  // Grid (vehicle frame, base_link), centred on (grid_offset_x, grid_offset_y).
  // Every length below is bounded by 10 km (and the sensor pose by 1 km), so that no cell index, range or
  // angle leaves the range of float and int.
  double grid_resolution = 0.5;  ///< cell side, m, in [0.01, 10000]; the paper's 0.5 m
  double grid_size_x = 100.0;    ///< extent along x, m (≥ one cell, ≤ 10000)
  double grid_size_y = 100.0;    ///< extent along y, m (≥ one cell, ≤ 10000)
  double grid_offset_x = 0.0;    ///< x of the grid centre in base_link, m, in [−10000, 10000]
  double grid_offset_y = 0.0;    ///< y of the grid centre in base_link, m, in [−10000, 10000]

  // Polar model.
  double azimuth_resolution_deg = 0.25;  ///< width of an azimuth sector, degrees, in [0.01, 45]
  double min_range = 1.0;                ///< horizontal range below which a return is rejected, m (≥ 0)
  double max_range = 80.0;               ///< horizontal range beyond which a return is rejected, m (> min_range)

  // Self filter: returns strictly inside this base_link box (the vehicle's own body) are rejected.
  // The default empty box disables it.
  double self_box_min_x = 0.0;  ///< m
  double self_box_max_x = 0.0;  ///< m (≥ self_box_min_x)
  double self_box_min_y = 0.0;  ///< m
  double self_box_max_y = 0.0;  ///< m (≥ self_box_min_y)

  // Heights in base_link.
  double ground_height = 0.0;        ///< z of the ground surface in base_link, m
  double ground_tolerance = 0.2;     ///< a return with |z − ground_height| ≤ this is ground, m (≥ 0)
  double obstacle_min_height = 0.3;  ///< lowest obstacle return above the ground, m (≥ ground_tolerance)
  double obstacle_max_height = 2.5;  ///< clearance: returns higher above the ground are ignored, m (> obstacle_min_height)

  // Masses.
  double mu_free = 0.7;              ///< μ_F: free mass between the sensor and a return, in [0, 1]
  double mu_occupied = 0.8;          ///< μ_O: occupied mass of a cell holding an obstacle return, in [0, 1]
  double free_decay_length = 0.0;    ///< μ_F(r) = μ_F·exp(−r / L), m; 0 disables the decay (≥ 0)
  /**
   * Cells closer than this to a sector's nearest obstacle (in range) are left unknown rather than free, m (≥ 0):
   * a wall seen at a grazing angle or from a moving vehicle otherwise flickers between free and occupied in
   * its boundary cells, which the fusion reads as a moving object.
   */
  double free_margin = 0.0;
  /**
   * Step "relative obstacle height" (not in the paper), m above ground_height, in [0, 10000]; 0 disables it. A
   * return in the obstacle band but lower than this is an obstacle only when it also stands obstacle_min_height
   * above the lowest return of its own and the 8 neighbouring cells; otherwise it is neither ground nor obstacle
   * (counted as low_relief). On a street that is not flat (slope, camber, a raised pavement) ground returns 30–50 cm
   * above the vehicle's ground plane otherwise become obstacles that come and go from sweep to sweep, which the
   * fusion reads as motion. Returns higher than this are obstacles as before (a car roof seen from above has no lower
   * return around it).
   */
  double relative_height_limit = 0.8;
  /**
   * Step "ambiguous unknown" (not in the paper): a cell holding a return that is neither ground nor obstacle (in the
   * gap between the ground band and the obstacle band, dropped by the relative obstacle height, or disputed by step
   * ground consensus) gets no free mass:
   * what the sensor model cannot call ground or obstacle is unknown, not free.
   */
  bool ambiguous_unknown = true;
  /**
   * Step "ground cells free" (not in the paper): a cell holding a ground return gets free mass (μ_F at its centre's
   * range) even where it lies beyond the nearest obstacle of its sector. The polar model stops free space at a
   * sector's first obstacle, but a multi-beam lidar's upper beams pass over low or near objects and hit the ground
   * behind them: that ground was seen. Only the cells of the ground returns themselves are free, not the ray's path
   * to them (which passed above whatever stands there). Step ambiguous unknown and the obstacle returns still take a
   * cell's free mass back. Off by default: on the labelled real sequences it decides more of the ground F, but it
   * adds false V and labelled-obstacle cells decided F (doc/steps.md; `evaluate`'s row
   * `default_with_ground_cells_free`).
   */
  bool ground_cells_free = false;
  /**
   * Step "ground consensus" (not in the paper), with a fitted ground model: the other fitted model (`zones` for
   * `planes`, `planes` for `zones`) is fitted to the same returns, and a return that one model puts on the ground and
   * the other in the obstacle band is disputed: it bounds the free space of its sector (the ray ended there) but
   * gives no occupied mass, and with step ambiguous unknown its cell no free mass. Otherwise a return in the obstacle
   * band of either model is an obstacle, and the model of ground_model decides the rest. Two ground fits that
   * disagree about a return are two sources in conflict: the cell is left to ignorance rather than to the fusion,
   * which read the disagreement, sweep after sweep, as motion.
   */
  bool ground_consensus = true;

  /**
   * Step "deskew" (not in the paper): clouds whose points carry a time field are moved to the sensor's pose at
   * the cloud's stamp before the grid is built (core/deskew.hpp; done by the caller, which knows the motion).
   */
  bool deskew = true;
  double deskew_max_sweep_duration = 0.2;  ///< s, a point time beyond this after the stamp skips deskewing, (0, 10]

  /// Step "ground model" (not in the paper): `flat` (z = ground_height), `planes` (a RANSAC plane per zone of 4
  /// rings × ground_sectors) or `zones` (a least-squares plane per zone of a concentric zone model of 504 zones from
  /// its lowest returns; core/ground_model.hpp).
  std::string ground_model = "planes";
  int ground_sectors = 8;               ///< azimuth sectors per ring of the `planes` model, in [1, 64]
  double ground_max_slope_deg = 5.0;    ///< a fitted plane steeper than this (against the body) is refused, deg, [0, 60]
  int ground_min_points = 20;           ///< candidates and inliers a zone's fit needs, in [3, 100000]
  double ground_search_band = 0.6;      ///< m, a zone's candidates lie within this of the predicted ground, (0, 10]
  double ground_fit_tolerance = 0.08;   ///< m, RANSAC (`zones`: least-squares) inlier distance, (0, ground_search_band]
  double ground_zones_max_slope_deg = 20.0;  ///< `zones`: a steeper zone plane is refused, deg, [0, 60]

  /**
   * Threads of build(), in [0, kMaxThreads]; 0: every core. The grid, the obstacle returns and the counts are
   * bit-identical for any number (the points are cut into chunks that depend only on the cloud's size).
   */
  int threads = 0;

  /// ground_model parsed.
  GroundModel groundModel() const { return parseGroundModel(ground_model); }
  /// The `planes` model's parameters.
  GroundModelParams groundModelParams() const
  {
    return GroundModelParams{ ground_sectors,       ground_max_slope_deg, ground_min_points, ground_search_band,
                              ground_fit_tolerance, ground_height,        groundModel(), ground_zones_max_slope_deg };
  }

  /// The grid described by the grid_* parameters.
  GridGeometry geometry() const
  {
    return GridGeometry::centred(grid_size_x, grid_size_y, grid_resolution, grid_offset_x, grid_offset_y);
  }

  /// @throws ParameterError naming the first out-of-range parameter.
  void validate() const;
};

/**
 * @brief Calls get(name, field) for every parameter of @p p, with the names of config/scan_grid.yaml: one list
 *        shared by the ROS loader and the YAML loader of the offline tools.
 */
template <class Get>
void forEachParam(ScanGridParams& p, Get&& get)
{
  get("grid_resolution", p.grid_resolution, { "m", "ScanGrid cell side (the paper: 0.5 m)" });
  get("grid_size_x", p.grid_size_x, { "m", "ScanGrid extent along x (vehicle frame)" });
  get("grid_size_y", p.grid_size_y, { "m", "ScanGrid extent along y" });
  get("grid_offset_x", p.grid_offset_x, { "m", "x of the ScanGrid centre in the vehicle frame" });
  get("grid_offset_y", p.grid_offset_y, { "m", "y of the ScanGrid centre in the vehicle frame" });
  get("azimuth_resolution_deg", p.azimuth_resolution_deg, { "deg", "width of an azimuth sector of the polar model" });
  get("min_range", p.min_range, { "m", "returns nearer (horizontally) are rejected" });
  get("max_range", p.max_range, { "m", "returns farther (horizontally) are rejected" });
  get("self_box_min_x", p.self_box_min_x, { "m", "self filter: returns strictly inside this vehicle-frame box are the vehicle's own" });
  get("self_box_max_x", p.self_box_max_x, { "m", "see self_box_min_x" });
  get("self_box_min_y", p.self_box_min_y, { "m", "see self_box_min_x" });
  get("self_box_max_y", p.self_box_max_y, { "m", "see self_box_min_x" });
  get("ground_height", p.ground_height, { "m", "z of the ground in the vehicle frame (flat model; prediction of the planes model)" });
  get("ground_tolerance", p.ground_tolerance, { "m", "a return within this of the ground is ground" });
  get("obstacle_min_height", p.obstacle_min_height, { "m", "lowest obstacle return above the ground" });
  get("obstacle_max_height", p.obstacle_max_height, { "m", "returns higher above the ground are ignored (overhangs)" });
  get("mu_free", p.mu_free, { "", "μ_F: free mass between the sensor and a return" });
  get("mu_occupied", p.mu_occupied, { "", "μ_O: occupied mass of a cell holding an obstacle return" });
  get("free_decay_length", p.free_decay_length, { "m", "μ_F(r) = μ_F·exp(−r / L); 0: no decay" });
  get("free_margin", p.free_margin, { "m", "cells nearer than this to a sector's first obstacle stay unknown rather than free" });
  get("relative_height_limit", p.relative_height_limit, { "m", "step: a low obstacle return must stand obstacle_min_height above the lowest return around it; 0: off" });
  get("ambiguous_unknown", p.ambiguous_unknown, { "", "step: a cell holding a return neither ground nor obstacle gets no free mass" });
  get("ground_cells_free", p.ground_cells_free, { "", "step: a cell holding a ground return is free, also beyond its sector's nearest obstacle" });
  get("ground_consensus", p.ground_consensus, { "", "step: a return one fitted ground model calls ground and the other obstacle bounds free space but gives no mass" });
  get("deskew", p.deskew, { "", "step: clouds with a per-point time field are moved to the sensor pose at the stamp" });
  get("deskew_max_sweep_duration", p.deskew_max_sweep_duration, { "s", "a point time beyond this after the stamp skips deskewing" });
  get("ground_model", p.ground_model, { "", "flat (z = ground_height), planes (RANSAC planes per zone and scan) or zones (region-wise planes from the lowest returns, 504 zones)" });
  get("ground_sectors", p.ground_sectors, { "", "azimuth sectors per ring of the planes model (zones: fixed layout)" });
  get("ground_max_slope_deg", p.ground_max_slope_deg, { "deg", "a fitted plane steeper than this against the body is refused" });
  get("ground_min_points", p.ground_min_points, { "returns", "candidates and inliers a zone's fit needs" });
  get("ground_search_band", p.ground_search_band, { "m", "a zone's candidates lie within this of the predicted ground" });
  get("ground_fit_tolerance", p.ground_fit_tolerance, { "m", "RANSAC (zones: least-squares) inlier distance" });
  get("ground_zones_max_slope_deg", p.ground_zones_max_slope_deg, { "deg", "zones model: a zone plane steeper than this against the body is refused (an embankment is ground, a wall is not)" });
  get("threads", p.threads, { "", "threads of the ScanGrid builder; 0: every core (results identical for any value)" });
}

/// Largest grid the builder accepts (cells), to refuse absurd sizes before allocating.
constexpr std::size_t kScanGridMaxCells = std::size_t(1) << 26;

/**
 * @brief A read-only view of points stored as interleaved records (a sensor_msgs/PointCloud2 buffer or
 *        any array of structs): no copy. Point (row r, column c) starts at
 *        `data + r * row_step + c * point_step`; x, y, z are native-endian float32 at the given offsets.
 */
struct PointCloudView
{
  const std::uint8_t* data = nullptr;  ///< first byte of the first point
  std::size_t width = 0;               ///< points per row (all points when unorganized)
  std::size_t height = 1;              ///< rows (1 when unorganized)
  std::size_t point_step = 0;          ///< bytes between two points of a row
  std::size_t row_step = 0;            ///< bytes between two rows (≥ width · point_step)
  std::size_t x_offset = 0;            ///< byte offset of float32 x in a point
  std::size_t y_offset = 4;            ///< byte offset of float32 y in a point
  std::size_t z_offset = 8;            ///< byte offset of float32 z in a point

  std::size_t size() const { return width * height; }

  /// A view of @p count packed records of @p point_step bytes with x, y, z at offsets 0, 4, 8 (default).
  static PointCloudView packed(const void* data, std::size_t count, std::size_t point_step,
                               std::size_t x_offset = 0, std::size_t y_offset = 4, std::size_t z_offset = 8);

  /// True when the offsets fit in a point, row_step covers a row and data is set (or the view is empty).
  bool consistent() const;
};

/// Counts of one build. rejected() = invalid returns; the others are valid returns by class.
/// (ground_fit is the `planes` model's, when on.)
struct ScanGridStats
{
  std::size_t points = 0;               ///< points in the view
  std::size_t non_finite = 0;           ///< NaN or inf coordinate
  std::size_t no_return = 0;            ///< exactly (0, 0, 0) in the sensor frame
  std::size_t below_min_range = 0;      ///< horizontal range < min_range
  std::size_t beyond_max_range = 0;     ///< horizontal range > max_range
  std::size_t self_returns = 0;         ///< inside the self-filter box (the vehicle's body)
  std::size_t ground = 0;               ///< ground returns
  std::size_t obstacle = 0;             ///< obstacle returns
  std::size_t obstacle_outside_grid = 0;///< obstacle returns outside the grid (still bound free space)
  std::size_t below_ground = 0;         ///< below the ground band (neither)
  std::size_t height_gap = 0;           ///< between the ground band and the obstacle band (neither)
  std::size_t above_clearance = 0;      ///< above obstacle_max_height (neither)
  std::size_t low_relief = 0;           ///< in the obstacle band but too close to the local lowest return (neither)
  std::size_t disputed = 0;             ///< ground for one ground model, obstacle for the other (step ground consensus)
  std::size_t occupied_cells = 0;       ///< cells with m(O) = μ_O
  std::size_t free_cells = 0;           ///< cells with m(F) > 0
  GroundFitStats ground_fit;            ///< the `planes` ground model's fit (all 0 with `flat`)

  std::size_t rejected() const { return non_finite + no_return + below_min_range + beyond_max_range + self_returns; }
};

/**
 * @brief Builds ScanGrids. configure() precomputes the cell → (sector, range, μ_F) table; build() then
 *        only bins the points and fills the grid. Not thread-safe (keeps scratch buffers); one per thread.
 */
class ScanGridBuilder
{
public:
  ScanGridBuilder() = default;
  /// Same as configure().
  ScanGridBuilder(const ScanGridParams& params, const Eigen::Isometry3d& sensor_pose);

  /**
   * @brief Sets the parameters and the sensor's pose in base_link (sensor → base_link). The table is
   *        recomputed only when the grid, the sectors, the ranges, μ_F, the decay or the sensor's
   *        (x, y) changed (by more than 1 mm; smaller moves keep the polar centre of the table).
   * @throws ParameterError (parameters, or a grid above kScanGridMaxCells), leaving the builder unchanged.
   */
  void configure(const ScanGridParams& params, const Eigen::Isometry3d& sensor_pose);

  /// Changes only the sensor pose (recomputes the table when its (x, y) moved).
  void setSensorPose(const Eigen::Isometry3d& sensor_pose);

  /**
   * @brief Fills @p grid (reset to geometry() when its geometry differs) from @p points, given in the
   *        sensor frame. Writes m(∅) = 0, m(F), m(O), m(Ω) of every cell; the counter plane is left as is.
   *        An empty view gives an all-Ω grid.
   * @return false (grid untouched, stats.points set) when the builder is not configured or the view is
   *         not consistent().
   */
  bool build(const PointCloudView& points, ScanMassGrid& grid, ScanGridStats* stats = nullptr);

  /**
   * @brief The obstacle returns of the last build() that fall inside the grid, in the grid's frame (base_link):
   *        x0, y0, x1, y1, … metres. What the `point_occupancy` step of the MapGrid places in its own cells.
   */
  ObstaclePoints obstaclePoints() const { return ObstaclePoints{ obstacle_points_.data(), obstacle_count_ }; }

  /**
   * @brief Keep, from the next build() on, what the sensor model made of each point (returnClasses()). Off by
   *        default: scoring tools turn it on (a labelled sweep's points against the model's ground); the grid
   *        built is the same either way.
   */
  void recordReturnClasses(bool on) { record_classes_ = on; }
  /// With recordReturnClasses(true): one class per point of the last build()'s view, in the view's order.
  const std::vector<ReturnClass>& returnClasses() const { return return_classes_; }

  bool configured() const { return configured_; }
  const ScanGridParams& params() const { return params_; }
  const GridGeometry& geometry() const { return geometry_; }
  const Eigen::Isometry3d& sensorPose() const { return sensor_pose_; }
  int numSectors() const { return num_sectors_; }
  /// Azimuth sector (in [0, numSectors())) of a direction (dx, dy) from the sensor, as used by the table.
  int sectorOf(double dx, double dy) const;
  /// How many times the table was computed (for tests: it must not be per scan).
  std::size_t tableBuilds() const { return table_builds_; }
  /// The ground planes of the last build() with the `planes` model (zones of the sensor-centred model).
  const GroundPlaneFitter& groundModel() const { return ground_; }

private:
  void buildTable();
  /// Sizes the per-build buffers of the steps and of recordReturnClasses() for a view of @p n_points
  /// (@p fitted: a fitted ground model), or empties what is off.
  void prepareStepBuffers(std::size_t n_points, bool fitted);
  /// Step "ambiguous unknown": takes the free mass back from the cells ambiguous_ flags; returns how many were free.
  std::size_t clearAmbiguousFree(float* m_f, float* m_omega) const;
  /// Step "ground cells free": gives free mass to the cells ground_seen_ flags that have none; returns how many.
  std::size_t fillGroundCells(float* m_f, float* m_omega) const;

  ScanGridParams params_;
  GridGeometry geometry_;
  Eigen::Isometry3d sensor_pose_ = Eigen::Isometry3d::Identity();
  bool configured_ = false;
  int num_sectors_ = 0;
  float sector_scale_ = 0.0f;
  std::size_t table_builds_ = 0;
  double table_sensor_x_ = 0.0;  // sensor position the table was computed for
  double table_sensor_y_ = 0.0;

  /// A cell of the table: squared range from the sensor, index, μ_F(r).
  struct TableEntry
  {
    float range2;
    std::uint32_t cell;
    float mu_free;
  };
  // Table: the cells in [min_range, max_range] grouped by sector, each group sorted by range, so that
  // the free cells of a sector are a prefix of its group.
  std::vector<TableEntry> table_;
  std::vector<std::uint32_t> sector_begin_;  // group of sector s: [sector_begin_[s], sector_begin_[s + 1])

  // Scratch, reused between scans: per sector the squared range of the nearest obstacle and of the free
  // limit; the ground and obstacle returns of the scan, compacted (sector, squared range, cell).
  std::vector<float> sector_obstacle2_;
  std::vector<float> sector_free2_;
  std::vector<std::uint32_t> ground_sector_;
  std::vector<float> ground_range2_;
  std::vector<std::uint32_t> obstacle_sector_;
  std::vector<float> obstacle_range2_;
  std::vector<std::uint32_t> obstacle_cell_;
  std::vector<float> obstacle_points_;
  std::size_t obstacle_count_ = 0;
  std::vector<float> obstacle_z_;
  std::vector<float> cell_min_z_;
  // recordReturnClasses(): the class of each point, and the point index of each obstacle and valid return.
  bool record_classes_ = false;
  std::vector<ReturnClass> return_classes_;
  std::vector<std::uint8_t> ambiguous_;  // step "ambiguous unknown": per cell, holds an ambiguous return
  std::vector<std::uint8_t> ground_seen_;  // step "ground cells free": per cell, holds a ground return
  std::vector<std::uint32_t> obstacle_point_;
  std::vector<std::uint32_t> valid_point_;
  // The `planes` ground model: the valid returns (relative to the sensor) and their zones, then the fitter.
  GroundModel ground_kind_ = GroundModel::kFlat;
  std::vector<float> valid_dx_, valid_dy_, valid_z_;
  std::vector<std::uint16_t> valid_zone_;
  GroundPlaneFitter ground_;
  GroundPlaneFitter second_;  // step ground consensus: the other fitted model
  std::vector<std::uint16_t> valid_zone2_;

  // Threads of build() (ScanGridParams::threads) and what each chunk of points found.
  std::shared_ptr<const Parallel> parallel_;
  struct ReturnCounts
  {
    std::size_t non_finite = 0, no_return = 0, below_min = 0, beyond_max = 0, self = 0;
    std::size_t below_ground = 0, gap = 0, above = 0, disputed = 0;
    ReturnCounts& operator+=(const ReturnCounts& o)
    {
      disputed += o.disputed;
      non_finite += o.non_finite;
      no_return += o.no_return;
      below_min += o.below_min;
      beyond_max += o.beyond_max;
      self += o.self;
      below_ground += o.below_ground;
      gap += o.gap;
      above += o.above;
      return *this;
    }
  };
  /// A chunk's returns start at index `first` of each list (its first point or valid return).
  struct ChunkReturns
  {
    std::size_t first = 0, valid = 0, ground = 0, obstacle = 0;
    ReturnCounts counts;
  };
  std::vector<ChunkReturns> chunk_returns_, valid_returns_;
  std::vector<std::size_t> sector_chunk_free_;

};

}  // namespace core
}  // namespace map_aided_fusion

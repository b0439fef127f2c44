/**
 * @file ground_model.hpp
 * @brief Per-scan ground model (not in the paper): the ground/obstacle split of the ScanGrid against a ground
 *        that is not the flat plane z = ground_height (sloped streets, camber, vehicle pitch).
 *
 * `planes` cuts the plane around the sensor into zones, rings of outer radius kGroundRingEdges (the last ring
 * reaches max_range) times `ground_sectors` azimuth sectors, and fits one plane per zone with PCL's RANSAC
 * (`pcl::SACSegmentation`, SACMODEL_PLANE, deterministic seed), ring by ring outwards:
 * - a zone's candidates are its returns within `ground_search_band` of the predicted ground: the flat plane
 *   for the innermost ring, the plane of the zone inside it (same sector) for the others; at most
 *   kGroundMaxCandidates of them, evenly subsampled;
 * - the fit keeps the plane with the most candidates within `ground_fit_tolerance`, refined by least squares;
 * - a zone with fewer than `ground_min_points` candidates or inliers (`few_points`), or whose plane's normal
 *   is further than `ground_max_slope_deg` from vertical (a wall taken for ground, `too_steep`), keeps the
 *   predicted plane; when no zone of a scan fits, the scan uses the flat model (`flat_fallback`).
 *
 * `zones` is the region-wise ground fit of the ground-segmentation literature (the concentric zone model and
 * region-wise plane fit of Patchwork, Lim et al. 2021): many small zones, kZoneRingEdges × kZoneRingSectors (504),
 * finer near the sensor, each fitted by least squares (PCA) from its lowest returns, ring by ring outwards:
 * - a zone's returns lower than the predicted ground by more than `ground_search_band` are left out (reflections);
 * - seeds: the returns within kGroundSeedBand of the mean of its kGroundLowestPoints lowest returns; the plane of the
 *   seeds is refitted kGroundFitIterations times to the returns within `ground_fit_tolerance` of it;
 * - the plane is kept when `ground_min_points` returns support it, its normal is within `ground_zones_max_slope_deg`
 *   of vertical (an embankment is ground, a wall is not) and it continues the ground predicted from the zone inside it
 *   (same azimuth): at the zone's inner edge it starts at most `ground_search_band` above the predicted ground (a
 *   truck's bed, a loading dock or a wall's foot seen over a parked car is not ground however flat it is) and at most
 *   `ground_search_band` plus the rise of a `ground_zones_max_slope_deg` slope to its centroid below it (an embankment whose
 *   foot lies inside the zone), or it rises from the predicted ground inside the zone within it (an embankment whose
 *   foot lies there, where that zone kept the road's plane); otherwise the zone keeps the predicted plane;
 * - returns along one line (spread across it below kGroundLineRatio of the spread along it: one far lidar ring, the
 *   foot of a wall, a car's lower edge) only tell the ground's height: the plane keeps the predicted tilt, and it
 *   continues the predicted ground only within kGroundLineBand of it.
 * The returns are then split against the plane of their own zone. PCL stays inside ground_model.cpp.
 */
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace map_aided_fusion {
namespace core {

class Parallel;

/// How the ScanGrid finds the ground.
enum class GroundModel
{
  kFlat,    ///< z = ground_height everywhere (the paper)
  kPlanes,  ///< one RANSAC plane per zone (see the file comment)
  kZones,   ///< one least-squares plane per zone of a concentric zone model (see the file comment)
};

const char* toString(GroundModel model);
/// @throws ParameterError("ground_model") for an unknown name.
GroundModel parseGroundModel(const std::string& name);

/// Outer radii of the rings but the last (m, from the sensor); the last ring reaches max_range.
constexpr std::array<float, 3> kGroundRingEdges{ 10.0f, 20.0f, 40.0f };
constexpr int kGroundRings = static_cast<int>(kGroundRingEdges.size()) + 1;
/// Candidates a zone's fit uses at most (evenly subsampled beyond).
constexpr std::size_t kGroundMaxCandidates = 256;
/// RANSAC iterations per zone.
constexpr int kGroundRansacIterations = 60;

/// `zones`: outer radii of the rings but the last (m; the last ring reaches max_range): four concentric zones of 2, 4,
/// 4 and 4 rings, the radii of Patchwork's concentric zone model for a 64-beam lidar.
constexpr std::array<float, 13> kZoneRingEdges{ 7.5f,  12.4f, 14.8f, 17.2f, 19.6f, 22.0f, 26.9f,
                                                31.7f, 36.5f, 41.4f, 51.0f, 60.7f, 70.3f };
/// `zones`: azimuth sectors of each ring (16 near the sensor, 32, 54 where the rings are wide and far, 32 beyond).
constexpr std::array<int, 14> kZoneRingSectors{ 16, 16, 32, 32, 32, 32, 54, 54, 54, 54, 32, 32, 32, 32 };
/// `zones`: the lowest returns of a zone whose mean height starts its seeds.
constexpr std::size_t kGroundLowestPoints = 20;
/// `zones`: seeds lie within this of the mean height of the lowest returns, m.
constexpr float kGroundSeedBand = 0.15f;
/// `zones`: refits of a zone's plane to the returns within ground_fit_tolerance of it.
constexpr int kGroundFitIterations = 3;
/// `zones`: a zone's returns whose spread across their main direction is below this share of their spread along it
/// lie on a line (one far lidar ring, a wall's foot): their plane keeps the predicted tilt.
constexpr double kGroundLineRatio = 0.1;
/// `zones`: returns along a line continue the predicted ground only within this of it, m (a car's lower edge seen
/// without the ground under it is 0.3–0.5 m up; a far ring of the ground within a few centimetres).
constexpr double kGroundLineBand = 0.15;

/// Parameters of the `planes` and `zones` ground models (ScanGridParams carries them; names as in config/scan_grid.yaml).
struct GroundModelParams
{
  int sectors = 8;                ///< azimuth sectors per ring, in [1, 64]
  double max_slope_deg = 5.0;     ///< a fitted normal further from vertical is refused, deg, in [0, 60]
  int min_points = 20;            ///< candidates and inliers a zone needs, in [3, 100000]
  double search_band = 0.6;       ///< m, candidates lie within this of the predicted ground, (0, 10]
  double fit_tolerance = 0.08;    ///< m, RANSAC inlier distance, (0, search_band]
  double ground_height = 0.0;     ///< m, the flat ground (ScanGridParams::ground_height)
  GroundModel model = GroundModel::kPlanes;  ///< `planes` or `zones` (the layout of the zones and their fit)
  double zones_max_slope_deg = 20.0;  ///< `zones`: a fitted normal further from vertical is refused, deg, in [0, 60]
};

/// A ground plane z = a·dx + b·dy + c, with (dx, dy) relative to the sensor's horizontal position.
struct GroundPlane
{
  float a = 0.0f, b = 0.0f, c = 0.0f;
  float at(float dx, float dy) const { return a * dx + b * dy + c; }
};

/// Counts of one fit.
struct GroundFitStats
{
  std::size_t zones = 0;        ///< zones of the model
  std::size_t fitted = 0;       ///< zones with their own plane
  std::size_t few_points = 0;   ///< zones with too few candidates or inliers (predicted plane kept)
  std::size_t too_steep = 0;    ///< zones whose plane was too steep (predicted plane kept)
  std::size_t discontinuous = 0;  ///< `zones`: planes that do not continue the ground inside them (predicted kept)
  bool flat_fallback = false;   ///< no zone fitted: the scan used the flat model
};

/**
 * @brief Fits the `planes` ground model. Not thread-safe (scratch buffers); one per ScanGridBuilder.
 */
class GroundPlaneFitter
{
public:
  GroundPlaneFitter();
  ~GroundPlaneFitter();
  /// Copies the parameters and planes; the copy has its own PCL state.
  GroundPlaneFitter(const GroundPlaneFitter& other);
  GroundPlaneFitter& operator=(const GroundPlaneFitter& other);

  /// Parameters are assumed validated (ScanGridParams::validate()).
  void configure(const GroundModelParams& params);

  int numZones() const { return ring_first_.back(); }
  int numRings() const { return static_cast<int>(ring_sectors_.size()); }
  /// Zone of a return at (dx, dy) from the sensor, r2 = dx² + dy², whose direction is @p azimuth_fraction in [0, 1)
  /// of the turn (any monotonic measure of the azimuth; the ScanGrid's is exact at multiples of 45°).
  int zoneOf(float r2, float azimuth_fraction) const
  {
    const int rings = numRings();
    int ring = 0;
    while (ring < rings - 1 && r2 >= ring_edges2_[static_cast<std::size_t>(ring)]) ++ring;
    const int sectors = ring_sectors_[static_cast<std::size_t>(ring)];
    int s = static_cast<int>(azimuth_fraction * static_cast<float>(sectors));
    s = s < 0 ? 0 : (s >= sectors ? sectors - 1 : s);
    return ring_first_[static_cast<std::size_t>(ring)] + s;
  }

  /**
   * @brief Fits every zone from the returns (dx, dy relative to the sensor, z in base_link) and their zones.
   * @return the counts; plane(zone) is then valid for every zone.
   */
  GroundFitStats fit(const float* dx, const float* dy, const float* z, const std::uint16_t* zone, std::size_t n,
                     const Parallel* parallel = nullptr);

  const GroundPlane& plane(int zone) const { return planes_[static_cast<std::size_t>(zone)]; }
  /// True when the last fit() gave @p zone a plane of its own (not the one predicted from inside it).
  bool fitted(int zone) const { return own_[static_cast<std::size_t>(zone)] != 0; }
  const std::vector<GroundPlane>& planes() const { return planes_; }

private:
  struct Pcl;
  /// `planes`: RANSAC on the zone's candidates; true when the zone got its own plane (else counted in @p st).
  bool fitRansac(std::size_t zone, const GroundPlane& predicted, const float* dx, const float* dy, const float* z,
                 GroundFitStats& st);
  /// `zones`: a zone's scratch lists (one per zone of a ring, so that a ring's zones fit in parallel).
  struct ZoneScratch
  {
    std::vector<std::uint32_t> candidates, inliers;
  };
  /// `zones`: least squares from the zone's lowest returns; true when the zone got its own plane. Writes only
  /// planes_[zone], @p scratch and @p st: the zones of one ring may fit at once.
  bool fitLowest(std::size_t zone, const GroundPlane& predicted, float inner_from, float inner_radius, const float* dx,
                 const float* dy, const float* z, ZoneScratch& scratch, GroundFitStats& st);
  /// The zones of ring @p ring, one after the other or (with @p parallel) at once; their counts added to @p st.
  void fitRing(int ring, const GroundPlane& flat, const float* dx, const float* dy, const float* z,
               const Parallel* parallel, GroundFitStats& st);
  /// `zones`: the least-squares plane (normal, centroid) of zone @p zone's lowest returns; @p line when they lie on a
  /// line. False when too few returns support it.
  bool lowestPlane(std::size_t zone, const GroundPlane& predicted, const float* dx, const float* dy, const float* z,
                   Eigen::Vector3d& normal, Eigen::Vector3d& mean, bool& line, ZoneScratch& scratch) const;
  /// The zone of the ring inside @p ring that holds the middle of sector @p s of @p ring.
  std::size_t innerZone(int ring, int s) const;

  GroundModelParams params_;
  std::vector<float> ring_edges2_;   // outer radius² of every ring but the last
  std::vector<int> ring_sectors_;    // sectors of each ring
  std::vector<int> ring_first_{ 0 };  // first zone of each ring, then the number of zones
  std::vector<GroundPlane> planes_;
  std::vector<std::uint8_t> own_;  // per zone: fitted by the last fit()
  std::vector<std::uint32_t> zone_begin_, order_, candidates_;
  std::vector<ZoneScratch> scratch_;
  std::vector<GroundFitStats> ring_stats_;
  std::unique_ptr<Pcl> pcl_;
};

}  // namespace core
}  // namespace map_aided_fusion

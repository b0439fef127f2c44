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
 * The returns are then split against the plane of their own zone. PCL stays inside ground_model.cpp.
 */
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace map_aided_fusion {
namespace core {

/// How the ScanGrid finds the ground.
enum class GroundModel
{
  kFlat,    ///< z = ground_height everywhere (the paper)
  kPlanes,  ///< one RANSAC plane per zone (see the file comment)
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

/// Parameters of the `planes` ground model (ScanGridParams carries them; names as in config/scan_grid.yaml).
struct GroundModelParams
{
  int sectors = 8;                ///< azimuth sectors per ring, in [1, 64]
  double max_slope_deg = 5.0;     ///< a fitted normal further from vertical is refused, deg, in [0, 60]
  int min_points = 20;            ///< candidates and inliers a zone needs, in [3, 100000]
  double search_band = 0.6;       ///< m, candidates lie within this of the predicted ground, (0, 10]
  double fit_tolerance = 0.08;    ///< m, RANSAC inlier distance, (0, search_band]
  double ground_height = 0.0;     ///< m, the flat ground (ScanGridParams::ground_height)
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

  int numZones() const { return kGroundRings * sectors_; }
  /// Zone of a return at (dx, dy) from the sensor, r2 = dx² + dy², whose direction is @p azimuth_fraction in [0, 1)
  /// of the turn (any monotonic measure of the azimuth; the ScanGrid's is exact at multiples of 45°).
  int zoneOf(float r2, float azimuth_fraction) const
  {
    int ring = 0;
    while (ring < kGroundRings - 1 && r2 >= ring_edges2_[ring]) ++ring;
    int s = static_cast<int>(azimuth_fraction * static_cast<float>(sectors_));
    s = s < 0 ? 0 : (s >= sectors_ ? sectors_ - 1 : s);
    return ring * sectors_ + s;
  }

  /**
   * @brief Fits every zone from the returns (dx, dy relative to the sensor, z in base_link) and their zones.
   * @return the counts; plane(zone) is then valid for every zone.
   */
  GroundFitStats fit(const float* dx, const float* dy, const float* z, const std::uint16_t* zone, std::size_t n);

  const GroundPlane& plane(int zone) const { return planes_[static_cast<std::size_t>(zone)]; }
  const std::vector<GroundPlane>& planes() const { return planes_; }

private:
  struct Pcl;
  GroundModelParams params_;
  int sectors_ = 1;
  std::array<float, kGroundRings - 1> ring_edges2_{};
  std::vector<GroundPlane> planes_;
  std::vector<std::uint32_t> zone_begin_, order_;
  std::unique_ptr<Pcl> pcl_;
};

}  // namespace core
}  // namespace map_aided_fusion

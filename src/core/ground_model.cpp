#include "map_aided_fusion/core/ground_model.hpp"

#include <algorithm>
#include <cmath>

#include <pcl/ModelCoefficients.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/sample_consensus/method_types.h>
#include <pcl/sample_consensus/model_types.h>
#include <pcl/segmentation/sac_segmentation.h>

#include <Eigen/Eigenvalues>

#include "map_aided_fusion/core/parallel.hpp"
#include "map_aided_fusion/core/parameters.hpp"

namespace map_aided_fusion {
namespace core {

namespace {
constexpr double kDegToRad = 3.14159265358979323846 / 180.0;
constexpr float kMinNormalZ = 1e-3f;
}  // namespace

const char* toString(GroundModel model)
{
  return model == GroundModel::kPlanes ? "planes" : model == GroundModel::kZones ? "zones" : "flat";
}

GroundModel parseGroundModel(const std::string& name)
{
  if (name == "flat") return GroundModel::kFlat;
  if (name == "planes") return GroundModel::kPlanes;
  if (name == "zones") return GroundModel::kZones;
  throw ParameterError("ground_model", "unknown model '" + name + "' (flat, planes, zones)");
}

struct GroundPlaneFitter::Pcl
{
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud{ new pcl::PointCloud<pcl::PointXYZ> };
  pcl::SACSegmentation<pcl::PointXYZ> seg;
  pcl::PointIndices inliers;
  pcl::ModelCoefficients coefficients;
};

GroundPlaneFitter::GroundPlaneFitter() : pcl_(std::make_unique<Pcl>()) {}
GroundPlaneFitter::~GroundPlaneFitter() = default;

GroundPlaneFitter::GroundPlaneFitter(const GroundPlaneFitter& other) : pcl_(std::make_unique<Pcl>())
{
  *this = other;
}

GroundPlaneFitter& GroundPlaneFitter::operator=(const GroundPlaneFitter& other)
{
  if (this == &other) return *this;
  configure(other.params_);
  planes_ = other.planes_;
  own_ = other.own_;
  return *this;
}

void GroundPlaneFitter::configure(const GroundModelParams& params)
{
  params_ = params;
  ring_edges2_.clear();
  ring_sectors_.clear();
  if (params.model == GroundModel::kZones)
  {
    for (const float e : kZoneRingEdges) ring_edges2_.push_back(e * e);
    ring_sectors_.assign(kZoneRingSectors.begin(), kZoneRingSectors.end());
  }
  else
  {
    for (const float e : kGroundRingEdges) ring_edges2_.push_back(e * e);
    ring_sectors_.assign(kGroundRings, std::max(1, params.sectors));
  }
  ring_first_.assign(1, 0);
  for (const int n : ring_sectors_) ring_first_.push_back(ring_first_.back() + n);
  planes_.assign(static_cast<std::size_t>(numZones()), GroundPlane{ 0.0f, 0.0f, static_cast<float>(params.ground_height) });
  own_.assign(static_cast<std::size_t>(numZones()), 0);
  pcl_->seg.setOptimizeCoefficients(true);
  pcl_->seg.setModelType(pcl::SACMODEL_PLANE);
  pcl_->seg.setMethodType(pcl::SAC_RANSAC);
  pcl_->seg.setMaxIterations(kGroundRansacIterations);
  pcl_->seg.setDistanceThreshold(params.fit_tolerance);
}

GroundFitStats GroundPlaneFitter::fit(const float* dx, const float* dy, const float* z, const std::uint16_t* zone,
                                      std::size_t n, const Parallel* parallel)
{
  GroundFitStats st;
  const std::size_t zones = static_cast<std::size_t>(numZones());
  st.zones = zones;
  const GroundPlane flat{ 0.0f, 0.0f, static_cast<float>(params_.ground_height) };
  planes_.assign(zones, flat);
  own_.assign(zones, 0);

  zone_begin_.assign(zones + 1, 0);
  for (std::size_t i = 0; i < n; ++i) ++zone_begin_[zone[i] + 1u];
  for (std::size_t k = 0; k < zones; ++k) zone_begin_[k + 1] += zone_begin_[k];
  order_.resize(n);
  {
    std::vector<std::uint32_t> next(zone_begin_.begin(), zone_begin_.end() - 1);
    for (std::size_t i = 0; i < n; ++i) order_[next[zone[i]]++] = static_cast<std::uint32_t>(i);
  }

  for (int ring = 0; ring < numRings(); ++ring) fitRing(ring, flat, dx, dy, z, parallel, st);
  if (st.fitted == 0)
  {
    planes_.assign(zones, flat);
    st.flat_fallback = true;
  }
  return st;
}

void GroundPlaneFitter::fitRing(int ring, const GroundPlane& flat, const float* dx, const float* dy, const float* z,
                                const Parallel* parallel, GroundFitStats& st)
{
  const float inner_radius = ring == 0 ? 0.0f : std::sqrt(ring_edges2_[static_cast<std::size_t>(ring - 1)]);
  const float inner_from = ring < 2 ? 0.0f : std::sqrt(ring_edges2_[static_cast<std::size_t>(ring - 2)]);
  const std::size_t sectors = static_cast<std::size_t>(ring_sectors_[static_cast<std::size_t>(ring)]);
  const std::size_t first = static_cast<std::size_t>(ring_first_[static_cast<std::size_t>(ring)]);
  if (params_.model != GroundModel::kZones)
  {
    for (std::size_t s = 0; s < sectors; ++s)  // PCL's RANSAC keeps state: one zone after the other
    {
      const std::size_t k = first + s;
      const GroundPlane predicted = ring == 0 ? flat : planes_[innerZone(ring, static_cast<int>(s))];
      planes_[k] = predicted;
      own_[k] = fitRansac(k, predicted, dx, dy, z, st);
      st.fitted += own_[k];
    }
    return;
  }
  // A zone reads the planes of the ring inside it and writes its own: a ring's zones fit at once, each with its own
  // scratch and counts, added in zone order (the same planes and counts for any thread count).
  if (scratch_.size() < sectors) scratch_.resize(sectors);
  ring_stats_.assign(sectors, GroundFitStats{});
  const auto one = [&](std::size_t s) {
    const std::size_t k = first + s;
    const GroundPlane predicted = ring == 0 ? flat : planes_[innerZone(ring, static_cast<int>(s))];
    planes_[k] = predicted;
    own_[k] = fitLowest(k, predicted, inner_from, inner_radius, dx, dy, z, scratch_[s], ring_stats_[s]);
  };
  if (parallel && parallel->threads() > 1)
    parallel->forChunks(sectors, one);
  else
    for (std::size_t s = 0; s < sectors; ++s) one(s);
  for (std::size_t s = 0; s < sectors; ++s)
  {
    st.fitted += own_[first + s];
    st.few_points += ring_stats_[s].few_points;
    st.too_steep += ring_stats_[s].too_steep;
    st.discontinuous += ring_stats_[s].discontinuous;
  }
}

std::size_t GroundPlaneFitter::innerZone(int ring, int s) const
{
  const int outer = ring_sectors_[static_cast<std::size_t>(ring)];
  const int inner = ring_sectors_[static_cast<std::size_t>(ring - 1)];
  const int si = std::min(inner - 1, ((2 * s + 1) * inner) / (2 * outer));
  return static_cast<std::size_t>(ring_first_[static_cast<std::size_t>(ring - 1)] + si);
}

bool GroundPlaneFitter::fitRansac(std::size_t k, const GroundPlane& predicted, const float* dx, const float* dy,
                                  const float* z, GroundFitStats& st)
{
  const float band = static_cast<float>(params_.search_band);
  const float min_normal_z = std::max(kMinNormalZ, static_cast<float>(std::cos(params_.max_slope_deg * kDegToRad)));
  const std::size_t min_points = static_cast<std::size_t>(params_.min_points);
  pcl::PointCloud<pcl::PointXYZ>& cloud = *pcl_->cloud;
  candidates_.clear();
  for (std::uint32_t j = zone_begin_[k]; j < zone_begin_[k + 1]; ++j)
  {
    const std::uint32_t i = order_[j];
    if (std::fabs(z[i] - predicted.at(dx[i], dy[i])) <= band) candidates_.push_back(i);
  }
  if (candidates_.size() < min_points)
  {
    ++st.few_points;
    return false;
  }
  const std::size_t stride = (candidates_.size() + kGroundMaxCandidates - 1) / kGroundMaxCandidates;
  cloud.clear();
  for (std::size_t j = 0; j < candidates_.size(); j += stride)
  {
    const std::uint32_t i = candidates_[j];
    cloud.push_back(pcl::PointXYZ(dx[i], dy[i], z[i]));
  }
  pcl_->seg.setInputCloud(pcl_->cloud);
  pcl_->seg.segment(pcl_->inliers, pcl_->coefficients);
  const std::vector<float>& c = pcl_->coefficients.values;
  if (pcl_->inliers.indices.size() < std::min(min_points, cloud.size()) || c.size() != 4)
  {
    ++st.few_points;
    return false;
  }
  const float norm = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
  if (!(norm > 0.0f) || !(std::fabs(c[2]) / norm >= min_normal_z))
  {
    ++st.too_steep;
    return false;
  }
  planes_[k] = GroundPlane{ -c[0] / c[2], -c[1] / c[2], -c[3] / c[2] };
  return true;
}

namespace {

/// The least-squares plane (PCA) of returns @p idx: false when they are fewer than 3 or all at one point.
/// @p line: true when they lie along a line (their spread across it is below kGroundLineRatio of the spread
/// along it), so that the plane's tilt across the line is not known.
bool pcaPlane(const std::vector<std::uint32_t>& idx, const float* dx, const float* dy, const float* z,
              Eigen::Vector3d& normal, Eigen::Vector3d& mean, bool* line = nullptr)
{
  if (idx.size() < 3) return false;
  mean.setZero();
  for (const std::uint32_t i : idx) mean += Eigen::Vector3d(dx[i], dy[i], z[i]);
  mean /= static_cast<double>(idx.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const std::uint32_t i : idx)
  {
    const Eigen::Vector3d d = Eigen::Vector3d(dx[i], dy[i], z[i]) - mean;
    cov.noalias() += d * d.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(cov);
  if (eig.info() != Eigen::Success || !(eig.eigenvalues()(1) > 0.0)) return false;
  normal = eig.eigenvectors().col(0);
  if (normal.z() < 0.0) normal = -normal;
  if (line) *line = eig.eigenvalues()(1) < kGroundLineRatio * kGroundLineRatio * eig.eigenvalues()(2);
  return normal.allFinite();
}


/// Whether @p plane, fitted to returns of centroid @p mean in a zone whose inner edge is @p inner_radius from the
/// sensor, continues @p predicted, the ground of the zone within (from @p inner_from to inner_radius). At the zone's
/// inner edge, on the centroid's direction, the plane may start at most @p band above the predicted ground (a
/// platform, a wall's foot seen over an occluder), and below it by at most band plus what a slope of @p max_slope
/// (rad) rises from there to the centroid (an embankment whose foot lies inside the zone). One that starts higher
/// continues the ground only when it rises from it inside the zone within (an embankment whose foot lies there,
/// where that zone kept the road's plane).
bool continuesGround(const GroundPlane& plane, const GroundPlane& predicted, const Eigen::Vector3d& mean,
                     double inner_from, double inner_radius, double band, double max_slope)
{
  const double r = std::hypot(mean.x(), mean.y());
  const double ux = r > 0.0 ? mean.x() / r : 1.0, uy = r > 0.0 ? mean.y() / r : 0.0;
  // Along the centroid's direction, plane − predicted = rise · s + offset at s metres from the sensor.
  const double rise = (static_cast<double>(plane.a) - predicted.a) * ux + (static_cast<double>(plane.b) - predicted.b) * uy;
  const double offset = static_cast<double>(plane.c) - predicted.c;
  const double edge = std::min(r, inner_radius);
  const double step = rise * edge + offset;
  const double below = band + std::tan(max_slope) * std::max(0.0, r - edge);
  if (step <= band && step >= -below) return true;
  const double foot = rise > 0.0 ? -offset / rise : -1.0;
  return rise > 0.0 && foot >= inner_from && foot <= edge;
}

}  // namespace

bool GroundPlaneFitter::lowestPlane(std::size_t k, const GroundPlane& predicted, const float* dx, const float* dy,
                                    const float* z, Eigen::Vector3d& normal, Eigen::Vector3d& mean, bool& line,
                                    ZoneScratch& scratch) const
{
  std::vector<std::uint32_t>& candidates = scratch.candidates;
  std::vector<std::uint32_t>& inliers = scratch.inliers;
  const float band = static_cast<float>(params_.search_band);
  const std::size_t min_points = static_cast<std::size_t>(params_.min_points);
  // The zone's returns, reflections far below the predicted ground left out, lowest first.
  candidates.clear();
  for (std::uint32_t j = zone_begin_[k]; j < zone_begin_[k + 1]; ++j)
  {
    const std::uint32_t i = order_[j];
    if (z[i] >= predicted.at(dx[i], dy[i]) - band) candidates.push_back(i);
  }
  if (candidates.size() < min_points) return false;
  std::sort(candidates.begin(), candidates.end(),
            [z](std::uint32_t a, std::uint32_t b) { return z[a] < z[b] || (z[a] == z[b] && a < b); });
  const std::size_t lowest = std::min(kGroundLowestPoints, candidates.size());
  double lpr = 0.0;
  for (std::size_t j = 0; j < lowest; ++j) lpr += z[candidates[j]];
  lpr /= static_cast<double>(lowest);
  inliers.clear();
  for (const std::uint32_t i : candidates)
  {
    if (z[i] >= lpr + kGroundSeedBand) break;
    inliers.push_back(i);
  }
  for (int it = 0; it < kGroundFitIterations; ++it)
  {
    if (!pcaPlane(inliers, dx, dy, z, normal, mean)) break;
    const double d = -normal.dot(mean);
    inliers.clear();
    for (const std::uint32_t i : candidates)
      if (std::abs(normal.x() * dx[i] + normal.y() * dy[i] + normal.z() * z[i] + d) <= params_.fit_tolerance)
        inliers.push_back(i);
  }
  return inliers.size() >= min_points && pcaPlane(inliers, dx, dy, z, normal, mean, &line);
}

bool GroundPlaneFitter::fitLowest(std::size_t k, const GroundPlane& predicted, float inner_from, float inner_radius,
                                  const float* dx, const float* dy, const float* z, ZoneScratch& scratch,
                                  GroundFitStats& st)
{
  Eigen::Vector3d normal, mean;
  bool line = false;
  if (!lowestPlane(k, predicted, dx, dy, z, normal, mean, line, scratch))
  {
    ++st.few_points;
    return false;
  }
  const double max_slope = params_.zones_max_slope_deg * kDegToRad;
  GroundPlane plane;
  if (line)
  {
    // Returns along one line (one lidar ring far away, a wall's foot): only their height is known; the plane keeps
    // the predicted tilt.
    plane = GroundPlane{ predicted.a, predicted.b,
                         static_cast<float>(mean.z() - predicted.a * mean.x() - predicted.b * mean.y()) };
  }
  else
  {
    if (!(normal.z() >= std::max<double>(kMinNormalZ, std::cos(max_slope))))
    {
      ++st.too_steep;
      return false;
    }
    plane = GroundPlane{ static_cast<float>(-normal.x() / normal.z()), static_cast<float>(-normal.y() / normal.z()),
                         static_cast<float>(normal.dot(mean) / normal.z()) };
  }
  // Returns along a line tell no tilt, so nothing tells a lifted line (an object's lower edge with no ground seen
  // under it) from the ground: such a line continues the ground only within kGroundLineBand of it.
  const double band = line ? kGroundLineBand : params_.search_band;
  if (!continuesGround(plane, predicted, mean, inner_from, inner_radius, band, line ? 0.0 : max_slope))
  {
    ++st.discontinuous;
    return false;
  }
  planes_[k] = plane;
  return true;
}

}  // namespace core
}  // namespace map_aided_fusion

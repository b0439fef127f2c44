#include "map_aided_fusion/core/ground_model.hpp"

#include <algorithm>
#include <cmath>

#include <pcl/ModelCoefficients.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/sample_consensus/method_types.h>
#include <pcl/sample_consensus/model_types.h>
#include <pcl/segmentation/sac_segmentation.h>

#include "map_aided_fusion/core/parameters.hpp"

namespace map_aided_fusion {
namespace core {

namespace {
constexpr double kDegToRad = 3.14159265358979323846 / 180.0;
constexpr float kMinNormalZ = 1e-3f;
}  // namespace

const char* toString(GroundModel model) { return model == GroundModel::kPlanes ? "planes" : "flat"; }

GroundModel parseGroundModel(const std::string& name)
{
  if (name == "flat") return GroundModel::kFlat;
  if (name == "planes") return GroundModel::kPlanes;
  throw ParameterError("ground_model", "unknown model '" + name + "' (flat, planes)");
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
  return *this;
}

void GroundPlaneFitter::configure(const GroundModelParams& params)
{
  params_ = params;
  sectors_ = std::max(1, params.sectors);
  for (std::size_t k = 0; k < ring_edges2_.size(); ++k) ring_edges2_[k] = kGroundRingEdges[k] * kGroundRingEdges[k];
  planes_.assign(static_cast<std::size_t>(numZones()), GroundPlane{ 0.0f, 0.0f, static_cast<float>(params.ground_height) });
  pcl_->seg.setOptimizeCoefficients(true);
  pcl_->seg.setModelType(pcl::SACMODEL_PLANE);
  pcl_->seg.setMethodType(pcl::SAC_RANSAC);
  pcl_->seg.setMaxIterations(kGroundRansacIterations);
  pcl_->seg.setDistanceThreshold(params.fit_tolerance);
}

GroundFitStats GroundPlaneFitter::fit(const float* dx, const float* dy, const float* z, const std::uint16_t* zone,
                                      std::size_t n)
{
  GroundFitStats st;
  const std::size_t zones = static_cast<std::size_t>(numZones());
  st.zones = zones;
  const GroundPlane flat{ 0.0f, 0.0f, static_cast<float>(params_.ground_height) };
  planes_.assign(zones, flat);

  zone_begin_.assign(zones + 1, 0);
  for (std::size_t i = 0; i < n; ++i) ++zone_begin_[zone[i] + 1u];
  for (std::size_t k = 0; k < zones; ++k) zone_begin_[k + 1] += zone_begin_[k];
  order_.resize(n);
  {
    std::vector<std::uint32_t> next(zone_begin_.begin(), zone_begin_.end() - 1);
    for (std::size_t i = 0; i < n; ++i) order_[next[zone[i]]++] = static_cast<std::uint32_t>(i);
  }

  const float band = static_cast<float>(params_.search_band);
  const float min_normal_z = std::max(kMinNormalZ, static_cast<float>(std::cos(params_.max_slope_deg * kDegToRad)));
  const std::size_t min_points = static_cast<std::size_t>(params_.min_points);
  pcl::PointCloud<pcl::PointXYZ>& cloud = *pcl_->cloud;
  std::vector<std::uint32_t> candidates;
  for (int ring = 0; ring < kGroundRings; ++ring)
    for (int s = 0; s < sectors_; ++s)
    {
      const std::size_t k = static_cast<std::size_t>(ring * sectors_ + s);
      const GroundPlane predicted = ring == 0 ? flat : planes_[k - static_cast<std::size_t>(sectors_)];
      planes_[k] = predicted;
      candidates.clear();
      for (std::uint32_t j = zone_begin_[k]; j < zone_begin_[k + 1]; ++j)
      {
        const std::uint32_t i = order_[j];
        if (std::fabs(z[i] - predicted.at(dx[i], dy[i])) <= band) candidates.push_back(i);
      }
      if (candidates.size() < min_points)
      {
        ++st.few_points;
        continue;
      }
      const std::size_t stride = (candidates.size() + kGroundMaxCandidates - 1) / kGroundMaxCandidates;
      cloud.clear();
      for (std::size_t j = 0; j < candidates.size(); j += stride)
      {
        const std::uint32_t i = candidates[j];
        cloud.push_back(pcl::PointXYZ(dx[i], dy[i], z[i]));
      }
      pcl_->seg.setInputCloud(pcl_->cloud);
      pcl_->seg.segment(pcl_->inliers, pcl_->coefficients);
      const std::vector<float>& c = pcl_->coefficients.values;
      if (pcl_->inliers.indices.size() < std::min(min_points, cloud.size()) || c.size() != 4)
      {
        ++st.few_points;
        continue;
      }
      const float norm = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
      if (!(norm > 0.0f) || !(std::fabs(c[2]) / norm >= min_normal_z))
      {
        ++st.too_steep;
        continue;
      }
      planes_[k] = GroundPlane{ -c[0] / c[2], -c[1] / c[2], -c[3] / c[2] };
      ++st.fitted;
    }
  if (st.fitted == 0)
  {
    planes_.assign(zones, flat);
    st.flat_fallback = true;
  }
  return st;
}

}  // namespace core
}  // namespace map_aided_fusion

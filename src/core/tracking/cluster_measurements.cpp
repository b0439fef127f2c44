#include "map_aided_fusion/core/tracking/cluster_measurements.hpp"

#include <algorithm>
#include <utility>

#include "map_aided_fusion/core/tracking/clustering.hpp"
#include "map_aided_fusion/core/tracking/shape_fit.hpp"

namespace map_aided_fusion {
namespace core {

namespace {

/// The diagonal of the axis-aligned bounding box of @p points[@p idx] (m).
double boxDiagonal(const std::vector<Point2>& points, const std::vector<int>& idx)
{
  double lx = 1e300, ly = 1e300, hx = -1e300, hy = -1e300;
  for (int i : idx)
  {
    lx = std::min(lx, points[i].x);
    ly = std::min(ly, points[i].y);
    hx = std::max(hx, points[i].x);
    hy = std::max(hy, points[i].y);
  }
  return std::hypot(hx - lx, hy - ly);
}

}  // namespace

MeasurementModelParams measurementModelOf(const TrackerParams& p)
{
  return MeasurementModelParams{ p.measurement_sigma, p.extent_sigma, p.steps.hidden_ends,
                                 kHiddenEndsSigma,   p.steps.open_anchor, p.steps.far_growth };
}

std::vector<Measurement> clusterReturns(const std::vector<Point2>& points, const TrackerParams& p,
                                        const std::vector<std::uint8_t>* background)
{
  std::vector<std::vector<int>> clusters = connectedClusters(points, 0.5 * p.cluster_distance);
  std::vector<std::pair<int, Measurement>> ordered;  // by first cell, for a result independent of hashing
  std::vector<int> split;  // step background split: the returns off background of the clusters too large
  auto tooLarge = [&](const std::vector<int>& idx) {
    if (!background || !p.steps.background_split) return;
    for (int i : idx)
      if (!(*background)[i]) split.push_back(i);
  };
  // A cluster's extent along any axis is at most its bounding box's diagonal.
  const double smallest_limit = std::min(p.max_object_length, p.max_object_width);
  auto mayBeTooLarge = [&](const std::vector<int>& idx) { return boxDiagonal(points, idx) > smallest_limit; };
  BoxFitParams fit;
  fit.enabled = p.steps.box_fit;
  fit.max_length = p.max_object_length;
  for (std::vector<int>& idx : clusters)
  {
    if (static_cast<int>(idx.size()) < p.min_cluster_points) continue;
    bool on_background_mostly = false;
    if (background && p.background_share < 1.0)
    {
      std::size_t on_background = 0;
      for (int i : idx) on_background += (*background)[i] != 0;
      on_background_mostly = static_cast<double>(on_background) > p.background_share * static_cast<double>(idx.size());
      // Step background split needs the extents of such a cluster only when it may be too large.
      if (on_background_mostly && (!p.steps.background_split || !mayBeTooLarge(idx))) continue;
    }
    const ClusterBox box = fitClusterBox(points, idx, fit);
    if (box.length() > p.max_object_length || box.width() > p.max_object_width)
    {
      tooLarge(idx);
      continue;
    }
    if (on_background_mostly) continue;
    const int first = idx.front();  // in point order: the smallest
    ordered.emplace_back(first, measurementOf(box, std::move(idx), measurementModelOf(p)));
  }
  if (split.size() >= static_cast<std::size_t>(p.min_cluster_points))
  {
    std::vector<Point2> sub(split.size());
    for (std::size_t k = 0; k < split.size(); ++k) sub[k] = points[split[k]];
    for (Measurement& m : clusterReturns(sub, p, nullptr))
    {
      if (m.length > p.pedestrian_size || m.width > p.pedestrian_size) continue;
      m.split = true;
      for (int& i : m.returns) i = split[i];
      const int first = *std::min_element(m.returns.begin(), m.returns.end());
      ordered.emplace_back(first, std::move(m));
    }
  }
  std::vector<std::size_t> order(ordered.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return ordered[a].first < ordered[b].first; });
  std::vector<Measurement> out;
  out.reserve(ordered.size());
  for (const std::size_t k : order) out.push_back(std::move(ordered[k].second));
  return out;
}

}  // namespace core
}  // namespace map_aided_fusion

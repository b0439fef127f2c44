#include "map_aided_fusion/core/tracking/shape_fit.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

namespace map_aided_fusion {
namespace core {

Eigen::Vector2d fittedAxis(const std::vector<Point2>& points, const std::vector<int>& idx, const Eigen::Vector2d& mean,
                           const Eigen::Vector2d& principal, const BoxFitParams& p)
{
  const std::size_t n = idx.size();
  std::vector<double> dx(n), dy(n), u(n), v(n);
  for (std::size_t i = 0; i < n; ++i)
  {
    dx[i] = points[idx[i]].x - mean.x();
    dy[i] = points[idx[i]].y - mean.y();
  }
  const int tries = static_cast<int>(std::ceil(90.0 / p.step_deg - 1e-9));
  const double closeness = p.closeness;
  double best_score = -1.0, best_angle = 0.0, best_lu = 0.0, best_lv = 0.0;
  for (int k = 0; k < tries; ++k)
  {
    const double angle = k * p.step_deg * M_PI / 180.0, c = std::cos(angle), s = std::sin(angle);
    double lo_u = 1e300, hi_u = -1e300, lo_v = 1e300, hi_v = -1e300;
    for (std::size_t i = 0; i < n; ++i)
    {
      u[i] = dx[i] * c + dy[i] * s;
      v[i] = dy[i] * c - dx[i] * s;
      lo_u = std::min(lo_u, u[i]);
      hi_u = std::max(hi_u, u[i]);
      lo_v = std::min(lo_v, v[i]);
      hi_v = std::max(hi_v, v[i]);
    }
    double score = 0.0;
    for (std::size_t i = 0; i < n; ++i)
    {
      const double edge = std::min(std::min(u[i] - lo_u, hi_u - u[i]), std::min(v[i] - lo_v, hi_v - v[i]));
      score += 1.0 / std::max(edge, closeness);
    }
    if (score > best_score)
    {
      best_score = score;
      best_angle = angle;
      best_lu = hi_u - lo_u;
      best_lv = hi_v - lo_v;
    }
  }
  const Eigen::Vector2d eu(std::cos(best_angle), std::sin(best_angle)), ev(-eu.y(), eu.x());
  const Eigen::Vector2d axis = best_lu >= best_lv ? eu : ev;
  return axis.dot(principal) < 0.0 ? Eigen::Vector2d(-axis) : axis;
}

ClusterBox fitClusterBox(const std::vector<Point2>& points, const std::vector<int>& idx, const BoxFitParams& p)
{
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (int i : idx) mean += Eigen::Vector2d(points[i].x, points[i].y);
  mean /= static_cast<double>(idx.size());
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (int i : idx)
  {
    const Eigen::Vector2d d = Eigen::Vector2d(points[i].x, points[i].y) - mean;
    scatter += d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(scatter);
  const Eigen::Vector2d principal = eig.eigenvectors().col(1);
  Eigen::Vector2d major = principal;
  double lo_u = 1e300, hi_u = -1e300, lo_v = 1e300, hi_v = -1e300;
  auto extents = [&]() {
    const Eigen::Vector2d minor(-major.y(), major.x());
    lo_u = lo_v = 1e300;
    hi_u = hi_v = -1e300;
    for (int i : idx)
    {
      const Eigen::Vector2d d = Eigen::Vector2d(points[i].x, points[i].y) - mean;
      lo_u = std::min(lo_u, d.dot(major));
      hi_u = std::max(hi_u, d.dot(major));
      lo_v = std::min(lo_v, d.dot(minor));
      hi_v = std::max(hi_v, d.dot(minor));
    }
  };
  extents();
  bool fitted = false;
  // A cluster longer than max_length · √2 along its principal axis is too long along any rectangle's.
  if (p.enabled && hi_u - lo_u >= p.min_length && hi_u - lo_u <= M_SQRT2 * p.max_length)
  {
    major = fittedAxis(points, idx, mean, principal, p);
    fitted = std::acos(std::min(1.0, std::abs(major.dot(principal)))) > p.step_deg * M_PI / 180.0;
    extents();
  }
  ClusterBox out;
  out.mean = mean;
  out.major = major;
  out.lo_u = lo_u;
  out.hi_u = hi_u;
  out.lo_v = lo_v;
  out.hi_v = hi_v;
  out.fitted = fitted;
  return out;
}

}  // namespace core
}  // namespace map_aided_fusion

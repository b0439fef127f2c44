#include "map_aided_fusion/core/tracking/common_motion.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/LU>

namespace map_aided_fusion {
namespace core {

namespace {

/// A seen track for the turning fit: its position from the centre, its velocity and σ(speed) (at least
/// kMinCommonSigma).
struct Relative
{
  Eigen::Vector2d r, v;
  double sigma;
};

/// The turning fit's result: v₀, ω, σ(ω) (ω NaN when singular) and how many tracks agree with it.
struct TurnFit
{
  Point2 v;
  double turn_rate, turn_sigma;
  long agree;
};

TurnFit fitTurn(const std::vector<Relative>& seen, Point2 start, double sigmas)
{
  Eigen::Vector3d theta(start.x, start.y, 0.0);
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  auto residual = [&theta](const Relative& s) {
    return Eigen::Vector2d(s.v.x() - theta(0) + theta(2) * s.r.y(), s.v.y() - theta(1) - theta(2) * s.r.x());
  };
  for (int iteration = 0; iteration < kCommonTurnIterations; ++iteration)
  {
    a.setZero();
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    for (const Relative& s : seen)
    {
      const double z = residual(s).norm() / s.sigma, k = sigmas;
      const double w = (z <= k ? 1.0 : k / z) / (s.sigma * s.sigma);
      const Eigen::Vector3d jx(1.0, 0.0, -s.r.y()), jy(0.0, 1.0, s.r.x());
      a += w * (jx * jx.transpose() + jy * jy.transpose());
      b += w * (jx * s.v.x() + jy * s.v.y());
    }
    const Eigen::Vector3d next = a.ldlt().solve(b);
    if (!next.allFinite() || !((a * next - b).norm() <= kCommonTurnSolveTolerance * (b.norm() + 1.0)))
      return TurnFit{ Point2{ 0.0, 0.0 }, std::nan(""), 0.0, 0 };
    theta = next;
  }
  const long agree = std::count_if(seen.begin(), seen.end(),
                                   [&](const Relative& s) { return residual(s).norm() <= sigmas * s.sigma; });
  const double turn_variance = a.inverse()(2, 2);
  return TurnFit{ Point2{ theta(0), theta(1) }, theta(2), std::sqrt(std::max(0.0, turn_variance)), agree };
}

/// The per-axis median of the velocities of @p seen (at least one).
Point2 medianVelocity(const std::vector<SeenTrack>& seen)
{
  std::vector<double> vx, vy;
  vx.reserve(seen.size());
  vy.reserve(seen.size());
  for (const SeenTrack& s : seen)
  {
    vx.push_back(s.velocity.x);
    vy.push_back(s.velocity.y);
  }
  const std::size_t n = seen.size();
  auto median = [n](std::vector<double>& v) {
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(n / 2), v.end());
    return v[n / 2];
  };
  return Point2{ median(vx), median(vy) };
}

}  // namespace

CommonMotion fitCommonMotion(const std::vector<SeenTrack>& seen, const Point2* sensor, const CommonMotionParams& p)
{
  CommonMotion out;
  const std::size_t n = seen.size();
  if (n == 0 || n < static_cast<std::size_t>(p.min_tracks)) return out;
  Point2 m = medianVelocity(seen);
  auto agree = std::count_if(seen.begin(), seen.end(), [&](const SeenTrack& s) {
    return std::hypot(s.velocity.x - m.x, s.velocity.y - m.y) <= p.sigmas * s.speed_sigma;
  });
  double turn_rate = 0.0;
  if (p.turn && sensor)
  {
    out.centre = *sensor;
    std::vector<Relative> relative;
    relative.reserve(n);
    for (const SeenTrack& s : seen)
      relative.push_back(Relative{ Eigen::Vector2d(s.position.x - sensor->x, s.position.y - sensor->y),
                                   Eigen::Vector2d(s.velocity.x, s.velocity.y), std::max(s.speed_sigma, kMinCommonSigma) });
    const TurnFit fit = fitTurn(relative, m, p.sigmas);
    if (std::abs(fit.turn_rate) <= p.max_turn_rate && std::abs(fit.turn_rate) > p.sigmas * fit.turn_sigma &&
        fit.agree > agree && std::hypot(fit.v.x, fit.v.y) <= p.max_speed)
    {
      m = fit.v;
      agree = fit.agree;
      turn_rate = fit.turn_rate;
    }
  }
  if (!(std::hypot(m.x, m.y) <= p.max_speed) || !(static_cast<double>(agree) > p.share * static_cast<double>(n)))
    return out;
  out.found = true;
  out.velocity = m;
  out.turn_rate = turn_rate;
  return out;
}

}  // namespace core
}  // namespace map_aided_fusion

#include "map_aided_fusion/core/tracking/measurement_model.hpp"

#include <algorithm>
#include <cmath>

namespace map_aided_fusion {
namespace core {

namespace {

/// Offset of the track's box centre from the centroid along one axis: the middle of the cluster when it is as long as
/// the box, else the box placed on the cluster's anchoring end (viewAlong()).
double centreAlong(const AxisView& a, double extent)
{
  if (std::abs((a.hi - a.lo) - extent) <= kAnchorTolerance) return 0.5 * (a.lo + a.hi);
  return a.anchor_lo ? a.lo + 0.5 * extent : a.hi - 0.5 * extent;
}

}  // namespace

AxisView viewAlong(const Measurement& m, const Eigen::Vector2d& axis)
{
  const Eigen::Vector2d mu(std::cos(m.yaw), std::sin(m.yaw)), mv(-mu.y(), mu.x());
  AxisView a{ 1e300, -1e300, true };
  for (double u : { m.lo_u, m.hi_u })
    for (double v : { m.lo_v, m.hi_v })
    {
      const double x = (u * mu + v * mv).dot(axis);
      a.lo = std::min(a.lo, x);
      a.hi = std::max(a.hi, x);
    }
  const Eigen::Vector2d sensor(m.sensor.x - m.centroid.x, m.sensor.y - m.centroid.y);
  const bool near_lo = sensor.dot(axis) < 0.5 * (a.lo + a.hi);
  a.anchor_lo = near_lo;
  if (m.ends_seen)
  {
    const double du = mu.dot(axis), dv = mv.dot(axis);
    const bool major = std::abs(du) >= std::abs(dv);
    if (std::max(std::abs(du), std::abs(dv)) < std::cos(kOpenEndsMaxAngle)) return a;
    const double d = major ? du : dv;
    const std::uint8_t low = major ? Measurement::kLowU : Measurement::kLowV;
    const std::uint8_t high = major ? Measurement::kHighU : Measurement::kHighV;
    const std::uint8_t lo_bit = d > 0.0 ? low : high, hi_bit = d > 0.0 ? high : low;
    const std::uint8_t near_bit = near_lo ? lo_bit : hi_bit, far_bit = near_lo ? hi_bit : lo_bit;
    if ((m.occluded & near_bit) && (m.open & far_bit)) a.anchor_lo = !near_lo;
  }
  return a;
}

Measurement measurementOf(const ClusterBox& box, std::vector<int>&& idx, const MeasurementModelParams& p)
{
  const Eigen::Vector2d& major = box.major;
  const Eigen::Vector2d minor(-major.y(), major.x());
  Measurement m;
  m.fitted = box.fitted;
  m.length = box.length();
  m.width = box.width();
  m.centroid = Point2{ box.mean.x(), box.mean.y() };
  m.lo_u = box.lo_u;
  m.hi_u = box.hi_u;
  m.lo_v = box.lo_v;
  m.hi_v = box.hi_v;
  m.yaw = std::atan2(major.y(), major.x());
  m.points = static_cast<int>(idx.size());
  const double su = clusterSigma(p, m.length), sv = clusterSigma(p, m.width);
  Eigen::Matrix2d axes;
  axes << major, minor;
  m.covariance = axes * Eigen::Vector2d(su * su, sv * sv).asDiagonal() * axes.transpose();
  m.returns = std::move(idx);
  return m;
}

bool anchored(const TrackView& t, const Measurement& m)
{
  return m.has_sensor && t.box_length > 0.0 && m.hi_u - m.lo_u > 0.0;
}

Point2 anchorPoint(const TrackView& t, const Measurement& m)
{
  if (!anchored(t, m)) return m.centroid;
  const Eigen::Vector2d tu(std::cos(t.box_yaw), std::sin(t.box_yaw)), tv(-tu.y(), tu.x());
  const Eigen::Vector2d r = Eigen::Vector2d(m.centroid.x, m.centroid.y) +
                            centreAlong(viewAlong(m, tu), t.box_length) * tu +
                            centreAlong(viewAlong(m, tv), t.box_width) * tv;
  return Point2{ r.x(), r.y() };
}

bool hiddenEnds(const TrackView& t, const Measurement& m, const MeasurementModelParams& p)
{
  constexpr std::uint8_t kEnds = Measurement::kLowU | Measurement::kHighU;
  return p.hidden_ends && !t.moving && m.ends_seen && (m.occluded & kEnds) == kEnds && !(m.open & kEnds);
}

bool openAnchor(const TrackView& t, const Measurement& m, const MeasurementModelParams& p)
{
  if (!p.open_anchor || !m.ends_seen || !m.has_sensor || !(t.box_length > 0.0)) return false;
  const AxisView a = viewAlong(m, Eigen::Vector2d(std::cos(m.yaw), std::sin(m.yaw)));
  return (m.open & (a.anchor_lo ? Measurement::kLowU : Measurement::kHighU)) != 0;
}

bool farGrowth(const TrackView& t, const Measurement& m, const MeasurementModelParams& p, bool open)
{
  return open && p.far_growth && std::abs(std::remainder(m.yaw - t.box_yaw, 0.5 * M_PI)) <= kMinAxesTurn;
}

Eigen::Matrix2d anchorCovariance(const TrackView& t, const Measurement& m, const MeasurementModelParams& p)
{
  const double dl = 0.5 * std::abs(m.length - t.last_length), dw = 0.5 * std::abs(m.width - t.last_width);
  const Eigen::Vector2d major(std::cos(m.yaw), std::sin(m.yaw)), minor(-major.y(), major.x());
  const bool open = openAnchor(t, m, p);
  const double along = (farGrowth(t, m, p, open) ? 0.0 : dl * dl) +
                       (hiddenEnds(t, m, p) ? p.hidden_ends_sigma * p.hidden_ends_sigma : 0.0);
  if (open)
  {
    const double su = p.measurement_sigma, sv = clusterSigma(p, m.width);
    return (su * su + along) * major * major.transpose() + (sv * sv + dw * dw) * minor * minor.transpose();
  }
  return m.covariance + along * major * major.transpose() + dw * dw * minor * minor.transpose();
}

}  // namespace core
}  // namespace map_aided_fusion

#include "map_aided_fusion/sim/motion.hpp"

#include <algorithm>
#include <cmath>

#include "map_aided_fusion/core/parameters.hpp"

namespace map_aided_fusion {
namespace sim {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kMinTurn = 1e-3;       // rad, straighter corners are kept as they are
constexpr double kSameSpot = 1e-9;      // m, duplicate vertices are dropped
constexpr double kMaxSpeed = 100.0;     // m/s, validation bound
constexpr double kMaxAcceleration = 20.0;
constexpr double kMaxCornerRadius = 1000.0;

double wrapAngle(double a)
{
  while (a > kPi) a -= 2.0 * kPi;
  while (a < -kPi) a += 2.0 * kPi;
  return a;
}

double dist(Point2 a, Point2 b) { return std::hypot(b.x - a.x, b.y - a.y); }

}  // namespace

double MotionState::vx() const { return speed * std::cos(yaw); }
double MotionState::vy() const { return speed * std::sin(yaw); }

void MotionParams::validate(const std::string& prefix) const
{
  core::requireInRange(prefix + "speed", speed, 0.0, kMaxSpeed);
  core::requireInRange(prefix + "acceleration", acceleration, 1e-3, kMaxAcceleration);
  core::requireInRange(prefix + "start_time", start_time, 0.0, 1e7);
  core::requireInRange(prefix + "corner_radius", corner_radius, 0.0, kMaxCornerRadius);
  for (const Stop& st : stops)
  {
    core::requireInRange(prefix + "stops.s", st.s, 0.0, 1e7);
    if (!(st.duration >= 0.0)) throw core::ParameterError(prefix + "stops.duration", "must be >= 0 (or .inf)");
  }
}

std::vector<Point2> roundCorners(const std::vector<Point2>& input, double radius, double max_step_rad)
{
  std::vector<Point2> pts;
  for (const Point2& p : input)
    if (pts.empty() || dist(pts.back(), p) > kSameSpot) pts.push_back(p);
  if (pts.size() < 3 || radius <= 0.0) return pts;
  std::vector<Point2> out{ pts.front() };
  for (std::size_t i = 1; i + 1 < pts.size(); ++i)
  {
    const Point2 a = pts[i - 1], p = pts[i], b = pts[i + 1];
    const double l1 = dist(a, p), l2 = dist(p, b);
    const double u1x = (p.x - a.x) / l1, u1y = (p.y - a.y) / l1;
    const double u2x = (b.x - p.x) / l2, u2y = (b.y - p.y) / l2;
    const double cross = u1x * u2y - u1y * u2x, dot = u1x * u2x + u1y * u2y;
    const double turn = std::atan2(std::abs(cross), dot);
    if (turn < kMinTurn)
    {
      out.push_back(p);
      continue;
    }
    const double half_tan = std::tan(0.5 * turn);
    const double d = std::min(radius * half_tan, 0.5 * std::min(l1, l2));
    const double r = d / half_tan;
    const double side = cross > 0.0 ? 1.0 : -1.0;
    const Point2 t1{ p.x - u1x * d, p.y - u1y * d };
    const Point2 c{ t1.x - side * u1y * r, t1.y + side * u1x * r };
    const double a1 = std::atan2(t1.y - c.y, t1.x - c.x);
    const int steps = std::max(1, static_cast<int>(std::ceil(turn / max_step_rad)));
    for (int k = 0; k <= steps; ++k)
    {
      const double ang = a1 + side * turn * k / steps;
      const Point2 q{ c.x + r * std::cos(ang), c.y + r * std::sin(ang) };
      if (dist(out.back(), q) > kSameSpot) out.push_back(q);
    }
  }
  if (dist(out.back(), pts.back()) > kSameSpot) out.push_back(pts.back());
  return out;
}

PathMotion::PathMotion(const std::vector<Point2>& path, const MotionParams& params) : params_(params)
{
  params_.validate("");
  if (path.empty()) throw core::ParameterError("path", "needs at least one point");
  constexpr double kArcStep = 5.0 * kPi / 180.0;
  points_ = roundCorners(path, params_.corner_radius, kArcStep);
  cumulative_.assign(points_.size(), 0.0);
  for (std::size_t i = 1; i < points_.size(); ++i)
    cumulative_[i] = cumulative_[i - 1] + dist(points_[i - 1], points_[i]);
  const std::size_t n = points_.size();
  vertex_yaw_.assign(n, 0.0);
  std::vector<double> seg(n > 1 ? n - 1 : 0);
  for (std::size_t i = 0; i + 1 < n; ++i)
    seg[i] = std::atan2(points_[i + 1].y - points_[i].y, points_[i + 1].x - points_[i].x);
  for (std::size_t i = 0; i < n && !seg.empty(); ++i)
  {
    if (i == 0) vertex_yaw_[i] = seg.front();
    else if (i + 1 == n) vertex_yaw_[i] = seg.back();
    else vertex_yaw_[i] = wrapAngle(seg[i - 1] + 0.5 * wrapAngle(seg[i] - seg[i - 1]));
  }

  const double total = length();
  std::vector<Stop> stops = params_.stops;
  for (Stop& st : stops) st.s = std::min(st.s, total);
  std::stable_sort(stops.begin(), stops.end(), [](const Stop& a, const Stop& b) { return a.s < b.s; });
  const double cruise = params_.speed;
  double t = params_.start_time, s = 0.0;
  double v = (!stops.empty() && stops.front().s <= kSameSpot) ? 0.0 : cruise;
  if (cruise <= 0.0)
  {
    legs_.push_back(Leg{ 0.0, 0.0, t, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, std::numeric_limits<double>::infinity() });
    end_time_ = std::numeric_limits<double>::infinity();
    return;
  }
  auto addLeg = [&](double b, bool stop_at_end, double dwell) {
    Leg leg;
    leg.s0 = s;
    leg.length = std::max(0.0, b - s);
    leg.t0 = t;
    leg.v0 = v;
    double v1 = stop_at_end ? 0.0 : cruise;
    double a = params_.acceleration;
    const double L = leg.length;
    if (v > v1 && L > 0.0) a = std::max(a, (v * v - v1 * v1) / (2.0 * L));
    if (v1 > v && v * v + 2.0 * a * L < v1 * v1) v1 = std::sqrt(v * v + 2.0 * a * L);
    if (L <= 0.0) v1 = std::min(v1, v);
    double vp = std::min(cruise, std::sqrt(std::max(0.0, (2.0 * a * L + v * v + v1 * v1) / 2.0)));
    vp = std::max(vp, std::max(v, v1));
    leg.v1 = v1;
    leg.vp = vp;
    leg.t_acc = (vp - v) / a;
    leg.t_dec = (vp - v1) / a;
    const double d_acc = (vp * vp - v * v) / (2.0 * a);
    const double d_dec = (vp * vp - v1 * v1) / (2.0 * a);
    leg.t_cruise = vp > 0.0 ? std::max(0.0, L - d_acc - d_dec) / vp : 0.0;
    leg.dwell = dwell;
    acc_.push_back(a);
    legs_.push_back(leg);
    t += leg.t_acc + leg.t_cruise + leg.t_dec + dwell;
    s = b;
    v = v1;
  };
  for (const Stop& st : stops) addLeg(st.s, true, st.duration);
  addLeg(total, params_.end == PathEnd::kStay, 0.0);
  end_time_ = t;
}

double PathMotion::distanceInLeg(std::size_t i, double tau, double& speed) const
{
  const Leg& leg = legs_[i];
  const double a = acc_[i];
  if (tau < leg.t_acc)
  {
    speed = leg.v0 + a * tau;
    return leg.v0 * tau + 0.5 * a * tau * tau;
  }
  const double d_acc = leg.v0 * leg.t_acc + 0.5 * a * leg.t_acc * leg.t_acc;
  tau -= leg.t_acc;
  if (tau < leg.t_cruise)
  {
    speed = leg.vp;
    return d_acc + leg.vp * tau;
  }
  const double d_cruise = leg.vp * leg.t_cruise;
  tau -= leg.t_cruise;
  if (tau < leg.t_dec)
  {
    speed = leg.vp - a * tau;
    return std::min(leg.length, d_acc + d_cruise + leg.vp * tau - 0.5 * a * tau * tau);
  }
  speed = leg.v1;
  return leg.length;
}

void PathMotion::pose(double s, double& x, double& y, double& yaw) const
{
  if (points_.size() == 1 || s <= 0.0)
  {
    x = points_.front().x;
    y = points_.front().y;
    yaw = vertex_yaw_.front();
    if (s <= 0.0 || points_.size() == 1) return;
  }
  if (s >= length())
  {
    x = points_.back().x;
    y = points_.back().y;
    yaw = vertex_yaw_.back();
    return;
  }
  const auto it = std::upper_bound(cumulative_.begin(), cumulative_.end(), s);
  const std::size_t j = static_cast<std::size_t>(it - cumulative_.begin()) - 1;
  const double seg = cumulative_[j + 1] - cumulative_[j];
  const double f = seg > 0.0 ? (s - cumulative_[j]) / seg : 0.0;
  x = points_[j].x + f * (points_[j + 1].x - points_[j].x);
  y = points_[j].y + f * (points_[j + 1].y - points_[j].y);
  yaw = wrapAngle(vertex_yaw_[j] + f * wrapAngle(vertex_yaw_[j + 1] - vertex_yaw_[j]));
}

MotionState PathMotion::at(double t) const
{
  MotionState st;
  if (!(t >= params_.start_time)) return st;
  if (t >= end_time_ && params_.end == PathEnd::kVanish && params_.speed > 0.0) return st;
  st.present = true;
  std::size_t i = 0;
  while (i + 1 < legs_.size() && t >= legs_[i + 1].t0) ++i;
  double speed = 0.0;
  const double d = params_.speed > 0.0 ? distanceInLeg(i, t - legs_[i].t0, speed) : 0.0;
  st.s = legs_[i].s0 + d;
  st.speed = speed;
  pose(st.s, st.x, st.y, st.yaw);
  return st;
}

double PathMotion::project(Point2 p) const
{
  if (points_.size() == 1) return 0.0;
  double best = std::numeric_limits<double>::infinity(), best_s = 0.0;
  for (std::size_t j = 0; j + 1 < points_.size(); ++j)
  {
    const Point2 a = points_[j], b = points_[j + 1];
    const double vx = b.x - a.x, vy = b.y - a.y, l2 = vx * vx + vy * vy;
    double f = l2 > 0.0 ? ((p.x - a.x) * vx + (p.y - a.y) * vy) / l2 : 0.0;
    f = std::clamp(f, 0.0, 1.0);
    const double d = std::hypot(a.x + f * vx - p.x, a.y + f * vy - p.y);
    if (d < best)
    {
      best = d;
      best_s = cumulative_[j] + f * (cumulative_[j + 1] - cumulative_[j]);
    }
  }
  return best_s;
}

}  // namespace sim
}  // namespace map_aided_fusion

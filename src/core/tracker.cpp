#include "map_aided_fusion/core/tracker.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/LU>  // Matrix::determinant() (usable())

#include "map_aided_fusion/core/assignment.hpp"
#include "map_aided_fusion/core/parameters.hpp"
#include "map_aided_fusion/core/stamp_guard.hpp"
#include "map_aided_fusion/core/tracking/clustering.hpp"
#include "map_aided_fusion/core/tracking/association.hpp"
#include "map_aided_fusion/core/tracking/common_motion.hpp"
#include "map_aided_fusion/core/tracking/motion_model.hpp"
#include "map_aided_fusion/core/tracking/shape_fit.hpp"

namespace map_aided_fusion {
namespace core {

namespace {

constexpr double kMinStep = 1e-6;      // s between two scans
/// Tracks or measurements of one gated component above which the association is greedy, not the cubic exact
/// method (no component of any dataset comes near: a cluster of clutter where every object gates with the next).
constexpr std::size_t kMaxExactComponent = 100;
constexpr double kSymmetryTolerance = 1e-9;  // relative: a covariance's two off-diagonal terms differ by rounding only
constexpr double kMaxBox = 1e6;  // m: a measurement's box beyond this (either way) is no object's: not used
constexpr double kManoeuvreStartRate = 0.5;   // 1/s: quiet → manoeuvring (step manoeuvres; a manoeuvre every 2 s)
constexpr double kManoeuvreEndRate = 2.0;     // 1/s: manoeuvring → quiet (a manoeuvre lasts 0.5 s on average)
constexpr double kMinGateCell = 0.5;     // m: the association's grid cells are never smaller (max_gate_distance)
constexpr double kGateSlack = 0.01;    // m added to the association's search radii (rounding)
constexpr double kLongBoxMaxWidthShare = 0.5;  // step long box: a cluster at most this wide for its length has an axis
// Step duplicates: pieces of one object move the same way, within 60°; two objects that pass each other do not.
const double kDuplicateMinCosine = std::cos(M_PI / 3.0);

bool finite(const Eigen::Vector4d& x, const Eigen::Matrix4d& p) { return x.allFinite() && p.allFinite(); }


/// A measurement a track may take: finite, a symmetric positive definite covariance, a box no larger than kMaxBox.
bool usable(const Measurement& m)
{
  const auto bounded = [](double v) { return std::abs(v) <= kMaxBox; };  // false for NaN
  const Eigen::Matrix2d& c = m.covariance;
  return std::isfinite(m.centroid.x) && std::isfinite(m.centroid.y) && c.allFinite() && c(0, 0) > 0.0 &&
         c.determinant() > 0.0 && std::abs(c(0, 1) - c(1, 0)) <= kSymmetryTolerance * (c(0, 0) + c(1, 1)) &&
         std::isfinite(m.yaw) && bounded(m.lo_u) && bounded(m.hi_u) &&
         bounded(m.lo_v) && bounded(m.hi_v) && bounded(m.length) && bounded(m.width) &&
         (!m.has_sensor || (std::isfinite(m.sensor.x) && std::isfinite(m.sensor.y)));
}

}  // namespace

namespace {

/**
 * The indices of the @p keep measurements nearest their sensor among @p n (measurement @p at(i)), in increasing index
 * order (ties: the lower index); without a sensor position, the first @p keep.
 */
template <class At>
std::vector<std::size_t> nearestFirst(At&& at, std::size_t n, std::size_t keep)
{
  std::vector<std::size_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = i;
  keep = std::min(keep, n);
  const auto distance = [&](std::size_t i) {
    const Measurement& m = *at(i);
    return m.has_sensor ? std::hypot(m.centroid.x - m.sensor.x, m.centroid.y - m.sensor.y) : 0.0;
  };
  std::vector<double> d(n);
  for (std::size_t i = 0; i < n; ++i) d[i] = distance(i);
  std::nth_element(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(keep), order.end(),
                   [&](std::size_t a, std::size_t b) { return d[a] != d[b] ? d[a] < d[b] : a < b; });
  order.resize(keep);
  std::sort(order.begin(), order.end());
  return order;
}

}  // namespace

namespace {

/// Step second axes (TrackerParams::second_axes): turns the box of @p t, seen once, to the axes of its second cluster
/// @p m when the first had none and @p m has. True when it turned.
bool takeSecondAxes(Track& t, const Measurement& m, const TrackerParams& p)
{
  if (!p.steps.second_axes || t.hits != 1) return false;
  if (!(t.extent_width >= kSecondAxesRound * t.extent_length)) return false;
  if (!(m.width <= kSecondAxesElongation * m.length) || !(m.length > kSecondAxesGrowth * t.extent_length))
    return false;
  const double turn = std::remainder(m.yaw - t.extent_yaw, M_PI);
  if (!(std::abs(turn) > kMinAxesTurn)) return false;
  const double c = std::abs(std::cos(turn)), s = std::abs(std::sin(turn));
  const double length = t.extent_length, width = t.extent_width;
  t.extent_yaw = m.yaw;
  t.extent_length = length * c + width * s;
  t.extent_width = length * s + width * c;
  return true;
}

}  // namespace

TrackView trackView(const Track& t)
{
  return TrackView{ t.extent_yaw, t.extent_length, t.extent_width, t.length, t.width, t.motion == TrackMotion::kMoving };
}

Point2 referencePoint(const Track& t, const Measurement& m) { return anchorPoint(trackView(t), m); }

ObjectBox ownBox(const Track& t) { return ObjectBox{ t.position(), t.extent_yaw, t.extent_length, t.extent_width }; }

bool inBox(const ObjectBox& box, Point2 p, double margin)
{
  const double c = std::cos(box.yaw), s = std::sin(box.yaw), dx = p.x - box.centre.x, dy = p.y - box.centre.y;
  return std::abs(dx * c + dy * s) <= 0.5 * box.length + margin && std::abs(-dx * s + dy * c) <= 0.5 * box.width + margin;
}

std::optional<Measurement> hiddenLengthBox(const Measurement& m, double heading, double length, double end_width)
{
  if (!m.has_sensor || !(length > 0.0)) return std::nullopt;
  const Eigen::Vector2d along(std::cos(heading), std::sin(heading)), across(-along.y(), along.x());
  const AxisView u = viewAlong(m, along), v = viewAlong(m, across);
  if (u.hi - u.lo >= length || v.hi - v.lo < end_width) return std::nullopt;
  const bool behind = (m.sensor.x - m.centroid.x) * along.x() + (m.sensor.y - m.centroid.y) * along.y() < 0.0;
  Measurement e = m;
  e.yaw = heading;
  e.lo_u = behind ? u.lo : u.hi - length;
  e.hi_u = behind ? u.lo + length : u.hi;
  e.lo_v = v.lo;
  e.hi_v = v.hi;
  return e;
}

ObjectBox objectBox(const Track& t, const TrackerParams& p, const std::vector<Measurement>& measurements)
{
  ObjectBox b = ownBox(t);
  if (!p.steps.hidden_centre || t.motion != TrackMotion::kMoving || !(t.speed() > 0.0)) return b;
  if (t.measurement < 0)
  {
    if (!t.seen_box.valid) return b;
    const double heading = std::atan2(t.x(3), t.x(2)), c = std::cos(heading), s = std::sin(heading);
    b.centre = Point2{ t.x(0) + c * t.seen_box.along - s * t.seen_box.across,
                       t.x(1) + s * t.seen_box.along + c * t.seen_box.across };
    b.yaw = heading + t.seen_box.yaw;
    b.length = t.seen_box.length;
    b.width = t.seen_box.width;
    return b;
  }
  if (t.measurement >= static_cast<int>(measurements.size())) return b;
  const Measurement& m = measurements[t.measurement];
  const std::optional<Measurement> e =
      hiddenLengthBox(m, std::atan2(t.x(3), t.x(2)), p.vehicle_length, kVehicleMinEndWidth);
  if (!e) return b;
  const double cu = 0.5 * (e->lo_u + e->hi_u), cv = 0.5 * (e->lo_v + e->hi_v);
  const double c = std::cos(e->yaw), s = std::sin(e->yaw);
  const Point2 followed = referencePoint(t, m);
  b.centre = Point2{ t.x(0) + m.centroid.x + cu * c - cv * s - followed.x,
                     t.x(1) + m.centroid.y + cu * s + cv * c - followed.y };
  b.yaw = e->yaw;
  b.length = e->hi_u - e->lo_u;
  b.width = e->hi_v - e->lo_v;
  return b;
}

double Track::speedSigma() const
{
  if (!manoeuvres) return core::speedSigma(x, P);
  return core::speedSigma(Eigen::Vector4d(imm.x[0].head<4>()), Eigen::Matrix4d(imm.P[0].topLeftCorner<4, 4>()));
}

Tracker::Tracker(const TrackerParams& params) : params_(params), measurement_model_(measurementModelOf(params))
{
  params_.validate();
}

std::size_t backgroundWarmupScans(double background_zeta, double delta_inc)
{
  if (!(delta_inc > 0.0) || !(background_zeta < 1.0)) return 0;
  if (background_zeta < 0.0) return 1;
  return static_cast<std::size_t>(std::floor(background_zeta / delta_inc)) + 1;
}

void Tracker::reset()
{
  ++counts_.resets;
  counts_.tracks_deleted += tracks_.size();
  tracks_.clear();
  seen_free_.clear();
  last_stamp_ = -1.0;
  common_ = CommonMotion{};
}

ManoeuvreModel Tracker::manoeuvreModel() const
{
  return ManoeuvreModel{ params_.acceleration_sigma, params_.manoeuvre_jerk_sigma, kManoeuvreStartRate,
                         kManoeuvreEndRate };
}

void Tracker::predict(Track& t, double dt) const
{
  if (!t.manoeuvres)
  {
    predictConstantVelocity(t.x, t.P, dt, params_.acceleration_sigma);
    return;
  }
  predictImm(t.imm, dt, manoeuvreModel());
  t.imm.combine(t.x, t.P);
}

namespace {

/// Steps heading box and long box: the box of @p t turns to the axes at @p yaw, its extents and its middle (the point
/// the track follows) taken from the cluster @p m along them.
void turnBox(Track& t, const Measurement& m, double yaw)
{
  t.extent_yaw = yaw;
  const Eigen::Vector2d tu(std::cos(yaw), std::sin(yaw)), tv(-tu.y(), tu.x());
  const AxisView a = viewAlong(m, tu), b = viewAlong(m, tv);
  t.extent_length = a.hi - a.lo;
  t.extent_width = b.hi - b.lo;
  t.x.head<2>() = Eigen::Vector2d(m.centroid.x, m.centroid.y) + 0.5 * (a.lo + a.hi) * tu + 0.5 * (b.lo + b.hi) * tv;
}

}  // namespace

bool Tracker::correct(Track& t, const Measurement& m, double stamp) const
{
  bool long_box = false;
  const Point2 ref = referencePoint(t, m);
  const Eigen::Matrix2d r = anchorCovariance(trackView(t), m, measurement_model_);
  if (t.manoeuvres)
  {
    correctImm(t.imm, Eigen::Vector2d(ref.x, ref.y), r);
    t.imm.combine(t.x, t.P);
  }
  else
    correctPosition(t.x, t.P, Eigen::Vector2d(ref.x, ref.y), r);
  const Eigen::Vector2d corrected = t.x.head<2>();
  t.yaw = m.yaw;
  t.length = m.length;
  t.width = m.width;
  if (t.motion == TrackMotion::kMoving && anchored(trackView(t), m) && t.speed() > kDirectionlessSpeed)
  {
    const double heading = std::atan2(t.x(3), t.x(2));
    const double max_off = kHeadingBoxAngleDeg * M_PI / 180.0;
    if (params_.steps.heading_box && std::max(t.extent_length, t.extent_width) <= kHeadingBoxMaxLength)
    {
      if (std::abs(std::remainder(heading - t.extent_yaw, 0.5 * M_PI)) > max_off) turnBox(t, m, heading);
    }
    else if (params_.steps.long_box && m.length >= kLongBoxMinLength &&
             m.width <= kLongBoxMaxWidthShare * m.length && std::abs(std::remainder(m.yaw - heading, M_PI)) <= max_off &&
             std::abs(std::remainder(m.yaw - t.extent_yaw, 0.5 * M_PI)) > kMinAxesTurn)
    {
      turnBox(t, m, m.yaw);
      long_box = true;
    }
  }
  if (anchored(trackView(t), m))
  {
    // A longer cluster than the box: the box grows away from its anchoring end; its centre moves, the object does not.
    const Eigen::Vector2d tu(std::cos(t.extent_yaw), std::sin(t.extent_yaw)), tv(-tu.y(), tu.x());
    for (auto [axis, extent] : { std::pair<Eigen::Vector2d, double*>{ tu, &t.extent_length },
                                 std::pair<Eigen::Vector2d, double*>{ tv, &t.extent_width } })
    {
      const AxisView a = viewAlong(m, axis);
      const double grown = (a.hi - a.lo) - *extent;
      if (grown <= kAnchorTolerance) continue;
      t.x.head<2>() += (a.anchor_lo ? 0.5 : -0.5) * grown * axis;
      *extent = a.hi - a.lo;
    }
  }
  else
  {
    t.extent_length = std::max(t.extent_length, m.length);
    t.extent_width = std::max(t.extent_width, m.width);
  }
  // The box's bookkeeping moved the followed point on the object: every model follows it.
  if (t.manoeuvres) t.imm.shiftPosition(t.x.head<2>() - corrected);
  ++t.hits;
  ++t.consecutive_hits;
  if (background_known_) t.background_unchecked = false;
  t.last_hit = stamp;
  t.state = afterHit(t.state, t.consecutive_hits, lifecycleParams());
  return long_box;
}

bool Tracker::fastEnough(const Track& t, double sigmas) const
{
  return clearsSpeed(decisionSpeed(t), t.speedSigma(), sigmas, params_.moving_speed);
}

void Tracker::findCommonMotion(double stamp)
{
  common_ = CommonMotion{};
  if (!params_.steps.common_motion) return;
  common_seen_.clear();
  for (const Track& t : tracks_)
    if (t.reported() && t.last_hit >= stamp && finite(t.x, t.P))
      common_seen_.push_back(SeenTrack{ t.position(), t.decisionVelocity(), t.speedSigma() });
  const auto sensor =
      std::find_if(measurements_.begin(), measurements_.end(), [](const Measurement& x) { return x.has_sensor; });
  CommonMotionParams p;
  p.turn = params_.steps.common_turn;
  common_ = fitCommonMotion(common_seen_, sensor != measurements_.end() ? &sensor->sensor : nullptr, p);
  counts_.common_motion_scans += common_.found;
  counts_.common_turn_scans += common_.found && common_.turn_rate != 0.0;
}

void Tracker::decideMotion(Track& t, double stamp) const
{
  MotionEvidence e;
  e.tentative = t.state == TrackState::kTentative;
  if (!e.tentative)
  {
    e.speed = decisionSpeed(t);
    e.speed_sigma = t.speedSigma();
  }
  e.free_space_check = free_now_;
  e.motion_seen = t.motion_seen;
  const MotionDecisionParams p{ params_.moving_speed, params_.motion_sigmas, kFreeSpaceMotionSigmas,
                                params_.stopped_speed, params_.stopped_time };
  t.motion = core::decideMotion(e, stamp, t.still_since, p);
}

bool Tracker::smallWalker(const Track& t) const
{
  const double small = params_.pedestrian_size;
  const bool thick = t.extent_length >= kSmallMinExtent && t.extent_width >= kSmallMinExtent;
  return params_.steps.small_free_space && t.extent_length <= small && t.extent_width <= small && thick &&
         t.speed() <= kWalkingMaxSpeed;
}

void Tracker::seeFreeSpace(Track& t, double stamp)
{
  if (t.measurement < 0) return;
  const std::vector<int>& idx = measurements_[t.measurement].returns;
  Sighting now;
  now.stamp = stamp;
  now.position = t.position();
  const std::size_t n = std::min(idx.size(), static_cast<std::size_t>(kSightingPoints));
  now.points.reserve(n);
  for (std::size_t k = 0; k < n; ++k)
  {
    const int i = idx[k * idx.size() / n];
    if (i >= 0 && i < static_cast<int>(map_points_.size())) now.points.push_back(map_points_[i]);
  }
  if (!t.motion_seen && fastEnough(t, kFreeSpaceMotionSigmas))
  {
    const bool small = smallWalker(t);
    // It left: the returns of one earlier sighting lie in the free space of this scan.
    const SeenFree& current = seen_free_.back();
    const bool left = std::any_of(t.sightings.begin(), t.sightings.end(), [&](const Sighting& past) {
      return current.clearShare(past.points, small) >= params_.free_space_share;
    });
    // It came: its returns of this scan lie where some earlier scan saw free space.
    auto seenFreeBefore = [&](const Point2& q) {
      return std::any_of(seen_free_.begin(), seen_free_.end() - 1, [&](const SeenFree& f) { return f.clear(q, small); });
    };
    const auto came = std::count_if(now.points.begin(), now.points.end(), seenFreeBefore);
    t.motion_seen = left || (!now.points.empty() && static_cast<double>(came) >=
                                                        params_.free_space_share * static_cast<double>(now.points.size()));
    if (!t.motion_seen && params_.steps.walked && small && t.consecutive_hits >= kWalkMinHits &&
        !t.sightings.empty())
    {
      const Sighting& earliest = t.sightings.front();
      const double dt = stamp - earliest.stamp;
      const Point2 common = commonMotionAt(t.position());
      if (std::hypot(t.x(0) - earliest.position.x - common.x * dt, t.x(1) - earliest.position.y - common.y * dt) >=
          kWalkDistance)
      {
        t.motion_seen = true;
        ++counts_.walked;
      }
    }
  }
  const double oldest = stamp - params_.free_space_time - kMinStep;
  t.sightings.erase(std::remove_if(t.sightings.begin(), t.sightings.end(),
                                   [&](const Sighting& s) { return s.stamp < oldest || s.stamp >= stamp; }),
                    t.sightings.end());
  t.sightings.push_back(std::move(now));
}

void Tracker::update(double stamp, const Pose2& pose, const ObstaclePoints& returns,
                     const std::vector<std::uint8_t>* background, const ScanMassGrid* scan)
{
  if (!std::isfinite(pose.x) || !std::isfinite(pose.y) || !std::isfinite(pose.yaw) || !std::isfinite(stamp))
  {
    ++counts_.non_finite_inputs;
    return;
  }
  if (last_stamp_ >= 0.0 && stamp - last_stamp_ > kMinStep && !tracks_.empty() &&
      checkPoseJump(last_pose_.x, last_pose_.y, last_stamp_, pose.x, pose.y, stamp, params_.max_ego_speed).jumped)
  {
    reset();
  }
  last_pose_ = pose;
  free_now_ = scan && params_.steps.free_space_check;
  const bool open_ends = scan && params_.steps.open_ends;
  if (free_now_ || open_ends)
  {
    // The free-space check compares the scans of free_space_time; step open ends needs this scan's only.
    const double oldest = free_now_ ? stamp - params_.free_space_time - kMinStep : stamp;
    seen_free_.erase(std::remove_if(seen_free_.begin(), seen_free_.end(),
                                    [&](const SeenFree& f) { return f.stamp() < oldest || f.stamp() >= stamp; }),
                     seen_free_.end());
    seen_free_.emplace_back(*scan, pose, stamp, params_.free_space_margin,
                            params_.steps.small_free_space ? kSmallFreeSpaceMargin : -1.0);
  }
  else
    seen_free_.clear();
  const double c = std::cos(pose.yaw), s = std::sin(pose.yaw);
  map_points_.clear();
  map_points_.reserve(returns.count);
  map_flags_.clear();
  const bool flagged = background && background->size() == returns.count;
  for (std::size_t i = 0; i < returns.count; ++i)
  {
    const double x = returns.xy[2 * i], y = returns.xy[2 * i + 1];
    if (!std::isfinite(x) || !std::isfinite(y))
    {
      ++counts_.non_finite_inputs;
      continue;
    }
    map_points_.push_back(Point2{ pose.x + c * x - s * y, pose.y + s * x + c * y });
    if (flagged) map_flags_.push_back((*background)[i]);
  }
  std::vector<Measurement> found = clusterReturns(map_points_, params_, flagged ? &map_flags_ : nullptr);
  counts_.split_measurements +=
      std::count_if(found.begin(), found.end(), [](const Measurement& m) { return m.split; });
  counts_.box_fit += std::count_if(found.begin(), found.end(), [](const Measurement& m) { return m.fitted; });
  for (Measurement& m : found)
  {
    m.has_sensor = true;
    m.sensor = Point2{ pose.x, pose.y };
  }
  capMeasurements(found);
  for (Measurement& m : found)
  {
    if (open_ends) findOpenEnds(m, seen_free_.back(), *scan, pose, kOpenEndDistance);
  }
  own_measurements_ = std::move(found);
  update(stamp, own_measurements_);
}

void Tracker::dropDuplicates(std::vector<Track>& tracks, double stamp)
{
  std::vector<std::size_t> moving;
  for (std::size_t j = 0; j < tracks.size(); ++j)
    if (tracks[j].reported() && tracks[j].motion == TrackMotion::kMoving && tracks[j].last_hit >= stamp &&
        tracks[j].measurement >= 0)
      moving.push_back(j);
  if (moving.size() < 2) return;
  // The tracks with more hits (then the older ids) keep their objects.
  std::sort(moving.begin(), moving.end(), [&](std::size_t a, std::size_t b) {
    return tracks[a].hits != tracks[b].hits ? tracks[a].hits > tracks[b].hits : tracks[a].id < tracks[b].id;
  });
  std::vector<ObjectBox> boxes;
  std::vector<double> reach;  // how far from its centre the grown box reaches
  boxes.reserve(moving.size());
  reach.reserve(moving.size());
  const double margin = kFragmentMargin;
  for (std::size_t j : moving)
  {
    boxes.push_back(objectBox(tracks[j], params_, measurements_));
    reach.push_back(std::hypot(0.5 * boxes.back().length + margin, 0.5 * boxes.back().width + margin));
  }
  std::vector<char> dropped(tracks.size(), 0);
  for (std::size_t a = 0; a < moving.size(); ++a)
  {
    if (dropped[moving[a]]) continue;
    Track& keep = tracks[moving[a]];
    for (std::size_t b = a + 1; b < moving.size(); ++b)
    {
      const Track& other = tracks[moving[b]];
      const double dx = boxes[b].centre.x - boxes[a].centre.x, dy = boxes[b].centre.y - boxes[a].centre.y;
      if (dropped[moving[b]] || dx * dx + dy * dy > reach[a] * reach[a] || !inBox(boxes[a], boxes[b].centre, margin))
        continue;
      if (keep.velocity().x * other.velocity().x + keep.velocity().y * other.velocity().y <
          kDuplicateMinCosine * keep.speed() * other.speed())
        continue;
      dropped[moving[b]] = 1;
      keep.fragments.push_back(other.measurement);
      ++counts_.duplicates;
      ++counts_.tracks_deleted;
    }
  }
  std::size_t out = 0;
  for (std::size_t j = 0; j < tracks.size(); ++j)
  {
    if (dropped[j]) continue;
    if (out != j) tracks[out] = std::move(tracks[j]);
    ++out;
  }
  tracks.resize(out);
}

void Tracker::update(double stamp, const std::vector<Measurement>& measurements)
{
  ++counts_.scans;
  if (&measurements != &own_measurements_)
  {
    map_points_.clear();
    free_now_ = false;
  }
  if (!std::isfinite(stamp))
  {
    ++counts_.non_finite_inputs;
    return;
  }
  if (last_stamp_ >= 0.0 && stamp <= last_stamp_)
  {
    if (!tracks_.empty()) reset();
  }
  const double dt = last_stamp_ >= 0.0 && stamp > last_stamp_ ? stamp - last_stamp_ : 0.0;
  last_stamp_ = stamp;
  measurements_.clear();
  for (const Measurement& m : measurements)
  {
    if (usable(m))
      measurements_.push_back(m);
    else
      ++counts_.non_finite_inputs;
  }
  capMeasurements(measurements_);
  counts_.measurements += measurements_.size();
  for (Track& t : tracks_)
  {
    predict(t, dt);
    t.measurement = -1;
    t.fragments.clear();
  }
  const std::vector<char> used = associate(stamp);
  findCommonMotion(stamp);
  // Lifecycle: a tentative track missed once, a coasting track too long unseen, a broken state.
  std::vector<Track> kept;
  kept.reserve(tracks_.size() + measurements_.size());
  for (Track& t : tracks_)
  {
    const bool missed = t.last_hit < stamp;
    if (!finite(t.x, t.P) || t.speed() > params_.max_speed)
    {
      ++counts_.rejected_tracks;
      ++counts_.tracks_deleted;
      continue;
    }
    if (expired(t.state, missed, stamp - t.last_hit, lifecycleParams()))
    {
      ++counts_.tracks_deleted;
      continue;
    }
    if (free_now_) seeFreeSpace(t, stamp);
    decideMotion(t, stamp);
    kept.push_back(std::move(t));
  }
  if (params_.steps.duplicates) dropDuplicates(kept, stamp);
  startTracks(kept, used, stamp);
  tracks_ = std::move(kept);
  counts_.peak_tracks = std::max<std::uint64_t>(counts_.peak_tracks, tracks_.size());
  if (params_.steps.hidden_centre) rememberSeenBoxes();
}

void Tracker::capMeasurements(std::vector<Measurement>& found)
{
  counts_.peak_measurements = std::max<std::uint64_t>(counts_.peak_measurements, found.size());
  const auto cap = static_cast<std::size_t>(params_.max_measurements);
  if (found.size() <= cap) return;
  counts_.measurements_dropped += found.size() - cap;
  const std::vector<std::size_t> keep = nearestFirst([&](std::size_t i) { return &found[i]; }, found.size(), cap);
  std::vector<Measurement> kept;
  kept.reserve(cap);
  for (const std::size_t i : keep) kept.push_back(std::move(found[i]));
  found = std::move(kept);
}

std::vector<char> Tracker::associate(double stamp)
{
  std::size_t greedy = 0;
  const std::vector<int> pairs = solveAssignment(gate(), kMaxExactComponent, &greedy);
  counts_.greedy_associations += greedy;
  std::vector<char> used(measurements_.size(), 0);
  for (int r = 0; r < static_cast<int>(tracks_.size()); ++r)
  {
    Track& t = tracks_[r];
    if (pairs[r] >= 0)
    {
      const Measurement& z = measurements_[pairs[r]];
      if (takeSecondAxes(t, z, params_)) ++counts_.second_axes;
      const TrackView view = trackView(t);  // after step second axes turned its box
      if (hiddenEnds(view, z, measurement_model_)) ++counts_.hidden_ends;
      const bool open = openAnchor(view, z, measurement_model_);
      counts_.open_anchor += open;
      counts_.far_growth += farGrowth(view, z, measurement_model_, open);
      if (correct(t, z, stamp)) ++counts_.long_box;
      used[pairs[r]] = 1;
      t.measurement = pairs[r];
    }
    else
    {
      t.consecutive_hits = 0;
      t.state = afterMiss(t.state);
    }
  }
  return used;
}

void Tracker::startTracks(std::vector<Track>& kept, const std::vector<char>& used, double stamp)
{
  const std::size_t seen_tracks = kept.size();
  // Step fragments: the box of a moving track seen this scan (with step duplicates, its object box), grown by the
  // margin, holds the centroid of a cluster no track took; with step duplicates the cluster is that track's piece.
  std::vector<std::pair<std::size_t, ObjectBox>> moving_boxes;
  if (params_.steps.fragments)
    for (std::size_t j = 0; j < seen_tracks; ++j)
      if (kept[j].motion == TrackMotion::kMoving && kept[j].last_hit >= stamp)
        moving_boxes.emplace_back(j, params_.steps.duplicates ? objectBox(kept[j], params_, measurements_) : ownBox(kept[j]));
  std::vector<std::size_t> starts;
  for (std::size_t m = 0; m < measurements_.size(); ++m)
  {
    if (used[m]) continue;
    const Measurement& z = measurements_[m];
    const auto owner = std::find_if(moving_boxes.begin(), moving_boxes.end(), [&](const auto& jb) {
      return inBox(jb.second, z.centroid, kFragmentMargin);
    });
    if (owner == moving_boxes.end())
    {
      starts.push_back(m);
      continue;
    }
    ++counts_.fragments;
    if (params_.steps.duplicates) kept[owner->first].fragments.push_back(static_cast<int>(m));
  }
  // Within max_tracks, the clusters nearest the sensor start their tracks (in the measurements' order).
  const std::size_t room = kept.size() < static_cast<std::size_t>(params_.max_tracks)
                               ? static_cast<std::size_t>(params_.max_tracks) - kept.size()
                               : 0;
  if (starts.size() > room)
  {
    counts_.tracks_refused += starts.size() - room;
    std::vector<std::size_t> nearest =
        nearestFirst([&](std::size_t i) { return &measurements_[starts[i]]; }, starts.size(), room);
    for (std::size_t& i : nearest) i = starts[i];
    starts = std::move(nearest);
  }
  for (const std::size_t m : starts) kept.push_back(newTrack(measurements_[m], static_cast<int>(m), stamp));
}

Track Tracker::newTrack(const Measurement& z, int measurement, double stamp)
{
  Track t;
  t.id = next_id_++;
  // The middle of the cluster's box, the point referencePoint() follows.
  const double mu = 0.5 * (z.lo_u + z.hi_u), mv = 0.5 * (z.lo_v + z.hi_v);
  const double cu = std::cos(z.yaw), su = std::sin(z.yaw);
  t.x << z.centroid.x + mu * cu - mv * su, z.centroid.y + mu * su + mv * cu, 0.0, 0.0;
  t.P.setZero();
  t.P.topLeftCorner<2, 2>() = z.covariance;
  t.P(2, 2) = t.P(3, 3) = kInitialSpeedSigma * kInitialSpeedSigma;
  // Step manoeuvres, per class: a walker (a first cluster of a pedestrian's size) keeps the constant-velocity model.
  t.manoeuvres = manoeuvres() && !(z.length <= params_.pedestrian_size && z.width <= params_.pedestrian_size);
  if (t.manoeuvres)
    t.imm.reset(t.x, t.P, params_.acceleration_sigma * params_.acceleration_sigma, manoeuvreModel().stationaryManoeuvre());
  t.yaw = t.extent_yaw = z.yaw;
  t.length = t.extent_length = z.length;
  t.width = t.extent_width = z.width;
  t.hits = t.consecutive_hits = 1;
  t.first_stamp = t.last_hit = stamp;
  t.measurement = measurement;
  t.background_unchecked = !background_known_;
  t.state = bornState(lifecycleParams());
  if (free_now_) seeFreeSpace(t, stamp);
  decideMotion(t, stamp);
  ++counts_.tracks_created;
  return t;
}

SparseCosts Tracker::gate() const
{
  SparseCosts cost;
  cost.rows = static_cast<int>(tracks_.size());
  cost.cols = static_cast<int>(measurements_.size());
  if (cost.rows == 0 || cost.cols == 0) return cost;
  // The point a track follows (referencePoint()) lies within √2 c + ½ d of the cluster's centroid, c the farthest
  // corner of the cluster's box from it and d the diagonal of the track's box: a measurement's disc is its centroid's
  // of radius max_gate_distance + √2 c, a track's its position's of radius ½ d; pairs whose discs do not meet are
  // beyond the gate already.
  std::vector<GateDisc> track_discs(tracks_.size()), measurement_discs(measurements_.size());
  for (std::size_t m = 0; m < measurements_.size(); ++m)
  {
    const Measurement& z = measurements_[m];
    const double c = std::hypot(std::max(std::abs(z.lo_u), std::abs(z.hi_u)), std::max(std::abs(z.lo_v), std::abs(z.hi_v)));
    measurement_discs[m] = GateDisc{ z.centroid, params_.max_gate_distance + std::sqrt(2.0) * c + kGateSlack };
  }
  for (std::size_t t = 0; t < tracks_.size(); ++t)
    track_discs[t] = GateDisc{ tracks_[t].position(),
                               0.5 * std::hypot(tracks_[t].extent_length, tracks_[t].extent_width) + kGateSlack };
  const double cell = std::max(params_.max_gate_distance, kMinGateCell);
  for (const auto& [t, m] : spatialGate(track_discs, measurement_discs, cell))
    if (const std::optional<double> d2 = gateCost(tracks_[t], measurements_[m])) cost.pairs.push_back(GatedPair{ t, m, *d2 });
  return cost;
}

std::optional<double> Tracker::gateCost(const Track& t, const Measurement& z) const
{
  if (z.split && std::max(t.extent_length, t.extent_width) > params_.pedestrian_size) return std::nullopt;
  const Point2 ref = referencePoint(t, z);
  const Eigen::Vector2d y(ref.x - t.x(0), ref.y - t.x(1));
  if (y.norm() > params_.max_gate_distance) return std::nullopt;  // before the covariance: most pairs end here
  const Eigen::Matrix2d s = t.P.topLeftCorner<2, 2>() + anchorCovariance(trackView(t), z, measurement_model_);
  return mahalanobisGate(y, s, params_.max_gate_distance, params_.gate);
}

void Tracker::rememberSeenBoxes()
{
  for (Track& t : tracks_)
  {
    if (t.measurement < 0) continue;
    t.seen_box.valid = t.motion == TrackMotion::kMoving && t.speed() > 0.0;
    if (!t.seen_box.valid) continue;
    const ObjectBox b = objectBox(t, params_, measurements_);
    const double heading = std::atan2(t.x(3), t.x(2)), c = std::cos(heading), s = std::sin(heading);
    const double dx = b.centre.x - t.x(0), dy = b.centre.y - t.x(1);
    t.seen_box.along = c * dx + s * dy;
    t.seen_box.across = -s * dx + c * dy;
    t.seen_box.yaw = std::remainder(b.yaw - heading, 2.0 * M_PI);
    t.seen_box.length = b.length;
    t.seen_box.width = b.width;
  }
}

}  // namespace core
}  // namespace map_aided_fusion

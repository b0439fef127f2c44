#include "map_aided_fusion/sim/simulator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "map_aided_fusion/core/parameters.hpp"

namespace map_aided_fusion {
namespace sim {

namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;
constexpr double kTwoPi = 2.0 * 3.14159265358979323846;
constexpr double kTimeEpsilon = 1e-9;
/// Half the base over which the body's pitch and roll follow the terrain (wheelbase, track), m.
constexpr double kBodyHalfBase = 1.4;

/// splitmix64: small, fast, and the same on every platform (unlike std::normal_distribution).
class Rng
{
public:
  explicit Rng(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next()
  {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  double gaussian()
  {
    const double u1 = 1.0 - uniform();  // (0, 1]
    const double u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(kTwoPi * u2);
  }

private:
  std::uint64_t state_;
};

bool insideRing(const core::Ring& ring, core::Point2 p)
{
  bool inside = false;
  for (std::size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++)
  {
    const auto& a = ring[j];
    const auto& b = ring[i];
    if ((a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y)) inside = !inside;
  }
  return inside;
}

bool insidePolygon(const core::Polygon& poly, core::Point2 p)
{
  if (poly.outer.size() < 3 || !insideRing(poly.outer, p)) return false;
  for (const auto& h : poly.holes)
    if (h.size() >= 3 && insideRing(h, p)) return false;
  return true;
}

}  // namespace

Simulator::Simulator(Scenario scenario, const core::VectorMap& map) : scenario_(std::move(scenario))
{
  scenario_.validate();
  const MapErrors& errors = scenario_.map_errors;
  std::vector<bool> absent_point_used(errors.absent_at.size(), false);
  std::vector<bool> offset_used(errors.offsets.size(), false);
  const double rot = errors.rotation_deg * kDegToRad, cr = std::cos(rot), sr = std::sin(rot);
  const auto realPlace = [&](core::Polygon& poly, Point2 extra) {
    auto move = [&](core::Ring& ring) {
      for (Point2& p : ring)
        p = Point2{ cr * p.x - sr * p.y + errors.shift.x + extra.x, sr * p.x + cr * p.y + errors.shift.y + extra.y };
    };
    move(poly.outer);
    for (core::Ring& h : poly.holes) move(h);
  };
  std::vector<bool> absent_id_used(errors.absent_ids.size(), false);
  std::vector<WorldBuilding> world;
  for (const core::Building& b : map.buildings)
  {
    bool absent = false;
    for (std::size_t i = 0; i < errors.absent_at.size(); ++i)
      if (insidePolygon(b.footprint, errors.absent_at[i]))
      {
        absent = true;
        absent_point_used[i] = true;
      }
    for (std::size_t i = 0; i < errors.absent_ids.size(); ++i)
      if (!b.id.empty() && b.id == errors.absent_ids[i])
      {
        absent = true;
        absent_id_used[i] = true;
      }
    if (absent)
    {
      ++summary_.absent_buildings;
      continue;
    }
    WorldBuilding w;
    w.footprint = b.footprint;
    Point2 extra;
    for (std::size_t i = 0; i < errors.offsets.size(); ++i)
    {
      const BuildingOffset& o = errors.offsets[i];
      const bool hit = std::isnan(o.at.x) ? (!b.id.empty() && b.id == o.id) : insidePolygon(b.footprint, o.at);
      if (!hit) continue;
      offset_used[i] = true;
      extra.x += o.offset.x;
      extra.y += o.offset.y;
    }
    realPlace(w.footprint, extra);
    w.height = b.height > 0.0 ? b.height : scenario_.default_building_height;
    w.cell_class = core::CellClass::kBuilding;
    w.id = b.id;
    world.push_back(std::move(w));
    ++summary_.mapped_buildings;
  }
  for (std::size_t i = 0; i < absent_point_used.size(); ++i)
    if (!absent_point_used[i])
      throw core::ParameterError("map_errors.absent_buildings",
                                 "no map building contains (" + std::to_string(errors.absent_at[i].x) + ", " +
                                     std::to_string(errors.absent_at[i].y) + ")");
  for (std::size_t i = 0; i < absent_id_used.size(); ++i)
    if (!absent_id_used[i])
      throw core::ParameterError("map_errors.absent_buildings", "no map building has id '" + errors.absent_ids[i] + "'");
  for (std::size_t i = 0; i < offset_used.size(); ++i)
    if (!offset_used[i])
      throw core::ParameterError("map_errors.offset_buildings",
                                 "no map building matches entry " + std::to_string(i) + " (at or id)");
  const LocalisationError& le = scenario_.localisation_error;
  if (le.random_walk > 0.0)
  {
    const double dt = 1.0 / scenario_.tf_rate_hz;
    const double a = std::exp(-dt / le.random_walk_time), b = le.random_walk * std::sqrt(1.0 - a * a);
    Rng rng(scenario_.seed * 0xA0761D6478BD642FULL + 17);
    Point2 e{ le.random_walk * rng.gaussian(), le.random_walk * rng.gaussian() };
    const std::size_t n = static_cast<std::size_t>(std::ceil(scenario_.duration / dt)) + 2;
    walk_.reserve(n);
    for (std::size_t k = 0; k < n; ++k)
    {
      walk_.push_back(e);
      e = Point2{ a * e.x + b * rng.gaussian(), a * e.y + b * rng.gaussian() };
    }
  }
  for (WorldBuilding w : errors.unmapped)
  {
    w.cell_class = core::CellClass::kInfrastructure;
    world.push_back(std::move(w));
    ++summary_.unmapped_buildings;
  }
  static_raster_ = std::make_unique<StaticClassRaster>(world, scenario_.ground_truth.resolution);
  scene_ = std::make_unique<Scene>(std::move(world), scenario_.scene);
  ego_motion_ = std::make_unique<PathMotion>(scenario_.ego.route, scenario_.ego.motion);
  object_motion_.reserve(scenario_.objects.size());
  for (const ObjectSpec& o : scenario_.objects) object_motion_.emplace_back(o.path, o.motion);

  const LidarParams& lidar = scenario_.lidar;
  for (double e : lidar.elevations_deg)
  {
    const double rad = e * kDegToRad;
    cos_e_.push_back(std::cos(rad));
    sin_e_.push_back(std::sin(rad));
    slopes_.push_back(std::tan(rad));
    max_s_.push_back(lidar.max_range * std::cos(rad));
  }
  hits_.resize(slopes_.size());
}

Simulator::~Simulator() = default;

int Simulator::numScans() const
{
  return static_cast<int>(std::floor(scenario_.duration * scenario_.lidar.rate_hz + kTimeEpsilon));
}

double Simulator::scanTime(int k) const { return k / scenario_.lidar.rate_hz; }

Pose2 Simulator::egoPose(double t) const
{
  const MotionState st = ego_motion_->at(t);
  return Pose2{ st.x, st.y, st.yaw };
}

Pose2 Simulator::reportedEgoPose(double t) const
{
  Pose2 p = egoPose(t);
  const LocalisationError& le = scenario_.localisation_error;
  if (!le.any()) return p;
  const long k = std::max(0L, std::lround(t * scenario_.tf_rate_hz));
  p.x += le.bias.x;
  p.y += le.bias.y;
  p.yaw += le.bias_yaw_deg * kDegToRad;
  if (!walk_.empty())
  {
    const Point2& w = walk_[std::min(static_cast<std::size_t>(k), walk_.size() - 1)];
    p.x += w.x;
    p.y += w.y;
  }
  if (le.white_noise > 0.0)
  {
    Rng rng(scenario_.seed * 0xE7037ED1A0B428DBULL ^ (static_cast<std::uint64_t>(k) + 1) * 0x8EBC6AF09C88C6E3ULL);
    p.x += le.white_noise * rng.gaussian();
    p.y += le.white_noise * rng.gaussian();
  }
  return p;
}

double Simulator::egoSpeed(double t) const { return ego_motion_->at(t).speed; }

Pose2 Simulator::lidarPose(const Pose2& ego) const
{
  const LidarParams& l = scenario_.lidar;
  const double c = std::cos(ego.yaw), s = std::sin(ego.yaw);
  return Pose2{ ego.x + c * l.mount_x - s * l.mount_y, ego.y + s * l.mount_x + c * l.mount_y,
                ego.yaw + l.mount_yaw_deg * kDegToRad };
}

double Simulator::terrainHeight(double x, double y) const
{
  const Terrain& tr = scenario_.terrain;
  double h = 0.0;
  if (tr.grade > 0.0) h += tr.grade * tr.grade_length / kTwoPi * std::sin(kTwoPi * x / tr.grade_length);
  if (tr.camber > 0.0)
  {
    const std::vector<Point2>& route = scenario_.ego.route;
    double d2 = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i + 1 < route.size(); ++i)
    {
      const Point2 a = route[i], b = route[i + 1];
      const double ex = b.x - a.x, ey = b.y - a.y, len2 = ex * ex + ey * ey;
      const double u = len2 > 0.0 ? std::clamp(((x - a.x) * ex + (y - a.y) * ey) / len2, 0.0, 1.0) : 0.0;
      const double px = a.x + u * ex - x, py = a.y + u * ey - y;
      d2 = std::min(d2, px * px + py * py);
    }
    if (route.size() == 1) d2 = (x - route[0].x) * (x - route[0].x) + (y - route[0].y) * (y - route[0].y);
    h -= tr.camber * std::min(std::sqrt(d2), tr.camber_width);
  }
  return h;
}

void Simulator::bodyAttitude(double t, double& pitch, double& roll) const
{
  const Terrain& tr = scenario_.terrain;
  pitch = roll = 0.0;
  if (!tr.any()) return;
  const Pose2 e = egoPose(t);
  const double c = std::cos(e.yaw), s = std::sin(e.yaw), a = kBodyHalfBase;
  const double along = (terrainHeight(e.x + a * c, e.y + a * s) - terrainHeight(e.x - a * c, e.y - a * s)) / (2 * a);
  const double side = (terrainHeight(e.x - a * s, e.y + a * c) - terrainHeight(e.x + a * s, e.y - a * c)) / (2 * a);
  pitch = -std::atan(along) + tr.pitch_amplitude_deg * kDegToRad * std::sin(kTwoPi * t / tr.pitch_period);
  roll = std::atan(side);
}

void Simulator::objectsAt(double t, std::vector<WorldObject>& solids, std::vector<ObjectTruth>& truth) const
{
  solids.clear();
  truth.clear();
  for (std::size_t i = 0; i < scenario_.objects.size(); ++i)
  {
    const ObjectSpec& spec = scenario_.objects[i];
    const MotionState st = object_motion_[i].at(t);
    if (!st.present) continue;
    const double yaw = spec.path.size() == 1 ? spec.yaw_deg * kDegToRad : st.yaw;
    core::CellClass cls = core::CellClass::kInfrastructure;
    if (spec.forced_class != core::CellClass::kUnknown) cls = spec.forced_class;
    else if (spec.movable)
      cls = st.speed > scenario_.ground_truth.stop_speed ? core::CellClass::kMoving : core::CellClass::kStopped;
    WorldObject w;
    w.shape = spec.shape;
    w.cell_class = cls;
    w.material = spec.material;
    w.id = spec.id;
    ObjectTruth o;
    o.id = spec.id;
    o.cell_class = cls;
    o.kind = spec.kind;
    o.x = st.x;
    o.y = st.y;
    o.z = spec.z_min + 0.5 * spec.height;
    o.yaw = yaw;
    o.height = spec.height;
    o.vx = st.speed * std::cos(yaw);
    o.vy = st.speed * std::sin(yaw);
    if (spec.shape == WorldObject::Shape::kBox)
    {
      w.box = OrientedBox{ st.x, st.y, yaw, spec.length, spec.width, spec.z_min, spec.z_min + spec.height };
      o.length = spec.length;
      o.width = spec.width;
    }
    else
    {
      w.cylinder = Cylinder{ st.x, st.y, spec.radius, spec.z_min, spec.z_min + spec.height };
      o.length = o.width = 2.0 * spec.radius;
    }
    solids.push_back(w);
    truth.push_back(std::move(o));
  }
}

void Simulator::scan(int k, ScanFrame& out)
{
  const LidarParams& lidar = scenario_.lidar;
  const GroundTruthParams& gt = scenario_.ground_truth;
  out.index = k;
  out.time = scanTime(k);
  out.ego = egoPose(out.time);
  out.lidar = lidarPose(out.ego);
  out.points.clear();
  out.rays = out.no_return = out.dropped = 0;
  objectsAt(out.time, solids_, out.objects);
  scene_->setObjects(solids_);

  out.truth_geometry = static_raster_->window(out.ego.x, out.ego.y, gt.size_x, gt.size_y);
  static_raster_->classes(out.truth_geometry, scene_->objects(), out.truth_classes);
  observed_.assign(out.truth_geometry.numCells(), 0);
  object_hit_.assign(scene_->objects().size(), 0);

  Rng rng(scenario_.seed * 0x9E3779B97F4A7C15ULL ^ (static_cast<std::uint64_t>(k) + 1) * 0xD1B54A32D192ED03ULL);
  const int beams = lidar.numBeams();
  const int azimuths = lidar.numAzimuths();
  const double oz = lidar.mount_z;
  const bool terrain = scenario_.terrain.any();
  std::vector<double>& tilted = tilted_slopes_;
  tilted.assign(slopes_.begin(), slopes_.end());
  Pose2 origin = out.lidar;
  double pitch = 0.0, roll = 0.0, origin_h = 0.0;
  if (terrain) bodyAttitude(out.time, pitch, roll);
  for (int i = 0; i < azimuths; ++i)
  {
    const double offset = lidar.rolling_sweep ? scanPeriod() * i / azimuths : 0.0;
    if (lidar.rolling_sweep)
    {
      origin = lidarPose(egoPose(out.time + offset));
      if (terrain) bodyAttitude(out.time + offset, pitch, roll);
    }
    if (terrain) origin_h = terrainHeight(origin.x, origin.y);
    const double az_l = lidar.azimuthDeg(i) * kDegToRad;
    const double az_w = origin.yaw + az_l;
    const double ca = std::cos(az_l), sa = std::sin(az_l);
    const double cp = std::cos(pitch), sp = std::sin(pitch), cr = std::cos(roll), sr = std::sin(roll);
    if (terrain)
      for (int b = 0; b < beams; ++b)
      {
        // World elevation of the beam: the body-frame direction turned by roll (x) then pitch (y).
        const double dx = cos_e_[b] * ca, dy = cos_e_[b] * sa, dz = sin_e_[b];
        const double y1 = cr * dy - sr * dz, z1 = sr * dy + cr * dz;
        const double x2 = cp * dx + sp * z1, z2 = -sp * dx + cp * z1;
        tilted[b] = z2 / std::hypot(x2, y1);
      }
    scene_->castFan(origin.x, origin.y, oz, az_w, tilted.data(), max_s_.data(), beams, hits_.data());
    double s_obs = -1.0;
    for (int b = 0; b < beams; ++b)
    {
      ++out.rays;
      const BeamHit& h = hits_[b];
      if (h.solid == BeamHit::kNone)
      {
        ++out.no_return;
        if (gt.include_no_return_rays) s_obs = std::max(s_obs, max_s_[b]);
        continue;
      }
      s_obs = std::max(s_obs, h.s);
      if (h.solid >= Scene::kObjectBase) object_hit_[static_cast<std::size_t>(h.solid - Scene::kObjectBase)] = 1;
      if (rng.uniform() < lidar.dropout_probability)
      {
        ++out.dropped;
        continue;
      }
      const double cos_w = terrain ? 1.0 / std::sqrt(1.0 + tilted[b] * tilted[b]) : cos_e_[b];
      const double r = h.s / cos_w + lidar.range_noise_stddev * rng.gaussian();
      if (r < lidar.min_range || r > lidar.max_range)
      {
        ++out.dropped;
        continue;
      }
      LidarPoint p;
      if (terrain)
      {
        // The return in the level frame of the lidar's yaw, raised by the terrain, then into the tilted body.
        const double horizontal = r * cos_w;
        const double hx = horizontal * std::cos(az_w), hy = horizontal * std::sin(az_w);
        const double lift = terrainHeight(origin.x + hx, origin.y + hy) - origin_h;
        const double vx = horizontal * ca, vy = horizontal * sa, vz = r * tilted[b] * cos_w + lift;
        const double x1 = cp * vx - sp * vz, z1 = sp * vx + cp * vz;
        p.x = static_cast<float>(x1);
        p.y = static_cast<float>(cr * vy + sr * z1);
        p.z = static_cast<float>(-sr * vy + cr * z1);
      }
      else
      {
        const double horizontal = r * cos_e_[b];
        p.x = static_cast<float>(horizontal * ca);
        p.y = static_cast<float>(horizontal * sa);
        p.z = static_cast<float>(r * sin_e_[b]);
      }
      p.intensity = materialIntensity(scene_->materialOf(h.solid));
      p.ring = static_cast<std::uint16_t>(b);
      p.time = static_cast<float>(offset);
      out.points.push_back(p);
    }
    if (s_obs >= 0.0)
      traverseCells(out.truth_geometry, core::Point2{ origin.x, origin.y }, std::cos(az_w), std::sin(az_w), s_obs,
                    [&](std::size_t c) { observed_[c] = 1; });
  }
  if (gt.object_needs_hit)
  {
    constexpr std::int8_t kNoFootprint = std::numeric_limits<std::int8_t>::min();
    hidden_cells_.assign(observed_.size(), kNoFootprint);
    for (std::size_t j = 0; j < object_hit_.size(); ++j)
      if (!object_hit_[j]) rasterizeObject(scene_->objects()[j], out.truth_geometry, hidden_cells_);
    for (std::size_t c = 0; c < observed_.size(); ++c)
      if (hidden_cells_[c] != kNoFootprint) observed_[c] = 0;
  }
  for (std::size_t c = 0; c < observed_.size(); ++c)
    if (!observed_[c]) out.truth_classes[c] = static_cast<std::int8_t>(core::CellClass::kUnknown);
}

}  // namespace sim
}  // namespace map_aided_fusion

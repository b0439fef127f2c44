#include "map_aided_fusion/sim/scenario.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <set>
#include <sstream>

#include "map_aided_fusion/core/parameters.hpp"

namespace map_aided_fusion {
namespace sim {

namespace {

constexpr double kMaxDuration = 24.0 * 3600.0;
constexpr double kMinTfRate = 50.0;
constexpr double kMaxTfRate = 1000.0;
constexpr double kMaxGtSize = 2000.0;
constexpr double kMaxObjectSize = 50.0;
constexpr double kMaxBuildingHeight = 1000.0;
/// Largest pose or map error a scenario may ask for, metres.
constexpr double kMaxLocalisationError = 50.0;
constexpr double kMaxStopSpeed = 5.0;
constexpr double kMaxGrade = 0.3;
constexpr double kMinGradeLength = 10.0;
constexpr double kMaxGradeLength = 10000.0;
constexpr double kMaxCamber = 0.2;
constexpr double kMaxCamberWidth = 100.0;
constexpr double kMaxPitchDeg = 10.0;
constexpr double kMinPitchPeriod = 0.1;

using core::ParameterError;

/// @throws ParameterError naming the first key of the mapping @p n (at @p path) that is not in @p known.
void requireKnownKeys(const YAML::Node& n, const std::string& path, std::initializer_list<const char*> known)
{
  if (!n || !n.IsMap()) return;
  for (const auto& kv : n)
  {
    const std::string key = kv.first.as<std::string>();
    if (std::none_of(known.begin(), known.end(), [&](const char* k) { return key == k; }))
    {
      std::string list;
      for (const char* k : known) list += (list.empty() ? "" : ", ") + std::string(k);
      throw ParameterError(path + key, "is not a scenario key (here: " + list + ")");
    }
  }
}

template <class T>
T get(const YAML::Node& n, const std::string& key, const std::string& path, const T& fallback)
{
  const YAML::Node v = n[key];
  if (!v) return fallback;
  try
  {
    return v.as<T>();
  }
  catch (const YAML::Exception&)
  {
    throw ParameterError(path + key, "has the wrong type");
  }
}

double getDuration(const YAML::Node& n, const std::string& key, const std::string& path, double fallback)
{
  const YAML::Node v = n[key];
  if (v && v.IsScalar() && (v.Scalar() == "forever" || v.Scalar() == "inf"))
    return std::numeric_limits<double>::infinity();
  return get<double>(n, key, path, fallback);
}

Point2 toPoint(const YAML::Node& n, const std::string& path)
{
  if (!n.IsSequence() || n.size() != 2) throw ParameterError(path, "must be a point [x, y]");
  try
  {
    const Point2 p{ n[0].as<double>(), n[1].as<double>() };
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) throw ParameterError(path, "must be finite");
    return p;
  }
  catch (const YAML::Exception&)
  {
    throw ParameterError(path, "must be a point [x, y] of numbers");
  }
}

std::vector<Point2> toPoints(const YAML::Node& n, const std::string& path)
{
  if (!n || !n.IsSequence()) throw ParameterError(path, "must be a list of points [[x, y], ...]");
  std::vector<Point2> pts;
  for (std::size_t i = 0; i < n.size(); ++i) pts.push_back(toPoint(n[i], path + "[" + std::to_string(i) + "]"));
  return pts;
}

void readMotion(const YAML::Node& n, const std::string& path, const std::vector<Point2>& points, MotionParams& m)
{
  m.speed = get<double>(n, "speed", path, m.speed);
  m.acceleration = get<double>(n, "acceleration", path, m.acceleration);
  m.start_time = get<double>(n, "start_time", path, m.start_time);
  m.corner_radius = get<double>(n, "corner_radius", path, m.corner_radius);
  const std::string end = get<std::string>(n, "end", path, m.end == PathEnd::kStay ? "stay" : "vanish");
  if (end == "stay") m.end = PathEnd::kStay;
  else if (end == "vanish") m.end = PathEnd::kVanish;
  else throw ParameterError(path + "end", "must be 'stay' or 'vanish'");
  m.validate(path);
  m.stops.clear();
  const YAML::Node stops = n["stops"];
  if (!stops) return;
  if (!stops.IsSequence()) throw ParameterError(path + "stops", "must be a list");
  MotionParams plain = m;
  const PathMotion geometry(points, plain);
  for (std::size_t i = 0; i < stops.size(); ++i)
  {
    const std::string sp = path + "stops[" + std::to_string(i) + "].";
    requireKnownKeys(stops[i], sp, { "at", "s", "duration" });
    Stop st;
    if (stops[i]["at"]) st.s = geometry.project(toPoint(stops[i]["at"], sp + "at"));
    else if (stops[i]["s"]) st.s = get<double>(stops[i], "s", sp, 0.0);
    else throw ParameterError(sp + "at", "a stop needs 'at: [x, y]' or 's: metres'");
    st.duration = getDuration(stops[i], "duration", sp, 0.0);
    m.stops.push_back(st);
  }
  m.validate(path);
}

core::CellClass parseClass(const std::string& s, const std::string& path)
{
  if (s == "auto") return core::CellClass::kUnknown;
  if (s == "N") return core::CellClass::kInfrastructure;
  if (s == "S") return core::CellClass::kStopped;
  if (s == "V") return core::CellClass::kMoving;
  throw ParameterError(path, "must be auto, N, S or V");
}

}  // namespace

bool objectKindDefaults(const std::string& kind, ObjectSpec& o)
{
  using Shape = WorldObject::Shape;
  struct Kind
  {
    const char* name;
    Shape shape;
    double length, width, height, radius;
    bool movable;
    Material material;
  };
  static const Kind kKinds[] = {
    { "car", Shape::kBox, 4.5, 1.8, 1.5, 0.0, true, Material::kVehicle },
    { "van", Shape::kBox, 5.2, 2.0, 2.2, 0.0, true, Material::kVehicle },
    { "bus", Shape::kBox, 12.0, 2.55, 3.2, 0.0, true, Material::kVehicle },
    { "truck", Shape::kBox, 8.0, 2.5, 3.5, 0.0, true, Material::kVehicle },
    { "cyclist", Shape::kBox, 1.8, 0.6, 1.7, 0.0, true, Material::kPedestrian },
    { "pedestrian", Shape::kCylinder, 0.0, 0.0, 1.75, 0.3, true, Material::kPedestrian },
    { "pole", Shape::kCylinder, 0.0, 0.0, 6.0, 0.15, false, Material::kStreetFurniture },
    { "bin", Shape::kBox, 0.6, 0.6, 1.1, 0.0, false, Material::kStreetFurniture },
    { "tree", Shape::kCylinder, 0.0, 0.0, 7.0, 0.4, false, Material::kVegetation },
    { "box", Shape::kBox, 1.0, 1.0, 1.0, 0.0, false, Material::kStreetFurniture },
  };
  for (const Kind& k : kKinds)
    if (kind == k.name)
    {
      o.kind = kind;
      o.shape = k.shape;
      o.length = k.length;
      o.width = k.width;
      o.height = k.height;
      o.radius = k.radius;
      o.movable = k.movable;
      o.material = k.material;
      return true;
    }
  return false;
}

void GroundTruthParams::validate() const
{
  core::requireInRange("ground_truth.size_x", size_x, 1e-2, kMaxGtSize);
  core::requireInRange("ground_truth.size_y", size_y, 1e-2, kMaxGtSize);
  core::requireInRange("ground_truth.resolution", resolution, 1e-2, std::min(size_x, size_y));
  core::requireInRange("ground_truth.stop_speed", stop_speed, 0.0, kMaxStopSpeed);
}

double LocalisationError::reportedSigma() const
{
  if (reported_sigma >= 0.0) return reported_sigma;
  return std::sqrt(bias.x * bias.x + bias.y * bias.y + random_walk * random_walk + white_noise * white_noise);
}

void Scenario::validate() const
{
  core::requireInRange("duration", duration, 0.0, kMaxDuration);
  core::requireInRange("default_building_height", default_building_height, 0.1, kMaxBuildingHeight);
  core::requireInRange("tf_rate_hz", tf_rate_hz, kMinTfRate, kMaxTfRate);
  core::requireInRange("start_stamp", start_stamp, 1.0, 4.0e9);
  lidar.validate();
  ground_truth.validate();
  scene.validate();
  if (ego.route.empty()) throw ParameterError("ego.route", "needs at least one point");
  ego.motion.validate("ego.");
  std::set<std::uint32_t> ids;
  for (const ObjectSpec& o : objects)
  {
    const std::string p = "objects[id " + std::to_string(o.id) + "].";
    if (!ids.insert(o.id).second) throw ParameterError(p + "id", "is not unique");
    if (o.path.empty()) throw ParameterError(p + "path", "needs at least one point");
    core::requireInRange(p + "height", o.height, 1e-3, kMaxObjectSize);
    core::requireInRange(p + "z_min", o.z_min, 0.0, kMaxObjectSize);
    if (o.shape == WorldObject::Shape::kBox)
    {
      core::requireInRange(p + "length", o.length, 1e-3, kMaxObjectSize);
      core::requireInRange(p + "width", o.width, 1e-3, kMaxObjectSize);
    }
    else
    {
      core::requireInRange(p + "radius", o.radius, 1e-3, kMaxObjectSize);
    }
    o.motion.validate(p);
  }
  const LocalisationError& le = localisation_error;
  core::requireInRange("localisation_error.bias", std::hypot(le.bias.x, le.bias.y), 0.0, kMaxLocalisationError);
  core::requireInRange("localisation_error.bias_yaw_deg", le.bias_yaw_deg, -180.0, 180.0);
  core::requireInRange("localisation_error.random_walk", le.random_walk, 0.0, kMaxLocalisationError);
  core::requireInRange("localisation_error.random_walk_time", le.random_walk_time, 0.1, kMaxDuration);
  core::requireInRange("localisation_error.white_noise", le.white_noise, 0.0, kMaxLocalisationError);
  core::requireInRange("localisation_error.reported_sigma", le.reported_sigma, -1.0, kMaxLocalisationError);
  core::requireInRange("localisation_error.covariance_rate_hz", le.covariance_rate_hz, 0.1, kMaxTfRate);
  core::requireInRange("map_errors.shift", std::hypot(map_errors.shift.x, map_errors.shift.y), 0.0, kMaxLocalisationError);
  core::requireInRange("map_errors.rotation_deg", map_errors.rotation_deg, -180.0, 180.0);
  core::requireInRange("terrain.grade", terrain.grade, 0.0, kMaxGrade);
  core::requireInRange("terrain.grade_length", terrain.grade_length, kMinGradeLength, kMaxGradeLength);
  core::requireInRange("terrain.camber", terrain.camber, 0.0, kMaxCamber);
  core::requireInRange("terrain.camber_width", terrain.camber_width, 0.0, kMaxCamberWidth);
  core::requireInRange("terrain.pitch_amplitude_deg", terrain.pitch_amplitude_deg, 0.0, kMaxPitchDeg);
  core::requireInRange("terrain.pitch_period", terrain.pitch_period, kMinPitchPeriod, kMaxDuration);
  for (const BuildingOffset& o : map_errors.offsets)
    core::requireInRange("map_errors.offset_buildings.offset", std::hypot(o.offset.x, o.offset.y), 0.0, kMaxLocalisationError);
  for (const WorldBuilding& b : map_errors.unmapped)
  {
    if (b.footprint.outer.size() < 3)
      throw ParameterError("map_errors.unmapped_buildings.footprint", "needs at least 3 points");
    core::requireInRange("map_errors.unmapped_buildings.height", b.height, 0.1, kMaxBuildingHeight);
  }
}

Scenario parseScenario(const std::string& yaml_text, const std::string& base_dir)
{
  YAML::Node root;
  try
  {
    root = YAML::Load(yaml_text);
  }
  catch (const YAML::Exception& e)
  {
    throw ParameterError("yaml", e.what());
  }
  if (!root.IsMap()) throw ParameterError("yaml", "a scenario must be a YAML mapping");
  if (const YAML::Node base = root["base"])
  {
    const std::string name = get<std::string>(root, "base", "", "");
    const std::string path = (name.front() == '/' || base_dir.empty()) ? name : base_dir + "/" + name;
    YAML::Node merged;
    try
    {
      merged = YAML::LoadFile(path);
    }
    catch (const YAML::Exception& e)
    {
      throw ParameterError("base", "cannot read scenario '" + path + "': " + e.what());
    }
    if (!merged.IsMap() || merged["base"]) throw ParameterError("base", "'" + path + "' must be a scenario without a base");
    for (const auto& kv : root)
      if (kv.first.as<std::string>() != "base") merged[kv.first.as<std::string>()] = kv.second;
    root = merged;
  }
  requireKnownKeys(root, "", { "name", "map", "map_origin", "duration", "seed", "default_building_height", "tf_rate_hz",
                               "start_stamp", "lidar", "ground_truth", "scene", "ego", "map_errors",
                               "localisation_error", "terrain", "objects" });
  Scenario sc;
  sc.name = get<std::string>(root, "name", "", sc.name);
  const std::string map = get<std::string>(root, "map", "", "");
  if (!map.empty()) sc.map_file = (map.front() == '/' || base_dir.empty()) ? map : base_dir + "/" + map;
  if (const YAML::Node origin = root["map_origin"])
  {
    const auto v = get<std::vector<double>>(root, "map_origin", "", {});
    if (v.size() < 2 || v.size() > 3) throw ParameterError("map_origin", "must be [latitude, longitude(, altitude)]");
    core::requireInRange("map_origin", v[0], -90.0, 90.0);
    core::requireInRange("map_origin", v[1], -180.0, 180.0);
    sc.map_origin_latitude = v[0];
    sc.map_origin_longitude = v[1];
    if (v.size() == 3) sc.map_origin_altitude = v[2];
  }
  sc.duration = get<double>(root, "duration", "", sc.duration);
  sc.seed = get<std::uint64_t>(root, "seed", "", sc.seed);
  sc.default_building_height = get<double>(root, "default_building_height", "", sc.default_building_height);
  sc.tf_rate_hz = get<double>(root, "tf_rate_hz", "", sc.tf_rate_hz);
  sc.start_stamp = get<double>(root, "start_stamp", "", sc.start_stamp);

  if (const YAML::Node l = root["lidar"])
  {
    requireKnownKeys(l, "lidar.", { "preset", "elevations_deg", "azimuth_resolution_deg", "fov_deg", "min_range",
                                    "max_range", "range_noise_stddev", "dropout_probability", "rate_hz", "mount_x",
                                    "mount_y", "mount_z", "mount_yaw_deg", "rolling_sweep" });
    const std::string preset = get<std::string>(l, "preset", "lidar.", "vlp32");
    sc.lidar = LidarParams::fromPreset(preset);
    LidarParams& p = sc.lidar;
    if (l["elevations_deg"]) p.elevations_deg = get<std::vector<double>>(l, "elevations_deg", "lidar.", {});
    p.azimuth_resolution_deg = get<double>(l, "azimuth_resolution_deg", "lidar.", p.azimuth_resolution_deg);
    p.fov_deg = get<double>(l, "fov_deg", "lidar.", p.fov_deg);
    p.min_range = get<double>(l, "min_range", "lidar.", p.min_range);
    p.max_range = get<double>(l, "max_range", "lidar.", p.max_range);
    p.range_noise_stddev = get<double>(l, "range_noise_stddev", "lidar.", p.range_noise_stddev);
    p.dropout_probability = get<double>(l, "dropout_probability", "lidar.", p.dropout_probability);
    p.rate_hz = get<double>(l, "rate_hz", "lidar.", p.rate_hz);
    p.mount_x = get<double>(l, "mount_x", "lidar.", p.mount_x);
    p.mount_y = get<double>(l, "mount_y", "lidar.", p.mount_y);
    p.mount_z = get<double>(l, "mount_z", "lidar.", p.mount_z);
    p.mount_yaw_deg = get<double>(l, "mount_yaw_deg", "lidar.", p.mount_yaw_deg);
    p.rolling_sweep = get<bool>(l, "rolling_sweep", "lidar.", p.rolling_sweep);
  }
  if (const YAML::Node g = root["ground_truth"])
  {
    requireKnownKeys(g, "ground_truth.",
                     { "size_x", "size_y", "resolution", "stop_speed", "include_no_return_rays", "object_needs_hit" });
    GroundTruthParams& p = sc.ground_truth;
    p.size_x = get<double>(g, "size_x", "ground_truth.", p.size_x);
    p.size_y = get<double>(g, "size_y", "ground_truth.", p.size_y);
    p.resolution = get<double>(g, "resolution", "ground_truth.", p.resolution);
    p.stop_speed = get<double>(g, "stop_speed", "ground_truth.", p.stop_speed);
    p.include_no_return_rays = get<bool>(g, "include_no_return_rays", "ground_truth.", p.include_no_return_rays);
    p.object_needs_hit = get<bool>(g, "object_needs_hit", "ground_truth.", p.object_needs_hit);
  }
  if (const YAML::Node s = root["scene"])
  {
    requireKnownKeys(s, "scene.", { "cell_size", "margin" });
    sc.scene.cell_size = get<double>(s, "cell_size", "scene.", sc.scene.cell_size);
    sc.scene.margin = get<double>(s, "margin", "scene.", sc.scene.margin);
  }
  const YAML::Node ego = root["ego"];
  if (!ego) throw ParameterError("ego", "is required (route, speed, stops)");
  requireKnownKeys(ego, "ego.", { "route", "speed", "acceleration", "start_time", "corner_radius", "end", "stops" });
  sc.ego.route = toPoints(ego["route"], "ego.route");
  readMotion(ego, "ego.", sc.ego.route, sc.ego.motion);

  if (const YAML::Node errors = root["map_errors"])
  {
    requireKnownKeys(errors, "map_errors.",
                     { "unmapped_buildings", "absent_buildings", "shift", "rotation_deg", "offset_buildings" });
    if (const YAML::Node u = errors["unmapped_buildings"])
      for (std::size_t i = 0; i < u.size(); ++i)
      {
        const std::string p = "map_errors.unmapped_buildings[" + std::to_string(i) + "].";
        requireKnownKeys(u[i], p, { "name", "footprint", "height" });
        WorldBuilding b;
        b.footprint.outer = toPoints(u[i]["footprint"], p + "footprint");
        b.height = get<double>(u[i], "height", p, sc.default_building_height);
        b.id = get<std::string>(u[i], "name", p, "unmapped_" + std::to_string(i));
        b.cell_class = core::CellClass::kInfrastructure;
        sc.map_errors.unmapped.push_back(std::move(b));
      }
    if (const YAML::Node shift = errors["shift"]) sc.map_errors.shift = toPoint(shift, "map_errors.shift");
    sc.map_errors.rotation_deg = get<double>(errors, "rotation_deg", "map_errors.", 0.0);
    if (const YAML::Node o = errors["offset_buildings"])
      for (std::size_t i = 0; i < o.size(); ++i)
      {
        const std::string p = "map_errors.offset_buildings[" + std::to_string(i) + "].";
        requireKnownKeys(o[i], p, { "at", "id", "offset" });
        BuildingOffset b;
        if (o[i]["at"]) b.at = toPoint(o[i]["at"], p + "at");
        else if (o[i]["id"]) b.id = get<std::string>(o[i], "id", p, "");
        else throw ParameterError(p + "at", "an offset building needs 'at: [x, y]' or 'id: ...'");
        if (!o[i]["offset"]) throw ParameterError(p + "offset", "is required: [dx, dy] in metres");
        b.offset = toPoint(o[i]["offset"], p + "offset");
        sc.map_errors.offsets.push_back(std::move(b));
      }
    if (const YAML::Node a = errors["absent_buildings"])
      for (std::size_t i = 0; i < a.size(); ++i)
      {
        const std::string p = "map_errors.absent_buildings[" + std::to_string(i) + "].";
        requireKnownKeys(a[i], p, { "at", "id" });
        if (a[i]["at"]) sc.map_errors.absent_at.push_back(toPoint(a[i]["at"], p + "at"));
        else if (a[i]["id"]) sc.map_errors.absent_ids.push_back(get<std::string>(a[i], "id", p, ""));
        else throw ParameterError(p + "at", "an absent building needs 'at: [x, y]' or 'id: ...'");
      }
  }

  if (const YAML::Node l = root["localisation_error"])
  {
    LocalisationError& e = sc.localisation_error;
    const std::string p = "localisation_error.";
    requireKnownKeys(l, p, { "bias", "bias_yaw_deg", "random_walk", "random_walk_time", "white_noise", "reported_sigma",
                             "covariance_rate_hz" });
    if (l["bias"]) e.bias = toPoint(l["bias"], p + "bias");
    e.bias_yaw_deg = get<double>(l, "bias_yaw_deg", p, e.bias_yaw_deg);
    e.random_walk = get<double>(l, "random_walk", p, e.random_walk);
    e.random_walk_time = get<double>(l, "random_walk_time", p, e.random_walk_time);
    e.white_noise = get<double>(l, "white_noise", p, e.white_noise);
    e.reported_sigma = get<double>(l, "reported_sigma", p, e.reported_sigma);
    e.covariance_rate_hz = get<double>(l, "covariance_rate_hz", p, e.covariance_rate_hz);
  }

  if (const YAML::Node t = root["terrain"])
  {
    Terrain& e = sc.terrain;
    const std::string p = "terrain.";
    requireKnownKeys(t, p, { "grade", "grade_length", "camber", "camber_width", "pitch_amplitude_deg", "pitch_period" });
    e.grade = get<double>(t, "grade", p, e.grade);
    e.grade_length = get<double>(t, "grade_length", p, e.grade_length);
    e.camber = get<double>(t, "camber", p, e.camber);
    e.camber_width = get<double>(t, "camber_width", p, e.camber_width);
    e.pitch_amplitude_deg = get<double>(t, "pitch_amplitude_deg", p, e.pitch_amplitude_deg);
    e.pitch_period = get<double>(t, "pitch_period", p, e.pitch_period);
  }

  if (const YAML::Node objects = root["objects"])
  {
    if (!objects.IsSequence()) throw ParameterError("objects", "must be a list");
    std::uint32_t next_id = 1;
    for (std::size_t i = 0; i < objects.size(); ++i)
    {
      const YAML::Node n = objects[i];
      const std::string p = "objects[" + std::to_string(i) + "].";
      requireKnownKeys(n, p, { "id", "kind", "path", "at", "yaw_deg", "length", "width", "height", "radius", "z_min",
                               "speed", "acceleration", "corner_radius", "start_time", "end", "stops", "class" });
      ObjectSpec o;
      const std::string kind = get<std::string>(n, "kind", p, "car");
      if (!objectKindDefaults(kind, o))
        throw ParameterError(p + "kind", "unknown kind '" + kind + "' (car, van, bus, truck, cyclist, pedestrian, "
                                         "pole, bin, tree, box)");
      o.id = get<std::uint32_t>(n, "id", p, next_id);
      next_id = std::max(next_id, o.id + 1);
      o.length = get<double>(n, "length", p, o.length);
      o.width = get<double>(n, "width", p, o.width);
      o.height = get<double>(n, "height", p, o.height);
      o.radius = get<double>(n, "radius", p, o.radius);
      o.z_min = get<double>(n, "z_min", p, o.z_min);
      o.yaw_deg = get<double>(n, "yaw_deg", p, o.yaw_deg);
      o.forced_class = parseClass(get<std::string>(n, "class", p, "auto"), p + "class");
      if (n["at"]) o.path = { toPoint(n["at"], p + "at") };
      else o.path = toPoints(n["path"], p + "path");
      if (o.path.size() == 1) o.motion.speed = 0.0;
      readMotion(n, p, o.path, o.motion);
      sc.objects.push_back(std::move(o));
    }
  }
  sc.validate();
  return sc;
}

Scenario loadScenario(const std::string& path)
{
  std::ifstream in(path);
  if (!in) throw ParameterError("scenario", "cannot read '" + path + "'");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::size_t slash = path.find_last_of('/');
  const std::string dir = slash == std::string::npos ? "." : path.substr(0, slash);
  Scenario sc = parseScenario(ss.str(), dir);
  sc.source = path;
  return sc;
}

}  // namespace sim
}  // namespace map_aided_fusion

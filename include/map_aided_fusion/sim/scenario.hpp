/**
 * @file scenario.hpp
 * @brief A simulation scenario (map, ego route, objects with paths, speeds and stops, map errors, lidar,
 *        seed, duration) and its YAML loader. See scenarios/default.yaml for the documented format.
 */
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "map_aided_fusion/core/cell_class.hpp"
#include "map_aided_fusion/sim/lidar.hpp"
#include "map_aided_fusion/sim/motion.hpp"
#include "map_aided_fusion/sim/scene.hpp"

namespace map_aided_fusion {
namespace sim {

/// One object of a scenario (a path of one point is a static object).
struct ObjectSpec
{
  std::uint32_t id = 0;
  std::string kind = "car";  ///< car, bus, truck, pedestrian, cyclist, pole, bin, tree, box
  WorldObject::Shape shape = WorldObject::Shape::kBox;
  double length = 4.5;  ///< m (boxes)
  double width = 1.8;   ///< m (boxes)
  double height = 1.5;  ///< m
  double radius = 0.3;  ///< m (cylinders)
  double z_min = 0.0;   ///< m, height of the object's underside
  double yaw_deg = 0.0; ///< heading of a static object (one-point path)
  bool movable = true;  ///< vehicles and people: S when stopped, V when moving; others: N
  /// Forced class (N, S or V), or kUnknown for the automatic rule above.
  core::CellClass forced_class = core::CellClass::kUnknown;
  Material material = Material::kVehicle;
  std::vector<Point2> path;
  MotionParams motion;
};

/// The ego vehicle: its route and its motion along it.
struct EgoSpec
{
  std::vector<Point2> route;
  MotionParams motion;
};

/// A mapped building that stands elsewhere in the real world.
struct BuildingOffset
{
  Point2 at{ std::numeric_limits<double>::quiet_NaN(), 0.0 };  ///< a point inside it (NaN: use id)
  std::string id;                                               ///< or its map id
  Point2 offset;                                                ///< real position − mapped position, metres
};

/// Differences between the real world and the map.
struct MapErrors
{
  std::vector<WorldBuilding> unmapped;     ///< real buildings that the map lacks (ground truth N)
  std::vector<Point2> absent_at;           ///< mapped buildings, found by a point inside, that are not there
  std::vector<std::string> absent_ids;     ///< mapped buildings, by map id, that are not there
  /// The whole map is off: the real buildings are the mapped ones rotated by rotation_deg about the map origin,
  /// then shifted by shift (metres).
  Point2 shift;
  double rotation_deg = 0.0;
  std::vector<BuildingOffset> offsets;     ///< single buildings off by their own offset (after the whole-map error)
};

/**
 * @brief What the localisation publishes beyond the truth: the tf map → base_link carries the true pose plus
 *        bias + random walk + white noise; the ground truth does not. Also a pose covariance topic.
 */
struct LocalisationError
{
  Point2 bias;                 ///< constant position error, metres
  double bias_yaw_deg = 0.0;   ///< constant heading error, degrees
  double random_walk = 0.0;    ///< stationary σ of a slow random walk per axis (Ornstein–Uhlenbeck), metres
  double random_walk_time = 10.0;  ///< its correlation time, s (> 0)
  double white_noise = 0.0;    ///< σ of independent noise on each published pose, per axis, metres
  /// σ the localisation reports in its covariance, metres; < 0: sqrt(|bias|² + random_walk² + white_noise²).
  double reported_sigma = -1.0;
  double covariance_rate_hz = 10.0;  ///< rate of the covariance topic (> 0)
  bool any() const { return bias.x != 0.0 || bias.y != 0.0 || bias_yaw_deg != 0.0 || random_walk > 0.0 || white_noise > 0.0; }
  /// The σ published in the covariance.
  double reportedSigma() const;
};

/**
 * @brief A ground that is not flat, and an ego that pitches. The terrain height at (x, y), map frame, is
 *        h = grade · grade_length / 2π · sin(2π x / grade_length) (rolling hills along x, steepest slope = grade)
 *        − camber · min(d, camber_width), d the distance to the ego's route (the road's crown).
 *
 * The ego's body follows the terrain's slope at its position (pitch and roll over its wheelbase), plus a pitch
 * oscillation of pitch_amplitude_deg and period pitch_period (braking, bumps); the lidar is fixed to the body,
 * while the published tf stays level. Rays are cast in the flat world with the body's tilt, and every return is
 * raised by the terrain height at its (x, y) relative to the ego's (buildings and objects stand on the terrain).
 */
struct Terrain
{
  double grade = 0.0;            ///< steepest slope of the hills (rise / run), [0, 0.3]
  double grade_length = 200.0;   ///< m, wavelength of the hills, [10, 10000]
  double camber = 0.0;           ///< cross fall from the crown (rise / run), [0, 0.2]
  double camber_width = 7.0;     ///< m, the fall stops this far from the crown (the kerb), [0, 100]
  double pitch_amplitude_deg = 0.0;  ///< deg, [0, 10]
  double pitch_period = 3.0;         ///< s, [0.1, 1000]
  bool any() const { return grade > 0.0 || camber > 0.0 || pitch_amplitude_deg > 0.0; }
};

/// Ground-truth raster parameters.
struct GroundTruthParams
{
  double size_x = 100.0;     ///< m, window around the ego
  double size_y = 100.0;     ///< m
  double resolution = 0.5;   ///< m
  double stop_speed = 0.1;   ///< m/s, a movable object slower than this is stopped (S)
  /// Count the cells traversed by rays without any return (up to their max range) as observed.
  bool include_no_return_rays = false;
  /// An object's footprint is observed only in a scan in which some ray hit the object (its cells are -1 otherwise):
  /// the rays that pass over a pedestrian hidden behind a parked car, to a facade behind, do not see it.
  bool object_needs_hit = true;
  /// @throws core::ParameterError naming the parameter
  void validate() const;
};

/// A whole scenario.
struct Scenario
{
  std::string name = "scenario";
  std::string source;    ///< the YAML file it was loaded from, if any
  std::string map_file;  ///< absolute or relative to the working directory (resolved by loadScenario)
  /// WGS84 origin of the map frame (degrees, degrees, metres); NaN: the map loader's default (data centre).
  double map_origin_latitude = std::numeric_limits<double>::quiet_NaN();
  double map_origin_longitude = std::numeric_limits<double>::quiet_NaN();
  double map_origin_altitude = 0.0;
  double duration = 60.0;               ///< s
  std::uint64_t seed = 1;
  double default_building_height = 10.0;  ///< m, for map buildings without height
  double tf_rate_hz = 100.0;              ///< map→base_link rate in the bag (≥ 50)
  double start_stamp = 1.6e9;             ///< s, ROS time of t = 0
  LidarParams lidar = LidarParams::fromPreset("vlp32");
  EgoSpec ego;
  std::vector<ObjectSpec> objects;
  MapErrors map_errors;
  LocalisationError localisation_error;
  Terrain terrain;
  GroundTruthParams ground_truth;
  SceneParams scene;

  /// @throws core::ParameterError naming the parameter
  void validate() const;
};

/// The defaults (shape, size, material, mobility) of an object kind; false for an unknown kind.
bool objectKindDefaults(const std::string& kind, ObjectSpec& spec);

/**
 * @brief Parses a scenario from YAML text. Relative file names (map, base) are resolved against @p base_dir.
 *        `base: other.yaml` loads that scenario first; this file's top-level keys then replace its keys.
 * @throws core::ParameterError naming the offending key (YAML syntax errors are reported as key "yaml").
 */
Scenario parseScenario(const std::string& yaml_text, const std::string& base_dir);

/// Loads a scenario file (relative names in it are resolved against the file's folder).
Scenario loadScenario(const std::string& path);

}  // namespace sim
}  // namespace map_aided_fusion

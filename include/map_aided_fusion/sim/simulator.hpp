/**
 * @file simulator.hpp
 * @brief The scenario simulator: builds the world from a core::VectorMap and a Scenario, moves the ego and
 *        the objects, and produces per scan the lidar points (lidar frame), the ground-truth class window
 *        (map frame) and the object list. ROS-free and deterministic for a given seed: scan k depends only
 *        on (scenario, map, seed, k).
 */
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "map_aided_fusion/core/grid_geometry.hpp"
#include "map_aided_fusion/core/vector_map.hpp"
#include "map_aided_fusion/sim/ground_truth.hpp"
#include "map_aided_fusion/sim/scenario.hpp"
#include "map_aided_fusion/sim/scene.hpp"

namespace map_aided_fusion {
namespace sim {

/// One lidar return, in the lidar frame.
struct LidarPoint
{
  float x = 0.0f, y = 0.0f, z = 0.0f;
  float intensity = 0.0f;
  std::uint16_t ring = 0;  ///< beam index, 0 = lowest elevation
  float time = 0.0f;       ///< s after the scan's stamp (0 unless lidar.rolling_sweep)
};

/// A planar pose (map frame).
struct Pose2
{
  double x = 0.0, y = 0.0, yaw = 0.0;
};

/// One object as published on /ground_truth/objects (map frame, box centre).
struct ObjectTruth
{
  std::uint32_t id = 0;
  core::CellClass cell_class = core::CellClass::kInfrastructure;
  std::string kind;
  double x = 0.0, y = 0.0, z = 0.0, yaw = 0.0;
  double length = 0.0, width = 0.0, height = 0.0;
  double vx = 0.0, vy = 0.0;
};

/// Everything the simulator produces for one scan.
struct ScanFrame
{
  int index = 0;
  double time = 0.0;   ///< s since the start of the scenario
  Pose2 ego;           ///< base_link in map
  Pose2 lidar;         ///< lidar in map
  std::vector<LidarPoint> points;
  std::size_t rays = 0;        ///< rays cast
  std::size_t no_return = 0;   ///< rays without anything within range
  std::size_t dropped = 0;     ///< returns lost to dropout or outside [min_range, max_range] after noise
  core::GridGeometry truth_geometry;  ///< ground-truth window (map frame)
  /**
   * core::CellClass codes per cell of truth_geometry (row-major, like nav_msgs/OccupancyGrid), and -1 where no
   * ray of this scan could have seen: a cell is observed when the 2D projection of a ray passes through it up
   * to and including the cell of the ray's noise-free hit (returns lost to dropout still count; rays without
   * any hit count up to their max range only with ground_truth.include_no_return_rays). Classes: mapped
   * buildings C, buildings missing from the map N, objects by their class (the larger code wins where
   * footprints share a cell), the rest F; a cell belongs to a footprint when they overlap. With
   * ground_truth.object_needs_hit (the default), the footprint of an object that no ray of this scan hit is -1.
   */
  std::vector<std::int8_t> truth_classes;
  std::vector<ObjectTruth> objects;        ///< objects present at this instant
};

/// Counts of how the map errors of a scenario were applied.
struct WorldSummary
{
  std::size_t mapped_buildings = 0;   ///< in the world and in the map (C)
  std::size_t unmapped_buildings = 0; ///< in the world, not in the map (N)
  std::size_t absent_buildings = 0;   ///< in the map, not in the world
};

/// Deterministic scenario simulation. Not thread-safe (one Simulator per thread).
class Simulator
{
public:
  /**
   * @param map the map as the perception sees it (buildings with their heights, 0 = unknown)
   * @throws core::ParameterError when the scenario is invalid or a map error names no building
   */
  Simulator(Scenario scenario, const core::VectorMap& map);
  ~Simulator();
  Simulator(const Simulator&) = delete;
  Simulator& operator=(const Simulator&) = delete;

  const Scenario& scenario() const { return scenario_; }
  const WorldSummary& summary() const { return summary_; }
  const Scene& scene() const { return *scene_; }

  /// Scans at t = k / rate for k = 0 .. numScans() - 1, all within the duration.
  int numScans() const;
  double scanTime(int k) const;
  double scanPeriod() const { return 1.0 / scenario_.lidar.rate_hz; }

  /// Pose of base_link in the map frame at time @p t.
  Pose2 egoPose(double t) const;
  /// The pose the localisation publishes at time @p t: egoPose(t) plus the scenario's localisation error.
  Pose2 reportedEgoPose(double t) const;
  /// Ego speed (m/s) at time @p t.
  double egoSpeed(double t) const;
  /// Pose of the lidar in the map frame for an ego pose.
  Pose2 lidarPose(const Pose2& ego) const;
  /// Terrain height at (x, y) of the map frame (Terrain), m.
  double terrainHeight(double x, double y) const;
  /// The ego body's pitch (positive: nose down, about base_link y) and roll (about x), radians, at time @p t.
  void bodyAttitude(double t, double& pitch, double& roll) const;

  /// Objects present at time @p t, as solids and as ground-truth records (same order).
  void objectsAt(double t, std::vector<WorldObject>& solids, std::vector<ObjectTruth>& truth) const;

  /// Simulates scan @p k into @p out (buffers reused).
  void scan(int k, ScanFrame& out);

private:
  Scenario scenario_;
  WorldSummary summary_;
  std::unique_ptr<Scene> scene_;
  std::unique_ptr<StaticClassRaster> static_raster_;
  std::unique_ptr<PathMotion> ego_motion_;
  std::vector<PathMotion> object_motion_;
  // per-beam constants
  std::vector<double> slopes_, max_s_, cos_e_, sin_e_, tilted_slopes_;
  std::vector<BeamHit> hits_;
  std::vector<std::uint8_t> observed_;
  std::vector<std::uint8_t> object_hit_;     ///< per object of scene_->objects(): some ray of this scan hit it
  std::vector<std::int8_t> hidden_cells_;    ///< footprints of the objects no ray hit
  std::vector<WorldObject> solids_;
  std::vector<Point2> walk_;  ///< random walk of the localisation error, one sample per tf period
};

}  // namespace sim
}  // namespace map_aided_fusion

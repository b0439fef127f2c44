/**
 * @file prior_grid_worker.hpp
 * @brief The PriorGrid worker shared by the PriorGridNodelet and the plain prior_grid_node: loads the map
 *        given by the private parameters (config/prior_grid.yaml), rasterises it and publishes, latched:
 *        - `prior_grid` (map_aided_fusion/EvidentialGrid; focal sets B, R, T, Ω; frame `frame_id`),
 *        - `prior_grid/occupancy` (nav_msgs/OccupancyGrid for rviz: road 0, other 50, building 100),
 *        - `prior_grid/outlines` (visualization_msgs/MarkerArray: building, road-area and road centre-line
 *          outlines inside the published window).
 *        Service `~reload` (std_srvs/Trigger) re-reads the parameters and the map.
 *
 * Once a second it looks up the vehicle (vehicle_frame) in frame_id: farther than max_vehicle_distance from all the
 * map's data, it warns once and its diagnostics go WARN (a wrong map, origin or frame).
 *
 * Bad parameters or an unreadable map are logged (ROS_ERROR, naming the parameter or the file and the
 * cause) and returned by `~reload`; the node stays alive and publishes nothing new (a previously published
 * prior stays latched).
 */
#pragma once

#include <memory>
#include <mutex>
#include <string>

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>
#include <std_srvs/Trigger.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include "map_aided_fusion/core/prior_grid.hpp"
#include "map_aided_fusion/map_io/prior_grid_params.hpp"

namespace map_aided_fusion {

/// Occupancy values of prior_grid/occupancy.
constexpr std::int8_t kPriorOccupancyRoad = 0;
constexpr std::int8_t kPriorOccupancyOther = 50;
constexpr std::int8_t kPriorOccupancyBuilding = 100;
constexpr std::int8_t kPriorOccupancyUnknown = -1;

/// Reads PriorGridParams from a (private) node handle; missing parameters keep their defaults.
map_io::PriorGridParams readPriorGridParams(const ros::NodeHandle& pnh);

/// The worker: owns the publishers, the service and the PriorGrid.
class PriorGridWorker
{
public:
  /// Advertises, loads and publishes (errors are logged, not thrown).
  PriorGridWorker(ros::NodeHandle nh, ros::NodeHandle pnh);

  /// True when the last load succeeded.
  bool loaded() const { return loaded_; }
  /// Outcome of the last load (the error message when it failed).
  const std::string& status() const { return status_; }

private:
  bool load();
  bool reload(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  /// Diagnostics: the file, what was kept and skipped, the published grid and its origin.
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);
  void publish(const map_io::PriorGridParams& params, const core::VectorMap& map);
  /// Where the vehicle is with respect to the map's data (wall timer).
  void checkVehicle();

  ros::NodeHandle nh_;
  ros::NodeHandle pnh_;
  ros::Publisher prior_pub_;
  ros::Publisher occupancy_pub_;
  ros::Publisher outlines_pub_;
  ros::ServiceServer reload_srv_;
  std::mutex mutex_;
  core::PriorGrid grid_;
  bool loaded_ = false;
  std::string status_;
  map_io::MapLoadReport report_;
  core::GridGeometry published_;
  std::size_t loads_ = 0;
  core::VectorMap map_;                  ///< the loaded map, for the vehicle's distance to its data
  map_io::PriorGridParams params_;       ///< the parameters of the last successful load
  double vehicle_distance_ = -1.0;       ///< m from the vehicle to the nearest map data; -1: not known
  bool vehicle_far_ = false;             ///< farther than max_vehicle_distance (warned once per excursion)
  tf2_ros::Buffer tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  ros::WallTimer vehicle_timer_;
  std::unique_ptr<diagnostic_updater::Updater> diagnostics_;
  ros::WallTimer diagnostics_timer_;
};

}  // namespace map_aided_fusion

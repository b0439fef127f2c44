/**
 * @file sim_bag.hpp
 * @brief Thin ROS layer over the ROS-free simulator: message converters and a rosbag writer.
 *
 * Bag contents (topic: type, frame):
 *  - `/points`: sensor_msgs/PointCloud2, frame `lidar`, fields x y z intensity (float32) ring (uint16),
 *    point_step 18, one message per scan (10 Hz by default), stamped at the scan time.
 *  - `/tf`: tf2_msgs/TFMessage, `map` → `base_link` at the scenario's tf_rate_hz (≥ 50 Hz).
 *  - `/tf_static`: tf2_msgs/TFMessage, `base_link` → `lidar`, once at t = 0, recorded as latched
 *    (connection header `latching: 1`, as rosbag record does).
 *  - `/ground_truth/classes`: nav_msgs/OccupancyGrid, frame `map`, per scan: core::CellClass codes
 *    (F 0, C 1, N 2, S 3, V 4, −1 unknown).
 *  - `/ground_truth/objects`: map_aided_fusion/GroundTruthObjectArray, frame `map`, per scan.
 */
#pragma once

#include <cstddef>
#include <iosfwd>
#include <string>

#include <map_aided_fusion/GroundTruthObjectArray.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/time.h>
#include <sensor_msgs/PointCloud2.h>

#include "map_aided_fusion/sim/simulator.hpp"

namespace map_aided_fusion {

/// Topic and frame names of a simulation bag.
struct SimBagNames
{
  std::string points_topic = "/points";
  std::string tf_topic = "/tf";
  std::string tf_static_topic = "/tf_static";
  std::string classes_topic = "/ground_truth/classes";
  std::string objects_topic = "/ground_truth/objects";
  /// geometry_msgs/PoseWithCovarianceStamped of the localisation (only when the scenario has a localisation error)
  std::string pose_topic = "/localisation/pose";
  std::string map_frame = "map";
  std::string base_frame = "base_link";
  std::string lidar_frame = "lidar";
};

/// Options of writeSimulationBag().
struct SimBagOptions
{
  std::string path;              ///< output bag file
  SimBagNames names;
  std::ostream* progress = nullptr;  ///< progress line (carriage-return updated), or none
};

/// What writeSimulationBag() wrote.
struct SimBagStats
{
  int scans = 0;
  std::size_t points = 0;
  std::size_t tf_messages = 0;
  double wall_seconds = 0.0;
};

/// Static converters from the simulator's records to messages.
class SimConversions
{
public:
  /// ROS time of scenario time @p t.
  static ros::Time stamp(const sim::Scenario& scenario, double t);
  static void toPointCloud2(const sim::ScanFrame& frame, const ros::Time& stamp, const std::string& frame_id,
                            sensor_msgs::PointCloud2& msg);
  static void toClassGrid(const sim::ScanFrame& frame, const ros::Time& stamp, const std::string& frame_id,
                          nav_msgs::OccupancyGrid& msg);
  static void toObjectArray(const sim::ScanFrame& frame, const ros::Time& stamp, const std::string& frame_id,
                            GroundTruthObjectArray& msg);
};

/**
 * @brief Runs the whole scenario and writes the bag.
 * @throws rosbag::BagException when the file cannot be written.
 */
SimBagStats writeSimulationBag(sim::Simulator& simulator, const SimBagOptions& options);

}  // namespace map_aided_fusion

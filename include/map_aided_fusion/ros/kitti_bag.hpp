/**
 * @file kitti_bag.hpp
 * @brief KITTI / SemanticKITTI sequence → rosbag, and the labelled points such a bag carries.
 *
 * Bag contents (topic: type, frame):
 *  - `/points`: sensor_msgs/PointCloud2, frame `velodyne`, fields x y z intensity (float32), one per scan,
 *    stamped start_stamp + times.txt;
 *  - `/tf`: `map` → `base_link` at each scan stamp. `map` is the ground under the lidar of frame 0 (the lidar
 *    frame of frame 0 lowered by lidar_height), `base_link` the ground under the lidar (the lidar frame
 *    lowered by lidar_height): map → base_link = D · Tr⁻¹ · P · Tr · D⁻¹ with D the lidar_height lift;
 *  - `/tf_static`: `base_link` → `velodyne` (lidar_height up), latched;
 *  - `/ground_truth/points`: sensor_msgs/PointCloud2, frame `velodyne`, the scan's points with their ground
 *    truth, for labelled frames only: x y z (float32), label (uint32, the raw SemanticKITTI label: class in the
 *    low 16 bits, instance in the high 16), state (uint8: 0 unlabelled, 1 static, 2 moving);
 *  - with KITTI tracking labels (`label_02.txt` and a `P2:` line in calib.txt, dataset/kitti_tracking.hpp), per
 *    sweep: `/ground_truth/objects` (GroundTruthObjectArray, frame `map`: id = track id, kind = the label's type
 *    in lower case, box centre and yaw, size, velocity from the track's centres by least squares over ±0.5 s,
 *    cell_class 4 moving above 0.5 m/s, 3 parked below 0.25 m/s, −1 ambiguous: not judged) and
 *    `/ground_truth/valid` (nav_msgs/OccupancyGrid, frame `map`, centred on the lidar: 100 where the labels are
 *    valid — the camera's view minus the DontCare regions — 0 elsewhere).
 */
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <geometry_msgs/TransformStamped.h>
#include <sensor_msgs/PointCloud2.h>

#include <nav_msgs/OccupancyGrid.h>

#include "map_aided_fusion/GroundTruthObject.h"
#include "map_aided_fusion/dataset/kitti.hpp"
#include "map_aided_fusion/dataset/kitti_tracking.hpp"
#include "map_aided_fusion/eval/point_labels.hpp"

namespace map_aided_fusion {

/// Options of writeKittiBag().
struct KittiBagOptions
{
  std::string path;                      ///< the bag to write (written as PATH.partial, renamed when complete)
  double start_stamp = 1317376800.0;     ///< s, ROS time of times.txt's 0 (KITTI's 2011-09-30; never 0)
  double lidar_height = 1.73;            ///< m, the velodyne above the ground (KITTI's HDL-64E mount)
  std::string points_topic = "/points";
  std::string labels_topic = "/ground_truth/points";
  std::string objects_topic = "/ground_truth/objects";  ///< tracking labels only
  std::string valid_topic = "/ground_truth/valid";      ///< tracking labels only
  double valid_resolution = 0.25;                       ///< m, cells of the valid-label mask
  double valid_size = 120.0;                            ///< m, side of the mask, centred on the lidar
  dataset::MotionThresholds motion;                     ///< moving / parked speeds of the tracking boxes
  /// Tracking labels of frames beyond the sequence: an error (true) or skipped (false, for --frames).
  bool strict_labels = true;
  std::string map_frame = "map";
  std::string base_frame = "base_link";
  std::string lidar_frame = "velodyne";
  std::function<void(std::size_t done, std::size_t total)> progress;  ///< called after each frame, or empty
};

/// What writeKittiBag() wrote.
struct KittiBagStats
{
  std::size_t scans = 0;
  std::size_t labelled_scans = 0;
  std::size_t points = 0;
  std::size_t moving_points = 0;
  std::size_t object_boxes = 0;  ///< tracking boxes written (all sweeps)
  std::size_t moving_tracks = 0;  ///< track ids moving in at least one sweep
  std::size_t parked_tracks = 0;  ///< track ids parked in some sweep and moving in none
};

/// A ground-truth point read back from `/ground_truth/points`.
struct LabelledCloudPoint
{
  float x, y, z;
  std::uint32_t label;
  std::uint8_t state;  ///< dataset::PointState
};

/// Static converters between KITTI frames and messages (tested without a master).
class KittiConversions
{
public:
  static void toPointCloud2(const std::vector<dataset::KittiPoint>& points, const ros::Time& stamp,
                            const std::string& frame_id, sensor_msgs::PointCloud2& msg);
  static void toLabelledCloud(const std::vector<dataset::KittiPoint>& points, const std::vector<std::uint32_t>& labels,
                              const ros::Time& stamp, const std::string& frame_id, sensor_msgs::PointCloud2& msg);
  /// @throws std::runtime_error when @p msg does not have the fields toLabelledCloud() writes.
  static std::vector<LabelledCloudPoint> fromLabelledCloud(const sensor_msgs::PointCloud2& msg);
  /// A tracking box → the ground-truth object message (map frame).
  static GroundTruthObject toGroundTruthObject(const dataset::TrackedBox& box);
  /// A valid-label mask (1 valid, 0 not; row-major) → OccupancyGrid (100 valid, 0 not) in @p frame_id.
  static void toValidGrid(const std::vector<std::int8_t>& mask, double resolution, int width, int height,
                          double origin_x, double origin_y, const ros::Time& stamp, const std::string& frame_id,
                          nav_msgs::OccupancyGrid& msg);
  /// A tf transform → Eigen.
  static Eigen::Isometry3d toIsometry(const geometry_msgs::TransformStamped& t);
  /**
   * @brief A `/ground_truth/points` cloud → the scorer's points in the map frame. A point is an obstacle when its
   *        height in base_link is in [@p obstacle_low, @p obstacle_high] and its class is not a ground class.
   * @param map_sensor   map ← cloud frame at the cloud's stamp
   * @param base_sensor  base_link ← cloud frame
   */
  static std::vector<eval::LabelledPoint> toScoredPoints(const sensor_msgs::PointCloud2& msg,
                                                         const Eigen::Isometry3d& map_sensor,
                                                         const Eigen::Isometry3d& base_sensor, double obstacle_low,
                                                         double obstacle_high);
};

/**
 * @brief Converts a whole sequence. The bag is written to PATH.partial and renamed to PATH only when every frame
 *        was written; on any error the partial file is removed, so no half-written bag looks complete.
 * @throws dataset::KittiError or rosbag::BagException, naming the file at fault.
 */
KittiBagStats writeKittiBag(const dataset::KittiSequence& sequence, const KittiBagOptions& options);

}  // namespace map_aided_fusion

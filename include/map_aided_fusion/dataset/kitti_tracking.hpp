/**
 * @file kitti_tracking.hpp
 * @brief ROS-free reader of the KITTI tracking labels of one sequence, laid out as a KITTI odometry folder
 *        (kitti.hpp) plus `label_02.txt` and the `P2:` line of `calib.txt`; the boxes in the map frame with their
 *        velocity and motion state; where the labels are valid (the camera's view minus the `DontCare` regions).
 *
 * `label_02.txt`, one object per line, 17 fields (18 with a detection score, ignored):
 * frame, track id, type, truncated, occluded, alpha, image box (left, top, right, bottom, px), dimensions
 * (height, width, length, m), location (x, y, z of the bottom centre, m, rectified camera-0 coordinates), rotation_y.
 * `DontCare` lines (track id −1) are image regions whose objects are not labelled.
 *
 * Frames: `Tr` of calib.txt maps the velodyne to rectified camera 0 (kitti.hpp); P2 projects rectified camera-0
 * coordinates to the left colour image (1242 × 375 px). A box centre c in camera coordinates is, in the map frame
 * of kitti_to_bag, D · L_k · Tr⁻¹ · c (D: the lidar height lift, L_k the lidar pose of frame k).
 *
 * Every error names the file and line.
 */
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "map_aided_fusion/dataset/kitti.hpp"

namespace map_aided_fusion {
namespace dataset {

/// One line of label_02.txt.
struct TrackingLabel
{
  std::size_t frame = 0;
  int track_id = -1;          ///< −1 for DontCare
  std::string type;           ///< Car, Van, Truck, Pedestrian, Person_sitting, Cyclist, Tram, Misc, DontCare
  double left = 0, top = 0, right = 0, bottom = 0;  ///< image box, px
  double height = 0, width = 0, length = 0;         ///< m
  Eigen::Vector3d location = Eigen::Vector3d::Zero();  ///< bottom centre, rectified camera 0, m
  double rotation_y = 0.0;                           ///< rad, about the camera's y axis
  std::size_t line = 0;                              ///< line in the file
  bool dontCare() const { return type == "DontCare"; }
};

/// Motion state of a labelled box.
enum class BoxMotion : std::uint8_t
{
  kAmbiguous,  ///< speed between the thresholds, or unknown (one box only in the window): not judged
  kParked,
  kMoving,
};

/// Thresholds of the motion state (the issue's: moving above 0.5 m/s, parked below 0.25 m/s, ±0.5 s fit).
struct MotionThresholds
{
  double moving_speed = 0.5;   ///< m/s, strictly above: moving
  double parked_speed = 0.25;  ///< m/s, strictly below: parked
  double half_window = 0.5;    ///< s, the least-squares fit uses the track's centres within ± this
  /// s: a run of consecutive moving boxes of a track spanning less than this (first to last box) is label and pose
  /// noise, not motion: its boxes are ambiguous (0.4 s: five sweeps at 10 Hz).
  double min_moving_span = 0.4;
};

/// A labelled object of one frame in the map frame.
struct TrackedBox
{
  std::size_t frame = 0;
  int track_id = 0;
  std::string type;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  ///< box centre, map frame
  double yaw = 0.0;                                  ///< rad, heading of the length axis in the map frame
  double length = 0, width = 0, height = 0;          ///< m
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();  ///< m/s, map frame
  bool velocity_known = false;
  BoxMotion motion = BoxMotion::kAmbiguous;
};

/// The image the labels refer to: P2 and the image size.
struct CameraModel
{
  Eigen::Matrix<double, 3, 4> P2 = Eigen::Matrix<double, 3, 4>::Zero();
  int width = 1242;
  int height = 375;
  /// Projects a point of rectified camera-0 coordinates; false behind the camera (depth ≤ 0.1 m).
  bool project(const Eigen::Vector3d& camera_point, Eigen::Vector2d& pixel) const;
  bool inImage(const Eigen::Vector2d& pixel) const;
};

/// Parses the `P2:` line of a calib.txt. @throws KittiError naming the file (and line).
Eigen::Matrix<double, 3, 4> readCalibrationP2(const std::string& path);

/**
 * @brief Parses a label_02.txt.
 * @param frames   the number of sweeps of the sequence
 * @param strict   true: a label of a frame ≥ frames is an error; false: it is skipped (a sequence cut short)
 * @throws KittiError naming the file and line: a wrong field count, a field that is not a number, a negative
 *         frame or dimension, a frame beyond the sweeps (strict).
 */
std::vector<TrackingLabel> readTrackingLabels(const std::string& path, std::size_t frames, bool strict = true);

/// The labels of a tracking sequence, their boxes in the map frame and where they are valid.
class KittiTracking
{
public:
  /**
   * @brief Reads `label_02.txt` and the `P2:` line of `calib.txt` of @p sequence's folder and computes every box
   *        in the map frame of kitti_to_bag (lidar of frame 0 lifted by @p lidar_height).
   * @throws KittiError naming the file (and line) at fault.
   */
  KittiTracking(const KittiSequence& sequence, double lidar_height, const MotionThresholds& thresholds = {},
                bool strict = true);

  /// True when @p folder holds a label_02.txt.
  static bool present(const std::string& folder);

  const CameraModel& camera() const { return camera_; }
  const std::vector<TrackingLabel>& labels() const { return labels_; }
  /// The objects (not DontCare) of @p frame, in the map frame.
  std::vector<TrackedBox> boxes(std::size_t frame) const;
  /// Map ← rectified camera 0 at @p frame.
  Eigen::Isometry3d mapFromCamera(std::size_t frame) const;

  /**
   * @brief Where the labels of @p frame are valid, for the cells of a map-frame grid (row-major, @p width ×
   *        @p height cells of @p resolution metres from (@p origin_x, @p origin_y)): 1 when a point of the cell's
   *        column (0.25, 1.0 and 1.75 m above the ground under the lidar) projects into the image and none of those
   *        in the image falls in a DontCare region; 0 otherwise.
   */
  std::vector<std::int8_t> validMask(std::size_t frame, double resolution, int width, int height, double origin_x,
                                     double origin_y) const;

private:
  CameraModel camera_;
  std::vector<TrackingLabel> labels_;
  std::vector<TrackedBox> boxes_;  ///< every object box, by frame
  std::vector<Eigen::Isometry3d, Eigen::aligned_allocator<Eigen::Isometry3d>> map_from_camera_;
  std::vector<double> lidar_z_;  ///< the lidar's height in the map frame, by frame
  double lidar_height_ = 0.0;
};

}  // namespace dataset
}  // namespace map_aided_fusion

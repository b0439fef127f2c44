/**
 * @file kitti.hpp
 * @brief ROS-free reader of a KITTI odometry / SemanticKITTI sequence folder.
 *
 * Layout (one sequence, as distributed):
 *  - `velodyne/NNNNNN.bin`: float32 x, y, z, remission per point, lidar frame; frames numbered from 0 without gaps;
 *  - `labels/NNNNNN.label` (optional, per frame): uint32 per point, low 16 bits the semantic class, high 16 bits
 *    the instance id; a frame without a label file is unlabelled;
 *  - `poses.txt`: per frame, the 3×4 row-major pose P of camera 0 in the camera-0 frame of frame 0;
 *  - `calib.txt`: the `Tr:` line (velodyne → camera 0, 3×4 row-major); other lines are ignored;
 *  - `times.txt`: per frame, seconds since the start of the sequence.
 *
 * Every error names the file and, for text files, the line.
 */
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Geometry>

namespace map_aided_fusion {
namespace dataset {

/// A malformed or incomplete sequence folder; what() names the file (and line).
class KittiError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

/// Ground-truth motion state of one point (SemanticKITTI).
enum class PointState : std::uint8_t
{
  kUnlabelled = 0,  ///< class 0 (unlabeled) or 1 (outlier), or a frame without labels
  kStatic = 1,      ///< any other class below 252
  kMoving = 2,      ///< classes 252–259 (moving-car … moving-other-vehicle)
};

/// SemanticKITTI classes (low 16 bits of a label).
constexpr std::uint16_t kClassUnlabeled = 0;
constexpr std::uint16_t kClassOutlier = 1;
constexpr std::uint16_t kClassVegetation = 70;
constexpr std::uint16_t kFirstMovingClass = 252;
constexpr std::uint16_t kLastMovingClass = 259;

/// The motion state of a raw SemanticKITTI label.
PointState stateOf(std::uint32_t label);
/// The semantic class of a raw label (low 16 bits).
inline std::uint16_t semanticClass(std::uint32_t label) { return static_cast<std::uint16_t>(label & 0xFFFFu); }
/// The instance id of a raw label (high 16 bits; 0: none).
inline std::uint16_t instanceId(std::uint32_t label) { return static_cast<std::uint16_t>(label >> 16); }
/// True for the ground classes: road 40, parking 44, sidewalk 48, other-ground 49, lane-marking 60, terrain 72.
bool isGroundClass(std::uint16_t semantic_class);

/// One lidar point of a frame.
struct KittiPoint
{
  float x, y, z, remission;
};

/// An opened, checked sequence: counts, times and lidar poses; frames are read on demand.
class KittiSequence
{
public:
  /**
   * @brief Opens and checks @p folder: times.txt, poses.txt and calib.txt parse, there is a pose and a time
   *        per scan, velodyne/ holds frames 0 … N−1 without a gap.
   * @param max_frames  read at most this many frames (0: all)
   * @param poses_path  a poses.txt to read instead of the folder's (empty: `folder`/poses.txt)
   * @throws KittiError naming the file (and line) at fault.
   */
  explicit KittiSequence(const std::string& folder, std::size_t max_frames = 0, const std::string& poses_path = "");

  std::size_t size() const { return times_.size(); }
  const std::string& folder() const { return folder_; }
  /// Seconds since the start of the sequence.
  double time(std::size_t frame) const { return times_.at(frame); }
  /// Pose of the lidar of @p frame in the lidar frame of frame 0: Tr⁻¹ · P · Tr.
  const Eigen::Isometry3d& lidarPose(std::size_t frame) const { return lidar_poses_.at(frame); }
  /// Velodyne → camera 0 (`Tr`).
  const Eigen::Isometry3d& velodyneToCamera() const { return tr_; }
  /// Path of the point file of @p frame.
  std::string scanPath(std::size_t frame) const;
  /// Path of the label file of @p frame (it may not exist).
  std::string labelPath(std::size_t frame) const;
  bool hasLabels(std::size_t frame) const;
  /// Number of frames with a label file.
  std::size_t labelledFrames() const;

  /// @throws KittiError when the file is unreadable or its size is not a multiple of 16 bytes.
  std::vector<KittiPoint> readScan(std::size_t frame) const;
  /**
   * @brief The labels of @p frame, one per point of readScan(frame); empty when the frame has no label file.
   * @throws KittiError when the label file holds a different number of labels than the scan has points.
   */
  std::vector<std::uint32_t> readLabels(std::size_t frame, std::size_t points) const;

private:
  std::string folder_;
  std::vector<double> times_;
  std::vector<Eigen::Isometry3d, Eigen::aligned_allocator<Eigen::Isometry3d>> lidar_poses_;
  Eigen::Isometry3d tr_ = Eigen::Isometry3d::Identity();
  std::vector<bool> labelled_;
};

/// Parses the `Tr:` line of a KITTI calib.txt. @throws KittiError naming the file and line.
Eigen::Isometry3d readCalibrationTr(const std::string& path);
/// Parses a poses.txt (12 numbers per line). @throws KittiError naming the file and line.
std::vector<Eigen::Isometry3d, Eigen::aligned_allocator<Eigen::Isometry3d>> readPoses(const std::string& path);
/// Parses a times.txt (one number per line, non-decreasing). @throws KittiError naming the file and line.
std::vector<double> readTimes(const std::string& path);

}  // namespace dataset
}  // namespace map_aided_fusion

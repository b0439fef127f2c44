/**
 * @file cloud_deskew.hpp
 * @brief Deskewing of sensor_msgs/PointCloud2 sweeps (core/deskew.hpp) with the motion from tf: the per-point time
 *        field of the common ROS 1 drivers, the sensor's motion over the sweep, and the reasons a cloud is left
 *        as it is. Shared by the ScanGrid nodelet and the offline `evaluate`.
 */
#pragma once

#include <string>
#include <vector>

#include <sensor_msgs/PointCloud2.h>
#include <tf2/buffer_core.h>
#include <tf2/exceptions.h>

#include "map_aided_fusion/core/deskew.hpp"

namespace map_aided_fusion {

/// Time fields recognised by `deskew_time_field: auto`, in this order, and how each is read:
/// `time` (Velodyne, float32 s since the stamp), `t` (Ouster, uint32 ns since the stamp), `timestamp` (Hesai,
/// float64 s since the epoch), `offset_time` (Livox and others, uint32 ns since the stamp).
const std::vector<std::string>& knownTimeFields();

/// What happened to one cloud.
struct DeskewResult
{
  bool applied = false;  ///< the output view holds moved points
  /// "applied", "off" (deskew false), "no_time_field", or why this cloud was not deskewed:
  /// "time_field_type" (a known name with another datatype), "time_non_finite", "time_negative",
  /// "time_out_of_sweep", "no_motion" (tf cannot give the sensor's motion), "bad_motion".
  std::string status;
  std::string detail;  ///< for logs
  double span = 0.0;   ///< s, the latest point time after the stamp

  /// True when the cloud had to be left as it is for a fault (not "off", not "no_time_field"): counted and warned.
  bool skipped() const { return !applied && status != "off" && status != "no_time_field"; }
};

/**
 * @brief Finds the time field of @p cloud: @p name, or with "auto" the first of knownTimeFields() present.
 * @return "" when found (@p field set), "no_time_field", or "time_field_type" with @p detail.
 */
std::string findTimeField(const sensor_msgs::PointCloud2& cloud, const std::string& name, core::PointTimeField& field,
                          std::string* detail = nullptr);

/**
 * @brief The motion of @p sensor_frame over [stamp, stamp + span] in @p fixed_frame: from tf at both ends when tf
 *        has the end, else extrapolated at constant velocity from [stamp − span, stamp], else (the stamp not yet in
 *        the buffer) from the latest interval of that length.
 * @return false when tf has neither (detail says why).
 */
bool sweepMotionFromTf(const tf2::BufferCore& tf, const std::string& fixed_frame, const std::string& sensor_frame,
                       const ros::Time& stamp, double span, core::SweepMotion& motion, std::string* detail = nullptr);

/// Deskews clouds; keeps its output buffer between calls. One per thread.
class CloudDeskewer
{
public:
  /**
   * @brief Deskews @p cloud (whose x, y, z @p view reads) into @p out, or sets @p out = @p view.
   * @param enabled       ScanGridParams::deskew
   * @param time_field    a field name or "auto"
   * @param fixed_frame   the frame the vehicle moves in (tf)
   */
  DeskewResult apply(const sensor_msgs::PointCloud2& cloud, const core::PointCloudView& view, bool enabled,
                     const std::string& time_field, double max_sweep_duration, const tf2::BufferCore& tf,
                     const std::string& fixed_frame, core::PointCloudView& out);

private:
  std::vector<float> buffer_;
};

}  // namespace map_aided_fusion

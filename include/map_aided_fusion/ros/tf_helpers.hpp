/**
 * @file tf_helpers.hpp
 * @brief Small tf helpers shared by the ScanGrid worker and the sweep deskewing.
 */
#pragma once

#include <string>

#include <Eigen/Geometry>
#include <geometry_msgs/Transform.h>

namespace map_aided_fusion {

/// A frame id as tf2 knows it: tf1-style "/lidar" without its leading slash.
inline std::string tfFrame(const std::string& frame)
{
  return frame.empty() || frame[0] != '/' ? frame : frame.substr(1);
}

/// A geometry_msgs/Transform as an Eigen isometry (the quaternion normalised).
inline Eigen::Isometry3d toEigen(const geometry_msgs::Transform& t)
{
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translate(Eigen::Vector3d(t.translation.x, t.translation.y, t.translation.z));
  pose.rotate(Eigen::Quaterniond(t.rotation.w, t.rotation.x, t.rotation.y, t.rotation.z).normalized());
  return pose;
}

}  // namespace map_aided_fusion

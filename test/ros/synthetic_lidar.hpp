// A synthetic lidar for the rostests: ground rings around the vehicle and the faces of boxes, in the frame
// "lidar" kLidarHeight above base_link.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <geometry_msgs/TransformStamped.h>
#include <ros/time.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>

namespace maf_test {

constexpr double kLidarHeight = 1.8;

struct Box
{
  double x0, y0, x1, y1, height;
};

/// 2D ray from the origin to (x, y) crosses the box footprint.
inline bool rayHitsBox(double x, double y, const Box& b)
{
  double t0 = 0.0, t1 = 1.0;
  const double d[2] = { x, y }, lo[2] = { b.x0, b.y0 }, hi[2] = { b.x1, b.y1 };
  for (int k = 0; k < 2; ++k)
  {
    if (std::abs(d[k]) < 1e-12)
    {
      if (0.0 < lo[k] || 0.0 > hi[k]) return false;
      continue;
    }
    double a = lo[k] / d[k], c = hi[k] / d[k];
    if (a > c) std::swap(a, c);
    t0 = std::max(t0, a);
    t1 = std::min(t1, c);
    if (t0 > t1) return false;
  }
  return true;
}

/// The ground rings of a synthetic sweep: every range_step from 2 m to max_range, azimuths per ring.
struct Rings
{
  double max_range = 30.0;  ///< m
  double range_step = 0.5;  ///< m
  int azimuths = 720;       ///< per ring (0.5 deg)
};

/// A cloud in the lidar frame (lidar 1.8 m above base_link): ground rings and the faces of the boxes
/// (all coordinates given in base_link).
inline sensor_msgs::PointCloud2 makeCloud(const std::vector<Box>& boxes, const ros::Time& stamp,
                                          const std::string& frame = "lidar", const Rings& rings = Rings{})
{
  std::vector<float> xyz;
  for (double r = 2.0; r < rings.max_range; r += rings.range_step)
    for (double a = -M_PI; a < M_PI; a += 2.0 * M_PI / rings.azimuths)
    {
      const double x = r * std::cos(a), y = r * std::sin(a);
      bool hidden = false;
      for (const auto& b : boxes) hidden = hidden || rayHitsBox(x, y, b);
      if (hidden) continue;
      xyz.insert(xyz.end(), { static_cast<float>(x), static_cast<float>(y), static_cast<float>(-kLidarHeight) });
    }
  for (const auto& b : boxes)
    for (double z = 0.3; z < b.height; z += 0.2)
    {
      for (double x = b.x0; x <= b.x1; x += 0.1)
        for (double y : { b.y0, b.y1 })
          xyz.insert(xyz.end(), { static_cast<float>(x), static_cast<float>(y), static_cast<float>(z - kLidarHeight) });
      for (double y = b.y0; y <= b.y1; y += 0.1)
        for (double x : { b.x0, b.x1 })
          xyz.insert(xyz.end(), { static_cast<float>(x), static_cast<float>(y), static_cast<float>(z - kLidarHeight) });
    }
  sensor_msgs::PointCloud2 cloud;
  cloud.header.frame_id = frame;
  cloud.header.stamp = stamp;
  sensor_msgs::PointCloud2Modifier mod(cloud);
  mod.setPointCloud2FieldsByString(1, "xyz");
  mod.resize(xyz.size() / 3);
  sensor_msgs::PointCloud2Iterator<float> it(cloud, "x");
  for (std::size_t i = 0; i < xyz.size(); i += 3, ++it)
  {
    it[0] = xyz[i];
    it[1] = xyz[i + 1];
    it[2] = xyz[i + 2];
  }
  return cloud;
}

/// The static transform base_link → lidar (kLidarHeight above, no rotation).
inline geometry_msgs::TransformStamped lidarMount()
{
  geometry_msgs::TransformStamped lidar;
  lidar.header.frame_id = "base_link";
  lidar.child_frame_id = "lidar";
  lidar.transform.translation.z = kLidarHeight;
  lidar.transform.rotation.w = 1.0;
  return lidar;
}

}  // namespace maf_test

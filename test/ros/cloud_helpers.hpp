// Helpers shared by the ScanGrid tests and rostest nodes: point fields, packed float32 clouds, occupancy look-ups.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <boost/make_shared.hpp>
#include <nav_msgs/OccupancyGrid.h>
#include <sensor_msgs/PointCloud2.h>

#include "map_aided_fusion/ros/bag_writing.hpp"

namespace map_aided_fusion {
namespace test {

/// A single float32 PointField (other types: map_aided_fusion::pointField).
inline sensor_msgs::PointField floatField(const std::string& name, std::uint32_t offset)
{
  return map_aided_fusion::pointField(name, offset, sensor_msgs::PointField::FLOAT32);
}

/// An unorganized cloud of packed float32 records named @p names (x, y, z, …), @p floats holding them in order.
inline sensor_msgs::PointCloud2Ptr packedCloud(const std::vector<std::string>& names, const std::vector<float>& floats,
                                               const std::string& frame, const ros::Time& stamp)
{
  auto c = boost::make_shared<sensor_msgs::PointCloud2>();
  c->header.stamp = stamp;
  c->header.frame_id = frame;
  for (const std::string& n : names) c->fields.push_back(floatField(n, static_cast<std::uint32_t>(4 * c->fields.size())));
  c->point_step = static_cast<std::uint32_t>(4 * names.size());
  c->height = 1;
  c->width = static_cast<std::uint32_t>(floats.size() / names.size());
  c->row_step = c->width * c->point_step;
  c->is_dense = true;
  c->data.resize(c->row_step);
  std::memcpy(c->data.data(), floats.data(), c->row_step);
  return c;
}

/// The value of the cell of @p g under (x, y) in the grid's frame.
inline int occupancyAt(const nav_msgs::OccupancyGrid& g, double x, double y)
{
  const int cx = static_cast<int>(std::floor((x - g.info.origin.position.x) / g.info.resolution));
  const int cy = static_cast<int>(std::floor((y - g.info.origin.position.y) / g.info.resolution));
  return g.data[static_cast<std::size_t>(cy) * g.info.width + static_cast<std::size_t>(cx)];
}

}  // namespace test
}  // namespace map_aided_fusion

/**
 * @file bag_writing.hpp
 * @brief Small helpers shared by the bag writers (the simulator's and kitti_to_bag's).
 */
#pragma once

#include <cstdint>
#include <string>

#include <boost/make_shared.hpp>
#include <ros/message_traits.h>
#include <sensor_msgs/PointField.h>

namespace map_aided_fusion {

/// One PointCloud2 field of a single value.
inline sensor_msgs::PointField pointField(const std::string& name, std::uint32_t offset, std::uint8_t type)
{
  sensor_msgs::PointField f;
  f.name = name;
  f.offset = offset;
  f.datatype = type;
  f.count = 1;
  return f;
}

/// The connection header rosbag record writes for a latched topic of type @p M published by @p callerid.
template <class M>
boost::shared_ptr<ros::M_string> latchedConnectionHeader(const std::string& callerid)
{
  auto h = boost::make_shared<ros::M_string>();
  (*h)["type"] = ros::message_traits::datatype<M>();
  (*h)["md5sum"] = ros::message_traits::md5sum<M>();
  (*h)["message_definition"] = ros::message_traits::definition<M>();
  (*h)["callerid"] = callerid;
  (*h)["latching"] = "1";
  return h;
}

}  // namespace map_aided_fusion

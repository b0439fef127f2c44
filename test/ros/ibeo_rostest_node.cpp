// rostest (test/ibeo.test): launch/ibeo.launch wires the paper's sensor: a 4-layer IBEO cloud on the driver's topic
// and frame (lux_point_cloud_2202, ibeo_lux), the mount published by the launch file, the IBEO ScanGrid
// configuration. A car-high wall 10 m ahead of the bumper must occupy its cells; the road between is free.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <mutex>
#include <vector>

#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>

#include "cloud_helpers.hpp"

using namespace map_aided_fusion;

namespace {

constexpr double kTimeout = 30.0;  // s
constexpr double kPi = 3.14159265358979323846;
constexpr double kMountX = 3.7;    // launch/ibeo.launch's default mount
constexpr double kWall = 10.0;     // m ahead of the sensor
constexpr int kOccupiedAbove = 50;

/// ~800 points: 4 layers (-1.6 … +1.6 deg) every 0.5 deg over 110 deg, all on a wall 10 m ahead (x, y, z float32).
sensor_msgs::PointCloud2Ptr ibeoCloud(const ros::Time& stamp)
{
  std::vector<float> xyz;
  for (double layer : { -1.6, -0.8, 0.8, 1.6 })
    for (double az = -55.0; az <= 55.0; az += 0.5)
    {
      const double a = az * kPi / 180.0, e = layer * kPi / 180.0;
      if (std::abs(std::tan(a) * kWall) > 4.0) continue;  // the wall is 8 m wide
      const double r = kWall / (std::cos(a) * std::cos(e));
      xyz.insert(xyz.end(), { static_cast<float>(kWall), static_cast<float>(kWall * std::tan(a)),
                              static_cast<float>(r * std::sin(e)) });
    }
  return test::packedCloud({ "x", "y", "z" }, xyz, "ibeo_lux", stamp);
}

}  // namespace

TEST(Ibeo, TheLaunchFileWiresTheDriversTopicFrameAndMount)
{
  ros::NodeHandle nh;
  std::mutex m;
  nav_msgs::OccupancyGridConstPtr grid;
  ros::Subscriber sub = nh.subscribe<nav_msgs::OccupancyGrid>(
      "map_aided_fusion/scan_grid/occupancy", 1, [&](const nav_msgs::OccupancyGridConstPtr& g) {
        std::lock_guard<std::mutex> lock(m);
        grid = g;
      });
  ros::Publisher pub = nh.advertise<sensor_msgs::PointCloud2>("lux_point_cloud_2202", 1);
  ros::AsyncSpinner spinner(1);
  spinner.start();
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(kTimeout);
  bool done = false;
  while (ros::ok() && ros::WallTime::now() < end && !done)
  {
    pub.publish(ibeoCloud(ros::Time::now()));
    ros::WallDuration(0.1).sleep();
    std::lock_guard<std::mutex> lock(m);
    done = static_cast<bool>(grid);
  }
  ASSERT_TRUE(done) << "no ScanGrid within " << kTimeout << " s";
  std::lock_guard<std::mutex> lock(m);
  EXPECT_EQ(grid->header.frame_id, "base_link");
  EXPECT_DOUBLE_EQ(grid->info.resolution, 0.5);
  EXPECT_EQ(grid->info.width, 200u) << "the paper's 100 m window";
  EXPECT_GT(test::occupancyAt(*grid, kMountX + kWall + 0.1, 0.1), kOccupiedAbove);
  EXPECT_GE(test::occupancyAt(*grid, kMountX + 0.5 * kWall, 0.1), 0);
  EXPECT_LT(test::occupancyAt(*grid, kMountX + 0.5 * kWall, 0.1), kOccupiedAbove) << "free between the bumper and the wall";
  EXPECT_EQ(test::occupancyAt(*grid, -10.0, 0.1), -1) << "nothing is seen behind the car";
}

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "ibeo_rostest_node");
  return RUN_ALL_TESTS();
}

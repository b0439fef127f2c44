// rostest (test/pcl_filters.test): launch/pcl_filters.launch composes pcl/CropBox and pcl/VoxelGrid ahead of the
// ScanGridNodelet in one manager. A cloud with returns from the vehicle's own body and a dense wall goes in: the
// body's returns never reach the grid, the wall is thinned by the voxel grid and still occupies its cells.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <mutex>
#include <vector>

#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include "cloud_helpers.hpp"

using namespace map_aided_fusion;

namespace {

constexpr double kTimeout = 30.0;  // s
constexpr float kLidarHeight = 1.8f;
constexpr int kOccupiedAbove = 50;

struct Point
{
  float x, y, z, intensity;
};

/// Body returns (inside the launch file's default box, 0.8 m above the ground) and a wall 10 m ahead sampled
/// every 2 cm, in the lidar frame.
std::vector<Point> scene()
{
  std::vector<Point> pts;
  for (float x = -2.0f; x <= 2.5f; x += 0.1f)
    for (float y = -1.0f; y <= 1.0f; y += 0.1f) pts.push_back({ x, y, 0.8f - kLidarHeight, 10.0f });
  for (float y = -2.0f; y <= 2.0f; y += 0.02f)
    for (float z = -1.2f; z <= -0.2f; z += 0.02f) pts.push_back({ 10.1f, y, z, 50.0f });
  return pts;
}

sensor_msgs::PointCloud2Ptr cloud(const std::vector<Point>& pts, const ros::Time& stamp)
{
  std::vector<float> floats;
  for (const Point& p : pts) floats.insert(floats.end(), { p.x, p.y, p.z, p.intensity });
  return test::packedCloud({ "x", "y", "z", "intensity" }, floats, "lidar", stamp);
}

}  // namespace

TEST(PclFilters, CropBoxAndVoxelGridFeedTheScanGridInOneManager)
{
  ros::NodeHandle nh;
  tf2_ros::StaticTransformBroadcaster tf;
  geometry_msgs::TransformStamped t;
  t.header.stamp = ros::Time::now();
  t.header.frame_id = "base_link";
  t.child_frame_id = "lidar";
  t.transform.translation.z = kLidarHeight;
  t.transform.rotation.w = 1.0;
  tf.sendTransform(t);

  std::mutex m;
  sensor_msgs::PointCloud2ConstPtr filtered;
  nav_msgs::OccupancyGridConstPtr grid;
  ros::Subscriber filtered_sub = nh.subscribe<sensor_msgs::PointCloud2>(
      "voxel_grid/output", 1, [&](const sensor_msgs::PointCloud2ConstPtr& c) {
        std::lock_guard<std::mutex> lock(m);
        filtered = c;
      });
  ros::Subscriber grid_sub = nh.subscribe<nav_msgs::OccupancyGrid>(
      "scan_grid/occupancy", 1, [&](const nav_msgs::OccupancyGridConstPtr& g) {
        std::lock_guard<std::mutex> lock(m);
        grid = g;
      });
  ros::Publisher pub = nh.advertise<sensor_msgs::PointCloud2>("points_raw", 1);
  ros::AsyncSpinner spinner(2);
  spinner.start();

  const std::vector<Point> pts = scene();
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(kTimeout);
  bool done = false;
  while (ros::ok() && ros::WallTime::now() < end && !done)
  {
    pub.publish(cloud(pts, ros::Time::now()));
    ros::WallDuration(0.2).sleep();
    std::lock_guard<std::mutex> lock(m);
    done = filtered && grid;
  }
  ASSERT_TRUE(done) << "no filtered cloud or no grid within " << kTimeout << " s";
  std::lock_guard<std::mutex> lock(m);

  // The voxel grid thinned the 10 000 wall returns (10 cm voxels: about 40 × 10) and the crop removed the body.
  EXPECT_LT(filtered->width * filtered->height, pts.size() / 5);
  EXPECT_GT(filtered->width * filtered->height, 100u);
  std::size_t body = 0;
  for (std::size_t i = 0; i < filtered->width * filtered->height; ++i)
  {
    float x;
    std::memcpy(&x, filtered->data.data() + i * filtered->point_step, sizeof x);
    body += x < 5.0f;
  }
  EXPECT_EQ(body, 0u);

  // The wall occupies its cells; the body's would be occupied without the crop.
  EXPECT_GT(test::occupancyAt(*grid, 10.25, 0.0), kOccupiedAbove);
  EXPECT_LT(test::occupancyAt(*grid, 2.25, 0.25), kOccupiedAbove);
  EXPECT_LT(test::occupancyAt(*grid, -1.75, 0.25), kOccupiedAbove);
}

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "pcl_filters_rostest_node");
  return RUN_ALL_TESTS();
}

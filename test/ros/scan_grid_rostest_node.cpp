// rostest: ScanGridNodelet in a manager, fed clouds; grids carry the cloud's stamp; malformed clouds are
// rejected (and counted in the diagnostics) and the next good cloud is processed.
#include <gtest/gtest.h>

#include <cstring>
#include <mutex>
#include <vector>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include "map_aided_fusion/EvidentialGrid.h"

namespace {

constexpr double kTimeout = 15.0;  // s

struct Received
{
  std::mutex mutex;
  std::vector<map_aided_fusion::EvidentialGrid::ConstPtr> grids;
  std::vector<nav_msgs::OccupancyGrid::ConstPtr> occupancy;
  std::vector<diagnostic_msgs::DiagnosticArray::ConstPtr> diagnostics;
};

Received received;

sensor_msgs::PointField field(const std::string& name, std::uint32_t offset)
{
  sensor_msgs::PointField f;
  f.name = name;
  f.offset = offset;
  f.datatype = sensor_msgs::PointField::FLOAT32;
  f.count = 1;
  return f;
}

/// A wall 10 m ahead of the lidar, 1 m above the ground (the lidar is 1.8 m up), fields x y z intensity.
sensor_msgs::PointCloud2Ptr wallCloud(const ros::Time& stamp)
{
  auto c = boost::make_shared<sensor_msgs::PointCloud2>();
  c->header.stamp = stamp;
  c->header.frame_id = "lidar";
  c->fields = { field("x", 0), field("y", 4), field("z", 8), field("intensity", 12) };
  c->point_step = 16;
  c->height = 1;
  c->width = 101;
  c->row_step = c->width * c->point_step;
  c->is_dense = true;
  c->data.assign(c->row_step, 0);
  for (std::uint32_t i = 0; i < c->width; ++i)
  {
    const float p[4] = { 10.1f, -2.5f + 0.05f * static_cast<float>(i), -0.8f, 100.0f };
    std::memcpy(c->data.data() + i * c->point_step, p, sizeof p);
  }
  return c;
}

void onGrid(const map_aided_fusion::EvidentialGrid::ConstPtr& m)
{
  std::lock_guard<std::mutex> lock(received.mutex);
  received.grids.push_back(m);
}

void onOccupancy(const nav_msgs::OccupancyGrid::ConstPtr& m)
{
  std::lock_guard<std::mutex> lock(received.mutex);
  received.occupancy.push_back(m);
}

void onDiagnostics(const diagnostic_msgs::DiagnosticArray::ConstPtr& m)
{
  std::lock_guard<std::mutex> lock(received.mutex);
  received.diagnostics.push_back(m);
}

template <class Pred>
bool waitFor(Pred pred, double timeout = kTimeout)
{
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout);
  while (ros::ok() && ros::WallTime::now() < end)
  {
    if (pred()) return true;
    ros::WallDuration(0.01).sleep();
  }
  return pred();
}

bool gridWithStamp(const ros::Time& stamp)
{
  std::lock_guard<std::mutex> lock(received.mutex);
  for (const auto& g : received.grids)
    if (g->header.stamp == stamp) return true;
  return false;
}

bool occupancyWithStamp(const ros::Time& stamp)
{
  std::lock_guard<std::mutex> lock(received.mutex);
  for (const auto& g : received.occupancy)
    if (g->header.stamp == stamp) return true;
  return false;
}

/// The value of "clouds rejected" in the latest ScanGrid diagnostic status, or −1.
int rejectedInDiagnostics()
{
  std::lock_guard<std::mutex> lock(received.mutex);
  int value = -1;
  for (const auto& array : received.diagnostics)
    for (const auto& status : array->status)
      if (status.name.find("ScanGrid") != std::string::npos)
        for (const auto& kv : status.values)
          if (kv.key == "clouds rejected") value = std::stoi(kv.value);
  return value;
}

}  // namespace

TEST(ScanGridNodelet, PublishesGridsWithTheCloudStampAndSurvivesMalformedClouds)
{
  ros::NodeHandle nh;
  tf2_ros::StaticTransformBroadcaster tf_broadcaster;
  geometry_msgs::TransformStamped t;
  t.header.stamp = ros::Time::now();
  t.header.frame_id = "base_link";
  t.child_frame_id = "lidar";
  t.transform.translation.x = 1.0;
  t.transform.translation.z = 1.8;
  t.transform.rotation.w = 1.0;
  tf_broadcaster.sendTransform(t);

  ros::Publisher pub = nh.advertise<sensor_msgs::PointCloud2>("points", 10);
  ros::Subscriber grid_sub = nh.subscribe("scan_grid", 10, onGrid);
  ros::Subscriber occupancy_sub = nh.subscribe("scan_grid/occupancy", 10, onOccupancy);
  ros::Subscriber diagnostics_sub = nh.subscribe("/diagnostics", 10, onDiagnostics);
  ASSERT_TRUE(waitFor([&] {
    return pub.getNumSubscribers() > 0 && grid_sub.getNumPublishers() > 0 && occupancy_sub.getNumPublishers() > 0;
  })) << "the nodelet did not connect to points / scan_grid";

  // 1. A good cloud: a grid with its stamp, in base_link, classes [F, O], the wall occupied.
  const ros::Time t1(1000, 1);
  // The nodelet may still be connecting its own subscribers: resend until the first grid arrives.
  ASSERT_TRUE(waitFor([&] {
    pub.publish(wallCloud(t1));
    return waitFor([&] { return gridWithStamp(t1); }, 1.0);
  })) << "no grid for the first cloud";
  {
    std::lock_guard<std::mutex> lock(received.mutex);
    const auto& g = *received.grids.back();
    EXPECT_EQ(g.header.frame_id, "base_link");
    ASSERT_EQ(g.classes.size(), 2u);
    EXPECT_EQ(g.classes[0], "F");
    EXPECT_EQ(g.classes[1], "O");
    EXPECT_EQ(g.info.width, 80u);  // 40 m at 0.5 m (scan_grid.test)
    EXPECT_EQ(g.info.height, 80u);
    const std::size_t n = g.info.width * g.info.height;
    ASSERT_EQ(g.masses.size(), g.focal_sets.size() * n);
    // Wall at base_link x = 11.1 → column 62, y ∈ [−2.5, 2.5] → rows 35 … 45.
    std::size_t occupied = 0;
    for (std::size_t k = 0; k < g.focal_sets.size(); ++k)
      if (g.focal_sets[k] == 2)
        for (std::size_t i = 0; i < n; ++i)
        {
          if (g.masses[k * n + i] == 0.0f) continue;
          EXPECT_FLOAT_EQ(g.masses[k * n + i], 0.8f);
          EXPECT_EQ(i % g.info.width, 62u);
          ++occupied;
        }
    EXPECT_EQ(occupied, 11u);
  }
  EXPECT_TRUE(waitFor([&] { return occupancyWithStamp(t1); }));

  // 2. Malformed clouds: no z field; data shorter than width * height * point_step.
  const ros::Time t2(1001, 0), t3(1002, 0), t4(1003, 0);
  auto no_z = wallCloud(t2);
  no_z->fields.erase(no_z->fields.begin() + 2);
  pub.publish(no_z);
  auto short_data = wallCloud(t3);
  short_data->data.resize(short_data->data.size() - 1);
  pub.publish(short_data);
  // 3. The next good cloud is processed.
  pub.publish(wallCloud(t4));
  ASSERT_TRUE(waitFor([&] { return gridWithStamp(t4); })) << "no grid for the good cloud after the malformed ones";
  EXPECT_FALSE(gridWithStamp(t2));
  EXPECT_FALSE(gridWithStamp(t3));
  EXPECT_TRUE(waitFor([&] { return occupancyWithStamp(t4); }));
  // 4. Both are counted.
  EXPECT_TRUE(waitFor([&] { return rejectedInDiagnostics() == 2; })) << "clouds rejected = " << rejectedInDiagnostics();
}

int main(int argc, char** argv)
{
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "scan_grid_rostest");
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const int result = RUN_ALL_TESTS();
  spinner.stop();
  ros::shutdown();
  return result;
}

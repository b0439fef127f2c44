// A short scenario written to a bag and read back: topics, types, frames, stamps, counts, latched
// /tf_static, and message contents against the simulator's own records.
#include <gtest/gtest.h>

#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <tf2_msgs/TFMessage.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <unistd.h>

#include "../sim/town_fixture.hpp"
#include "map_aided_fusion/ros/sim_bag.hpp"

using namespace map_aided_fusion;

namespace {

sim::Scenario shortScenario()
{
  sim::Scenario sc;
  sc.duration = 1.0;
  sc.tf_rate_hz = 50.0;
  sc.lidar = sim::LidarParams::fromPreset("ibeo4");
  sc.ego.route = { { -130.0, -1.5 }, { 0.0, -1.5 } };
  sc.ego.motion.speed = 8.0;
  sim::ObjectSpec car;
  sim::objectKindDefaults("car", car);
  car.id = 5;
  car.path = { { -110.0, -1.5 }, { 0.0, -1.5 } };
  car.motion.speed = 6.0;
  sc.objects.push_back(car);
  return sc;
}

}  // namespace

TEST(SimBag, WriteAndReadBack)
{
  ros::Time::init();
  const std::string path = "/tmp/maf_test_sim_bag_" + std::to_string(::getpid()) + ".bag";
  sim::Simulator simulator(shortScenario(), maf_test::townLikeMap());
  SimBagOptions options;
  options.path = path;
  const SimBagStats stats = writeSimulationBag(simulator, options);
  EXPECT_EQ(stats.scans, 10);
  EXPECT_EQ(stats.tf_messages, 51u);  // 0, 0.02, ..., 1.0 s

  sim::Simulator reference(shortScenario(), maf_test::townLikeMap());
  const sim::Scenario& sc = reference.scenario();
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  rosbag::View view(bag);
  std::map<std::string, int> counts;
  std::map<std::string, std::string> types;
  double last_tf = -1.0;
  int scan = 0, grid_scan = 0;
  sim::ScanFrame frame;
  std::size_t points = 0;
  for (const rosbag::MessageInstance& m : view)
  {
    ++counts[m.getTopic()];
    types[m.getTopic()] = m.getDataType();
    if (m.getTopic() == "/tf_static")
    {
      const auto h = m.getConnectionHeader();
      ASSERT_TRUE(h);
      EXPECT_EQ((*h)["latching"], "1");
      const auto tf = m.instantiate<tf2_msgs::TFMessage>();
      ASSERT_EQ(tf->transforms.size(), 1u);
      EXPECT_EQ(tf->transforms[0].header.frame_id, "base_link");
      EXPECT_EQ(tf->transforms[0].child_frame_id, "lidar");
      EXPECT_DOUBLE_EQ(tf->transforms[0].transform.translation.x, 3.7);
      EXPECT_DOUBLE_EQ(tf->transforms[0].transform.translation.z, 0.5);
    }
    else if (m.getTopic() == "/tf")
    {
      const auto tf = m.instantiate<tf2_msgs::TFMessage>();
      ASSERT_EQ(tf->transforms.size(), 1u);
      const auto& t = tf->transforms[0];
      EXPECT_EQ(t.header.frame_id, "map");
      EXPECT_EQ(t.child_frame_id, "base_link");
      const double ts = t.header.stamp.toSec() - sc.start_stamp;
      EXPECT_GT(ts, last_tf);
      last_tf = ts;
      const sim::Pose2 ego = reference.egoPose(ts);
      EXPECT_NEAR(t.transform.translation.x, ego.x, 1e-6);
      EXPECT_NEAR(2.0 * std::atan2(t.transform.rotation.z, t.transform.rotation.w), ego.yaw, 1e-6);
      EXPECT_EQ(m.getTime(), t.header.stamp);
    }
    else if (m.getTopic() == "/points")
    {
      const auto cloud = m.instantiate<sensor_msgs::PointCloud2>();
      reference.scan(scan, frame);
      EXPECT_EQ(cloud->header.frame_id, "lidar");
      EXPECT_NEAR(cloud->header.stamp.toSec(), sc.start_stamp + 0.1 * scan, 1e-6);
      ASSERT_EQ(cloud->fields.size(), 6u);
      EXPECT_EQ(cloud->fields[4].name, "ring");
      EXPECT_EQ(cloud->fields[4].datatype, sensor_msgs::PointField::UINT16);
      EXPECT_EQ(cloud->fields[3].name, "intensity");
      EXPECT_EQ(cloud->fields[5].name, "time");
      EXPECT_EQ(cloud->fields[5].offset, 18u);
      EXPECT_EQ(cloud->fields[5].datatype, sensor_msgs::PointField::FLOAT32);
      ASSERT_EQ(cloud->width, frame.points.size());
      ASSERT_EQ(cloud->point_step, 22u);
      ASSERT_EQ(cloud->data.size(), 22u * frame.points.size());
      ASSERT_GT(frame.points.size(), 500u);
      float x, time;
      std::uint16_t ring;
      const std::size_t last = frame.points.size() - 1;
      std::memcpy(&x, &cloud->data[22 * last], 4);
      std::memcpy(&ring, &cloud->data[22 * last + 16], 2);
      std::memcpy(&time, &cloud->data[22 * last + 18], 4);
      EXPECT_EQ(x, frame.points[last].x);
      EXPECT_EQ(ring, frame.points[last].ring);
      EXPECT_EQ(time, frame.points[last].time);
      points += cloud->width;
      ++scan;
    }
    else if (m.getTopic() == "/ground_truth/classes")
    {
      const auto grid = m.instantiate<nav_msgs::OccupancyGrid>();
      EXPECT_EQ(grid->header.frame_id, "map");
      EXPECT_EQ(grid->info.width, 200u);
      EXPECT_FLOAT_EQ(grid->info.resolution, 0.5f);
      sim::ScanFrame f;
      reference.scan(grid_scan, f);
      EXPECT_NEAR(grid->info.origin.position.x, f.truth_geometry.origin_x, 1e-9);
      EXPECT_EQ(std::vector<std::int8_t>(grid->data.begin(), grid->data.end()), f.truth_classes);
      ++grid_scan;
    }
    else if (m.getTopic() == "/ground_truth/objects")
    {
      const auto objs = m.instantiate<GroundTruthObjectArray>();
      EXPECT_EQ(objs->header.frame_id, "map");
      ASSERT_EQ(objs->objects.size(), 1u);
      EXPECT_EQ(objs->objects[0].id, 5u);
      EXPECT_EQ(objs->objects[0].kind, "car");
      EXPECT_EQ(objs->objects[0].cell_class, 4);
      EXPECT_NEAR(objs->objects[0].velocity.x, 6.0, 1e-9);
    }
  }
  EXPECT_EQ(counts["/points"], 10);
  EXPECT_EQ(counts["/ground_truth/classes"], 10);
  EXPECT_EQ(counts["/ground_truth/objects"], 10);
  EXPECT_EQ(counts["/tf"], 51);
  EXPECT_EQ(counts["/tf_static"], 1);
  EXPECT_EQ(counts.size(), 5u);
  EXPECT_EQ(types["/points"], "sensor_msgs/PointCloud2");
  EXPECT_EQ(types["/ground_truth/classes"], "nav_msgs/OccupancyGrid");
  EXPECT_EQ(types["/ground_truth/objects"], "map_aided_fusion/GroundTruthObjectArray");
  EXPECT_EQ(types["/tf"], "tf2_msgs/TFMessage");
  EXPECT_EQ(points, stats.points);
  bag.close();
  std::remove(path.c_str());
}

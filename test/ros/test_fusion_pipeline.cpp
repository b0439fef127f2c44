// rostest of the whole pipeline (map loader, scan grid and fusion nodelets in one manager): a synthetic
// lidar on a vehicle standing at a road sees a car drive across; the car must be published as moving.
// Then a scan without a transform must be dropped and counted, and a jump back in time must reset.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>
#include <visualization_msgs/MarkerArray.h>

#include "synthetic_lidar.hpp"

namespace {

using maf_test::Box;
using maf_test::makeCloud;
constexpr double kScanPeriod = 0.1;

class PipelineTest : public ::testing::Test
{
protected:
  void SetUp() override
  {
    ros::NodeHandle pnh("~");
    pnh.param("vehicle_x", vehicle_x_, 0.0);
    pnh.param("vehicle_y", vehicle_y_, 0.0);
    pnh.param("vehicle_yaw", vehicle_yaw_, 0.0);
    pnh.param("car_lane_y", car_lane_y_, 4.0);
    points_pub_ = nh_.advertise<sensor_msgs::PointCloud2>("points", 10);
    objects_sub_ = nh_.subscribe("objects", 10, &PipelineTest::onObjects, this);
    decision_sub_ = nh_.subscribe("decision", 10, &PipelineTest::onDecision, this);
    diagnostics_sub_ = nh_.subscribe("/diagnostics", 50, &PipelineTest::onDiagnostics, this);
    static_broadcaster_.sendTransform(maf_test::lidarMount());
  }

  void onObjects(const visualization_msgs::MarkerArray::ConstPtr& m)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    objects_ = *m;
  }
  void onDecision(const nav_msgs::OccupancyGrid::ConstPtr& m)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    decision_ = *m;
    latencies_ms_.push_back((ros::Time::now() - m->header.stamp).toSec() * 1e3);
  }
  void onDiagnostics(const diagnostic_msgs::DiagnosticArray::ConstPtr& m)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& s : m->status)
    {
      if (s.name.find("fusion") == std::string::npos) continue;
      for (const auto& kv : s.values) fusion_diagnostics_[kv.key] = kv.value;
    }
  }
  double diagnostic(const std::string& key)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = fusion_diagnostics_.find(key);
    return it == fusion_diagnostics_.end() ? -1.0 : std::stod(it->second);
  }

  void sendPose(const ros::Time& stamp)
  {
    geometry_msgs::TransformStamped t;
    t.header.frame_id = "map";
    t.header.stamp = stamp;
    t.child_frame_id = "base_link";
    t.transform.translation.x = vehicle_x_;
    t.transform.translation.y = vehicle_y_;
    t.transform.rotation.z = std::sin(0.5 * vehicle_yaw_);
    t.transform.rotation.w = std::cos(0.5 * vehicle_yaw_);
    broadcaster_.sendTransform(t);
  }

  /// base_link → map.
  void toMap(double bx, double by, double& mx, double& my) const
  {
    mx = vehicle_x_ + std::cos(vehicle_yaw_) * bx - std::sin(vehicle_yaw_) * by;
    my = vehicle_y_ + std::sin(vehicle_yaw_) * bx + std::cos(vehicle_yaw_) * by;
  }

  void spinFor(double seconds)
  {
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(seconds);
    while (ros::ok() && ros::WallTime::now() < end)
    {
      ros::spinOnce();
      ros::WallDuration(0.01).sleep();
    }
  }

  ros::NodeHandle nh_;
  double vehicle_x_ = 0, vehicle_y_ = 0, vehicle_yaw_ = 0, car_lane_y_ = 4.0;
  ros::Publisher points_pub_;
  ros::Subscriber objects_sub_, decision_sub_, diagnostics_sub_;
  tf2_ros::TransformBroadcaster broadcaster_;
  tf2_ros::StaticTransformBroadcaster static_broadcaster_;
  std::mutex mutex_;
  std::optional<visualization_msgs::MarkerArray> objects_;
  std::optional<nav_msgs::OccupancyGrid> decision_;
  std::map<std::string, std::string> fusion_diagnostics_;
  std::vector<double> latencies_ms_;  ///< cloud stamp → decision received, through the three nodelets
};

TEST_F(PipelineTest, CarCrossingIsMovingDropsAreCountedTimeJumpsReset)
{
  // Wait for the manager to subscribe.
  for (int i = 0; i < 300 && points_pub_.getNumSubscribers() == 0; ++i) spinFor(0.1);
  ASSERT_GT(points_pub_.getNumSubscribers(), 0u) << "nobody subscribes to points";
  spinFor(2.0);  // prior loaded and latched
  // The prior is softened when it arrives, not in the first scan's callback, and once while σ stays the same.
  for (int i = 0; i < 100 && diagnostic("prior softenings") < 1.0; ++i) spinFor(0.1);
  EXPECT_EQ(diagnostic("prior softenings"), 1.0) << "the prior was not softened on arrival";
  EXPECT_EQ(diagnostic("scans fused"), 0.0);

  const ros::Time t0 = ros::Time::now();
  double car_x = -18.0;
  for (int k = 0; k < 45; ++k)
  {
    // Stamped when sent, so that the latency below is the pipeline's own.
    const ros::Time stamp = std::max(ros::Time::now(), t0 + ros::Duration(k * kScanPeriod));
    sendPose(stamp);
    std::vector<Box> boxes;
    if (k >= 10)
    {
      boxes.push_back(Box{ car_x, car_lane_y_ - 1.0, car_x + 4.5, car_lane_y_ + 1.0, 1.5 });
      car_x += 1.0;
    }
    spinFor(0.02);
    points_pub_.publish(makeCloud(boxes, stamp));
    spinFor(kScanPeriod);
  }
  spinFor(1.5);
  EXPECT_EQ(diagnostic("prior softenings"), 1.0) << "the prior was softened again with the same sigma";

  {
    std::lock_guard<std::mutex> lock(mutex_);
    ASSERT_TRUE(decision_.has_value()) << "no decision layer published";
    ASSERT_TRUE(objects_.has_value()) << "no objects published";
    // The car's last position (base_link) → cells decided V.
    const auto& d = *decision_;
    int moving = 0, cells = 0;
    for (double bx = car_x - 1.0 + 0.25; bx < car_x + 3.5; bx += 0.5)
      for (double by = car_lane_y_ - 0.75; by < car_lane_y_ + 1.0; by += 0.5)
      {
        double mx, my;
        toMap(bx, by, mx, my);
        const int cx = static_cast<int>(std::floor((mx - d.info.origin.position.x) / d.info.resolution));
        const int cy = static_cast<int>(std::floor((my - d.info.origin.position.y) / d.info.resolution));
        if (cx < 0 || cy < 0 || cx >= static_cast<int>(d.info.width) || cy >= static_cast<int>(d.info.height)) continue;
        ++cells;
        moving += d.data[cy * d.info.width + cx] == 4;
      }
    EXPECT_GT(cells, 0);
    EXPECT_GT(moving, 0) << "no cell of the car is decided moving";
    bool moving_object = false;
    for (const auto& m : objects_->markers)
    {
      if (m.ns != "objects/box" || m.color.r < 0.9) continue;
      double mx, my;
      toMap(car_x + 1.0, car_lane_y_, mx, my);
      moving_object = moving_object || std::hypot(m.pose.position.x - mx, m.pose.position.y - my) < 5.0;
    }
    EXPECT_TRUE(moving_object) << "no moving object near the car";
    // Reported, not asserted (speed is measured by benchmarks, not by tests).
    std::vector<double> l = latencies_ms_;
    std::sort(l.begin(), l.end());
    if (!l.empty())
      std::cout << "end-to-end latency, cloud stamp -> decision received (ms): median " << l[l.size() / 2] << ", p90 "
                << l[l.size() * 9 / 10] << ", max " << l.back() << " over " << l.size() << " scans\n";
  }
  spinFor(1.5);
  const double fused = diagnostic("scans fused");
  EXPECT_GE(fused, 40.0);
  const double dropped_before = diagnostic("scans dropped (no transform)");
  ASSERT_GE(dropped_before, 0.0) << "fusion diagnostics not received";

  // A scan far older than any pose in the tf buffer: never transformable, dropped and counted.
  points_pub_.publish(makeCloud({}, t0 - ros::Duration(30.0)));
  spinFor(2.5);
  EXPECT_EQ(diagnostic("scans dropped (no transform)"), dropped_before + 1.0);
  EXPECT_EQ(diagnostic("scans fused"), fused) << "the scan without a transform was fused";

  // The data's time jumps back while the (wall) clock does not (rosbag play --loop without --clock): the late scans
  // keep coming, none fused, for more than time_jump_threshold (1 s): the grid resets once, then fuses again.
  const double resets_before = diagnostic("grid resets (time jump)");
  const double fused_before_jump = diagnostic("scans fused");
  for (int k = 0; k < 20; ++k)
  {
    const ros::Time back = t0 + ros::Duration(1.0 + 0.1 * k);
    sendPose(back);
    spinFor(0.05);
    points_pub_.publish(makeCloud({}, back));
    spinFor(0.1);
  }
  spinFor(2.5);
  EXPECT_EQ(diagnostic("grid resets (time jump)"), resets_before + 1.0);
  EXPECT_GE(diagnostic("scans fused"), fused_before_jump + 5.0) << "the new timeline is not fused";
}

}  // namespace

int main(int argc, char** argv)
{
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_fusion_pipeline");
  return RUN_ALL_TESTS();
}

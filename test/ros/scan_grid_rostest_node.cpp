// rostest: ScanGridNodelet in a manager, fed clouds; grids carry the cloud's stamp; malformed clouds are
// rejected (and counted in the diagnostics) and the next good cloud is processed.
#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <mutex>
#include <vector>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include "cloud_helpers.hpp"
#include "map_aided_fusion/EvidentialGrid.h"

namespace {

constexpr double kTimeout = 15.0;  // s


/// A wall 10 m ahead of the lidar, 1 m above the ground (the lidar is 1.8 m up), fields x y z intensity.
sensor_msgs::PointCloud2Ptr wallCloud(const ros::Time& stamp)
{
  auto c = boost::make_shared<sensor_msgs::PointCloud2>();
  c->header.stamp = stamp;
  c->header.frame_id = "lidar";
  using map_aided_fusion::test::floatField;
  c->fields = { floatField("x", 0), floatField("y", 4), floatField("z", 8), floatField("intensity", 12) };
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

/// @p name without its leading slashes (diagnostic_updater drops the node name's first one).
std::string withoutSlash(const std::string& name) { return name.substr(std::min(name.find_first_not_of('/'), name.size())); }

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

/// Publishes clouds on <ns>/points and records <ns>/scan_grid, <ns>/scan_grid/occupancy and the
/// ScanGrid diagnostics of the node whose private namespace is <ns>/scan_grid.
class Probe
{
public:
  explicit Probe(const std::string& ns) : nh_(ns), status_prefix_(withoutSlash(nh_.getNamespace() + "/scan_grid:"))
  {
    pub_ = nh_.advertise<sensor_msgs::PointCloud2>("points", 10);
    grid_sub_ = nh_.subscribe("scan_grid", 10, &Probe::onGrid, this);
    occupancy_sub_ = nh_.subscribe("scan_grid/occupancy", 10, &Probe::onOccupancy, this);
    diagnostics_sub_ = nh_.subscribe("/diagnostics", 10, &Probe::onDiagnostics, this);
  }

  bool connected() const
  {
    return pub_.getNumSubscribers() > 0 && grid_sub_.getNumPublishers() > 0 && occupancy_sub_.getNumPublishers() > 0;
  }
  void publish(const sensor_msgs::PointCloud2Ptr& cloud) { pub_.publish(cloud); }
  std::size_t cloudSubscribers() const { return pub_.getNumSubscribers(); }
  std::size_t gridPublishers() const { return grid_sub_.getNumPublishers(); }

  map_aided_fusion::EvidentialGrid::ConstPtr grid(const ros::Time& stamp)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& g : grids_)
      if (g->header.stamp == stamp) return g;
    return nullptr;
  }
  bool occupancy(const ros::Time& stamp)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& g : occupancy_)
      if (g->header.stamp == stamp) return true;
    return false;
  }
  /// The value of "clouds rejected" in the latest diagnostics of this node, or −1.
  int rejected()
  {
    std::lock_guard<std::mutex> lock(mutex_);
    return rejected_;
  }

  /// Publishes a good cloud until its grid arrives (the node may still be connecting).
  map_aided_fusion::EvidentialGrid::ConstPtr roundTrip(const ros::Time& stamp)
  {
    waitFor([&] {
      publish(wallCloud(stamp));
      return waitFor([&] { return grid(stamp) != nullptr; }, 1.0);
    });
    return grid(stamp);
  }

private:
  void onGrid(const map_aided_fusion::EvidentialGrid::ConstPtr& m)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    grids_.push_back(m);
  }
  void onOccupancy(const nav_msgs::OccupancyGrid::ConstPtr& m)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    occupancy_.push_back(m);
  }
  void onDiagnostics(const diagnostic_msgs::DiagnosticArray::ConstPtr& m)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& status : m->status)
      if (withoutSlash(status.name).rfind(status_prefix_, 0) == 0)
        for (const auto& kv : status.values)
          if (kv.key == "clouds rejected") rejected_ = std::stoi(kv.value);
  }

  ros::NodeHandle nh_;
  std::string status_prefix_;
  ros::Publisher pub_;
  ros::Subscriber grid_sub_, occupancy_sub_, diagnostics_sub_;
  std::mutex mutex_;
  std::vector<map_aided_fusion::EvidentialGrid::ConstPtr> grids_;
  std::vector<nav_msgs::OccupancyGrid::ConstPtr> occupancy_;
  int rejected_ = -1;
};

/// The wall cloud's grid: base_link, classes [F, O], 80 × 80 cells, μ_O on column 62, rows 35 … 45.
void checkWallGrid(const map_aided_fusion::EvidentialGrid& g)
{
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

std::unique_ptr<tf2_ros::StaticTransformBroadcaster> tf_broadcaster;

void publishLidarTransform()
{
  if (tf_broadcaster) return;
  tf_broadcaster = std::make_unique<tf2_ros::StaticTransformBroadcaster>();
  geometry_msgs::TransformStamped t;
  t.header.stamp = ros::Time::now();
  t.header.frame_id = "base_link";
  t.child_frame_id = "lidar";
  t.transform.translation.x = 1.0;
  t.transform.translation.z = 1.8;
  t.transform.rotation.w = 1.0;
  tf_broadcaster->sendTransform(t);
}

}  // namespace

TEST(ScanGridNodelet, PublishesGridsWithTheCloudStampAndSurvivesMalformedClouds)
{
  publishLidarTransform();
  Probe probe("/");
  ASSERT_TRUE(waitFor([&] { return probe.connected(); })) << "the nodelet did not connect to points / scan_grid";

  // 1. A good cloud: a grid with its stamp, in base_link, classes [F, O], the wall occupied.
  const ros::Time t1(1000, 1);
  const auto g1 = probe.roundTrip(t1);
  ASSERT_TRUE(g1) << "no grid for the first cloud";
  checkWallGrid(*g1);
  EXPECT_TRUE(waitFor([&] { return probe.occupancy(t1); }));

  // 2. Malformed clouds: no z field; data shorter than width * height * point_step.
  const ros::Time t2(1001, 0), t3(1002, 0), t4(1003, 0);
  // One at a time: the subscriber queue is short, and a cloud dropped by the queue is not a rejection.
  auto no_z = wallCloud(t2);
  no_z->fields.erase(no_z->fields.begin() + 2);
  probe.publish(no_z);
  EXPECT_TRUE(waitFor([&] { return probe.rejected() == 1; })) << "clouds rejected = " << probe.rejected();
  auto short_data = wallCloud(t3);
  short_data->data.resize(short_data->data.size() - 1);
  probe.publish(short_data);
  EXPECT_TRUE(waitFor([&] { return probe.rejected() == 2; })) << "clouds rejected = " << probe.rejected();
  // 3. The next good cloud is processed.
  probe.publish(wallCloud(t4));
  ASSERT_TRUE(waitFor([&] { return probe.grid(t4) != nullptr; })) << "no grid for the good cloud after the malformed ones";
  EXPECT_FALSE(probe.grid(t2));
  EXPECT_FALSE(probe.grid(t3));
  EXPECT_TRUE(waitFor([&] { return probe.occupancy(t4); }));
  // 4. Both are counted.
  EXPECT_TRUE(waitFor([&] { return probe.rejected() == 2; })) << "clouds rejected = " << probe.rejected();
  // 5. A tf1-style frame id ("/lidar") is accepted.
  const ros::Time t5(1004, 0);
  auto slashed = wallCloud(t5);
  slashed->header.frame_id = "/lidar";
  probe.publish(slashed);
  const bool got_t5 = waitFor([&] { return probe.grid(t5) != nullptr; });
  ASSERT_TRUE(got_t5) << "no grid for a cloud in frame /lidar";
  checkWallGrid(*probe.grid(t5));
}

TEST(ScanGridNode, PlainNodeRunsTheSameWorker)
{
  publishLidarTransform();
  Probe probe("/plain");
  ASSERT_TRUE(waitFor([&] { return probe.connected(); })) << "scan_grid_node did not connect";
  const ros::Time t(2000, 5);
  const auto g = probe.roundTrip(t);
  ASSERT_TRUE(g) << "no grid from scan_grid_node";
  checkWallGrid(*g);
}

TEST(ScanGridNodelet, InvalidParameterLeavesTheNodeletIdleAndTheManagerAlive)
{
  publishLidarTransform();
  // /bad/scan_grid was loaded with mu_free = 1.5: it must neither subscribe nor publish.
  Probe bad("/bad");
  ros::WallDuration(2.0).sleep();
  EXPECT_EQ(bad.cloudSubscribers(), 0u);
  EXPECT_EQ(bad.gridPublishers(), 0u);
  // The manager that holds it still runs the good nodelet.
  Probe good("/");
  ASSERT_TRUE(waitFor([&] { return good.connected(); }));
  EXPECT_TRUE(good.roundTrip(ros::Time(3000, 0)));
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

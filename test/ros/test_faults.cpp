// rostests of the pipeline under faults (launch/map_aided_fusion.launch in one manager, a synthetic lidar):
// one test per fault of the "never throw evidence away" issue. test/faults.test runs Faults.* on wall time;
// test/bag_loop.test runs BagLoop.* under simulated time, replaying a recorded drive three times in a loop.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <dynamic_reconfigure/Reconfigure.h>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_msgs/Header.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include "../run_command.hpp"
#include "synthetic_lidar.hpp"

namespace {

using maf_test::Box;
using maf_test::makeCloud;

constexpr double kScanPeriod = 0.1;
constexpr double kSettle = 2.5;  // s: more than two diagnostic periods

/// What the three nodelets report on /diagnostics, by status (name fragment) then key.
/// Clouds the probe's publisher holds (more than Item13's burst of 61).
constexpr int kPublisherQueue = 100;

class Probe
{
public:
  Probe()
  {
    ros::NodeHandle nh;
    // Room for Item13's whole burst: clouds are lost in the ScanGrid's input queue, which is what it counts, not
    // in this publisher's queue (a cloud dropped here only leaves a gap the ScanGrid sees while idle).
    points_ = nh.advertise<sensor_msgs::PointCloud2>("points", kPublisherQueue);
    tf_ = nh.advertise<tf2_msgs::TFMessage>("/tf", 100);
    diagnostics_ = nh.subscribe("/diagnostics", 100, &Probe::onDiagnostics, this);
    decision_ = nh.subscribe("/map_aided_fusion/decision", 5, &Probe::onDecision, this);
    static_broadcaster_.sendTransform(maf_test::lidarMount());
  }

  void onDiagnostics(const diagnostic_msgs::DiagnosticArray::ConstPtr& m)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& s : m->status)
    {
      // Names are "<node namespace>: <task>"; every namespace holds "map_aided_fusion".
      auto endsWith = [&](const std::string& tail) {
        return s.name.size() >= tail.size() && s.name.compare(s.name.size() - tail.size(), tail.size(), tail) == 0;
      };
      const auto has = [&](const char* part) { return s.name.find(part) != std::string::npos; };
      const std::string who = has("fusion_huge")     ? "fusion_huge" :
                              has("fusion_typo")     ? "fusion_typo" :
                              has("scan_grid_wrong") ? "scan_grid_wrong" :
                              endsWith(": fusion")    ? "fusion" :
                              endsWith(": ScanGrid")  ? "scan_grid" :
                              endsWith(": PriorGrid") ? "prior_grid" :
                                                        "";
      if (who.empty()) continue;
      auto& d = values_[who];
      for (const auto& kv : s.values) d[kv.key] = kv.value;
      level_[who] = s.level;
      message_[who] = s.message;
      ++messages_[who];
    }
  }
  void onDecision(const nav_msgs::OccupancyGrid::ConstPtr& m)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    known_cells_ = 0;
    for (const auto v : m->data) known_cells_ += v >= 0;
  }

  /// A numeric diagnostic value, or −1 when not received.
  double value(const std::string& who, const std::string& key)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto w = values_.find(who);
    if (w == values_.end()) return -1.0;
    auto it = w->second.find(key);
    if (it == w->second.end()) return -1.0;
    try
    {
      return std::stod(it->second);
    }
    catch (const std::exception&)
    {
      return -1.0;
    }
  }
  std::string text(const std::string& who, const std::string& key)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    return values_[who][key];
  }
  int level(const std::string& who)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    return level_.count(who) ? level_[who] : -1;
  }
  std::string message(const std::string& who)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    return message_[who];
  }
  std::size_t messages(const std::string& who)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    return messages_[who];
  }
  std::size_t knownCells()
  {
    std::lock_guard<std::mutex> lock(mutex_);
    return known_cells_;
  }

  void sendPose(const ros::Time& stamp, double x = 0.0)
  {
    geometry_msgs::TransformStamped t;
    t.header.frame_id = "map";
    t.header.stamp = stamp;
    t.child_frame_id = "base_link";
    t.transform.translation.x = x;
    t.transform.rotation.w = 1.0;
    tf2_msgs::TFMessage m;
    m.transforms.push_back(t);
    tf_.publish(m);
  }
  void sendCloud(const ros::Time& stamp, const std::string& frame = "lidar")
  {
    points_.publish(makeCloud({ Box{ 8.0, 3.0, 12.5, 5.0, 1.5 } }, stamp, frame));
  }
  /// A blind sweep: every point NaN (a fogged window), or no point at all (@p empty).
  void sendBlindCloud(const ros::Time& stamp, bool empty)
  {
    sensor_msgs::PointCloud2 c = makeCloud({}, stamp);
    if (empty)
    {
      sensor_msgs::PointCloud2Modifier(c).resize(0);
    }
    else
    {
      for (sensor_msgs::PointCloud2Iterator<float> it(c, "x"); it != it.end(); ++it)
        it[0] = it[1] = it[2] = std::numeric_limits<float>::quiet_NaN();
    }
    points_.publish(c);
  }

  /// Spins on wall time while @p done is false, at most @p seconds; true when done.
  template <class F>
  bool waitFor(F&& done, double seconds)
  {
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(seconds);
    while (ros::ok() && ros::WallTime::now() < end)
    {
      if (done()) return true;
      ros::spinOnce();
      ros::WallDuration(0.01).sleep();
    }
    return done();
  }
  void spinFor(double seconds)
  {
    waitFor([] { return false; }, seconds);
  }

  ros::Publisher points_, tf_;

private:
  ros::Subscriber diagnostics_, decision_;
  tf2_ros::StaticTransformBroadcaster static_broadcaster_;
  std::mutex mutex_;
  std::map<std::string, std::map<std::string, std::string>> values_;
  std::map<std::string, int> level_;
  std::map<std::string, std::string> message_;
  std::map<std::string, std::size_t> messages_;
  std::size_t known_cells_ = 0;
};

Probe* probe = nullptr;
ros::Time last_stamp;  ///< stamp of the last cloud sent in order (wall-time tests)

/// Sends @p n scans at 10 Hz, stamped when sent, with their poses; waits until the fusion counted them.
void drive(int n)
{
  const double fused0 = probe->value("fusion", "scans fused");
  for (int k = 0; k < n; ++k)
  {
    last_stamp = ros::Time::now();
    probe->sendPose(last_stamp);
    probe->spinFor(0.02);
    probe->sendCloud(last_stamp);
    probe->spinFor(kScanPeriod);
  }
  probe->sendPose(ros::Time::now());
  probe->waitFor([&] { return probe->value("fusion", "scans fused") >= fused0 + n - 1; }, 5.0);
}

void setUpPipeline()
{
  ASSERT_TRUE(probe->waitFor([] { return probe->points_.getNumSubscribers() > 0; }, 30.0)) << "no subscriber";
  probe->spinFor(1.0);
  if (probe->value("fusion", "scans fused") < 10.0) drive(20);
  ASSERT_GE(probe->value("fusion", "scans fused"), 10.0) << "the pipeline does not fuse";
}

// ------------------------------------------------------------------------------------------------
// Wall time (test/faults.test)
// ------------------------------------------------------------------------------------------------

TEST(Faults, Item1_OutOfOrderScanIsDroppedAndCountedNotAReset)
{
  setUpPipeline();
  const double resets = probe->value("fusion", "grid resets (time jump)");
  const double out_of_order = probe->value("fusion", "scans dropped (out of order)");
  const std::size_t known = probe->knownCells();
  ASSERT_GT(known, 100u);
  probe->sendCloud(last_stamp - ros::Duration(0.05));  // 50 ms late, as from a second lidar
  EXPECT_TRUE(probe->waitFor(
      [&] { return probe->value("fusion", "scans dropped (out of order)") == out_of_order + 1.0; }, kSettle))
      << "out of order: " << probe->value("fusion", "scans dropped (out of order)");
  EXPECT_EQ(probe->value("fusion", "grid resets (time jump)"), resets);
  drive(3);
  EXPECT_GE(probe->knownCells(), known * 9 / 10) << "evidence was thrown away";
  EXPECT_EQ(probe->value("fusion", "grid resets (time jump)"), resets);
}

TEST(Faults, Item2_CloudStampedZeroIsRejectedAndCounted)
{
  setUpPipeline();
  const double rejected = probe->value("scan_grid", "clouds rejected: zero_stamp");
  const double resets = probe->value("fusion", "grid resets (time jump)");
  probe->sendCloud(ros::Time(0));
  EXPECT_TRUE(probe->waitFor(
      [&] { return probe->value("scan_grid", "clouds rejected: zero_stamp") == std::max(0.0, rejected) + 1.0; },
      kSettle));
  drive(2);
  EXPECT_EQ(probe->value("fusion", "grid resets (time jump)"), resets);
}

TEST(Faults, Item3_ScansReleasedAfterATfGapNeverReset)
{
  setUpPipeline();
  const double resets = probe->value("fusion", "grid resets (time jump)");
  const double fused = probe->value("fusion", "scans fused");
  const double out_of_order = probe->value("fusion", "scans dropped (out of order)");
  // A tf gap: three clouds wait for their transform, then one pose after them releases them all.
  const ros::Time t0 = ros::Time::now();
  for (int k = 1; k <= 3; ++k)
  {
    probe->sendCloud(t0 + ros::Duration(0.1 * k));
    probe->spinFor(kScanPeriod);
  }
  probe->spinFor(0.3);
  probe->sendPose(t0 + ros::Duration(0.45));
  EXPECT_TRUE(probe->waitFor(
      [&] {
        return probe->value("fusion", "scans fused") + probe->value("fusion", "scans dropped (out of order)") ==
               fused + out_of_order + 3.0;
      },
      kSettle))
      << "fused " << probe->value("fusion", "scans fused") - fused << ", out of order "
      << probe->value("fusion", "scans dropped (out of order)") - out_of_order;
  EXPECT_EQ(probe->value("fusion", "grid resets (time jump)"), resets);
  last_stamp = t0 + ros::Duration(0.3);
}

TEST(Faults, Item5_DiagnosticsTellTheLastSecondsAndTheMapLoaderReports)
{
  setUpPipeline();
  drive(10);
  probe->spinFor(1.2);
  EXPECT_GT(probe->value("fusion", "scan rate [Hz]"), 1.0);
  // Scans stop: within the staleness thresholds the status goes WARN then ERROR and the rate decays.
  EXPECT_TRUE(probe->waitFor([] { return probe->level("fusion") == diagnostic_msgs::DiagnosticStatus::ERROR; }, 6.0))
      << probe->message("fusion");
  EXPECT_TRUE(probe->waitFor([] { return probe->value("fusion", "scan rate [Hz]") == 0.0; }, 4.0))
      << "rate " << probe->value("fusion", "scan rate [Hz]");
  // Scans resume without loss: OK again (a drop long ago does not keep it WARN).
  drive(15);
  EXPECT_TRUE(probe->waitFor([] { return probe->level("fusion") == diagnostic_msgs::DiagnosticStatus::OK; }, 2.0))
      << probe->message("fusion");
  // The map loader has diagnostics of its own.
  EXPECT_GT(probe->messages("prior_grid"), 0u);
  EXPECT_GT(probe->value("prior_grid", "buildings kept"), 0.0);
  EXPECT_NE(probe->text("prior_grid", "file").find("town.osm"), std::string::npos);
  EXPECT_NE(probe->text("prior_grid", "grid [cells]").find(" x "), std::string::npos);
}

dynamic_reconfigure::Config reconfigure(const std::string& service, const std::string& name, double value)
{
  dynamic_reconfigure::Reconfigure srv;
  dynamic_reconfigure::DoubleParameter d;
  d.name = name;
  d.value = value;
  srv.request.config.doubles.push_back(d);
  EXPECT_TRUE(ros::service::waitForService(service, ros::Duration(10.0))) << service;
  EXPECT_TRUE(ros::service::call(service, srv)) << service;
  return srv.response.config;
}

double doubleOf(const dynamic_reconfigure::Config& c, const std::string& name)
{
  for (const auto& d : c.doubles)
    if (d.name == name) return d.value;
  return std::nan("");
}

TEST(Faults, Item6_ReconfigureRepliesWithTheValuesInForce)
{
  setUpPipeline();
  const std::string scan = "/map_aided_fusion/scan_grid/set_parameters";
  EXPECT_EQ(doubleOf(reconfigure(scan, "min_range", 90.0), "min_range"), 1.0) << "min_range above max_range shown";
  EXPECT_EQ(doubleOf(reconfigure(scan, "mu_free", 0.6), "mu_free"), 0.6) << "a valid change after a refusal";
  EXPECT_EQ(doubleOf(reconfigure(scan, "min_range", 2.0), "min_range"), 2.0);
  const std::string fusion = "/map_aided_fusion/fusion/set_parameters";
  for (const double bad : { 5.0, -1.0, std::numeric_limits<double>::infinity(), std::nan("") })
    EXPECT_EQ(doubleOf(reconfigure(fusion, "alpha_static", bad), "alpha_static"), 0.02) << "alpha_static " << bad;
  EXPECT_EQ(doubleOf(reconfigure(fusion, "alpha_static", 0.05), "alpha_static"), 0.05);
  probe->spinFor(kSettle);
  EXPECT_GE(probe->value("fusion", "reconfigure refused"), 4.0);
  EXPECT_GE(probe->value("scan_grid", "reconfigure refused"), 1.0);
  reconfigure(fusion, "alpha_static", 0.02);
  reconfigure(scan, "min_range", 1.0);
  reconfigure(scan, "mu_free", 0.7);
}

TEST(Faults, Item7_HugeWindowIsRefusedAndTheManagerKeepsWorking)
{
  setUpPipeline();
  // test/faults.test loads a second FusionNodelet with a 12 GB window into the same manager: its loader is up
  // with that configuration, but the nodelet refused to start (no reconfigure service of its own).
  ros::NodeHandle nh;
  double size_x = 0.0;
  EXPECT_TRUE(nh.getParam("/map_aided_fusion/fusion_huge/size_x", size_x) && size_x == 4096.0)
      << "the huge nodelet was not configured";
  std::vector<std::string> nodes;
  ros::master::getNodes(nodes);
  EXPECT_NE(std::find(nodes.begin(), nodes.end(), "/map_aided_fusion/fusion_huge"), nodes.end())
      << "the huge nodelet was not loaded";
  EXPECT_FALSE(ros::service::exists("/map_aided_fusion/fusion_huge/set_parameters", false))
      << "the huge fusion nodelet started";
  // It says why on /diagnostics, under its own name.
  EXPECT_TRUE(probe->waitFor([] { return probe->level("fusion_huge") == diagnostic_msgs::DiagnosticStatus::ERROR; },
                             kSettle));
  EXPECT_NE(probe->message("fusion_huge").find("memory_budget_mb"), std::string::npos) << probe->message("fusion_huge");
  const double fused = probe->value("fusion", "scans fused");
  drive(5);
  EXPECT_GE(probe->value("fusion", "scans fused"), fused + 4.0) << "the manager stopped fusing";
}

TEST(Faults, Item8_FusionNodeWithABadParameterSaysWhy)
{
  int status = 0;
  const std::string out =
      maf_test::runCommand(std::string(MAF_FUSION_NODE) + " __name:=bad_fusion _resolution:=-1", &status);
  EXPECT_EQ(status, 1);
  EXPECT_NE(out.find("resolution"), std::string::npos) << "printed: " << out;
}

TEST(Faults, Item11_FutureDuplicatePoseJumpAreCounted)
{
  setUpPipeline();
  const double future = std::max(0.0, probe->value("scan_grid", "clouds rejected: future_stamp"));
  probe->sendCloud(ros::Time::now() + ros::Duration(3600.0));
  EXPECT_TRUE(probe->waitFor(
      [&] { return probe->value("scan_grid", "clouds rejected: future_stamp") == future + 1.0; }, kSettle));

  drive(3);
  const double duplicate = probe->value("fusion", "scans dropped (duplicate stamp)");
  probe->sendCloud(last_stamp);  // the same stamp again
  EXPECT_TRUE(probe->waitFor(
      [&] { return probe->value("fusion", "scans dropped (duplicate stamp)") == duplicate + 1.0; }, kSettle));

  const double jumps = probe->value("fusion", "pose jumps");
  const ros::Time t = ros::Time::now();
  probe->sendPose(t, 500.0);  // 500 m in a tenth of a second
  probe->spinFor(0.02);
  probe->sendCloud(t);
  probe->spinFor(0.1);
  probe->sendPose(ros::Time::now(), 500.0);
  EXPECT_TRUE(probe->waitFor([&] { return probe->value("fusion", "pose jumps") == jumps + 1.0; }, kSettle));
  EXPECT_EQ(probe->value("fusion", "grid resets (time jump)"), 0.0);
}

TEST(Faults, Item12_BlindLidarIsReportedNotFusedAndTheGridKept)
{
  setUpPipeline();
  drive(5);
  probe->spinFor(0.5);
  const std::size_t known = probe->knownCells();
  ASSERT_GT(known, 100u);
  const double fused = probe->value("fusion", "scans fused");
  const double non_finite = std::max(0.0, probe->value("scan_grid", "clouds rejected: blind_non_finite"));
  const double empty = std::max(0.0, probe->value("scan_grid", "clouds rejected: blind_empty"));
  const double lost = std::max(0.0, probe->value("scan_grid", "clouds lost in the input queue"));
  // 4 s of all-NaN sweeps, then 1 s of empty ones, at 10 Hz with the vehicle's poses.
  bool warned = false;
  for (int k = 0; k < 50; ++k)
  {
    const ros::Time t = ros::Time::now();
    probe->sendPose(t);
    probe->spinFor(0.02);
    probe->sendBlindCloud(t, k >= 40);
    probe->spinFor(kScanPeriod);
    warned = warned || (probe->level("scan_grid") == diagnostic_msgs::DiagnosticStatus::WARN &&
                        probe->message("scan_grid").find("lidar blind for") != std::string::npos);
  }
  probe->spinFor(1.2);
  EXPECT_TRUE(warned) << "never WARN 'lidar blind' during the first seconds";
  EXPECT_EQ(probe->level("scan_grid"), diagnostic_msgs::DiagnosticStatus::ERROR) << probe->message("scan_grid");
  EXPECT_NE(probe->message("scan_grid").find("lidar blind for"), std::string::npos) << probe->message("scan_grid");
  EXPECT_GE(probe->value("scan_grid", "lidar blind for (s)"), 4.0);
  EXPECT_GE(probe->value("scan_grid", "clouds rejected: blind_non_finite") - non_finite, 35.0);
  EXPECT_GE(probe->value("scan_grid", "clouds rejected: blind_empty") - empty, 8.0);
  EXPECT_EQ(probe->value("fusion", "scans fused"), fused) << "a blind cloud reached the MapGrid";
  EXPECT_EQ(std::max(0.0, probe->value("scan_grid", "clouds lost in the input queue")), lost)
      << "every blind cloud was received and handled: none was lost in the input queue";
  EXPECT_EQ(probe->value("fusion", "grid resets (time jump)"), 0.0);
  // Sight returns: the decided cells were kept, and the blind spell is over.
  drive(3);
  probe->spinFor(0.5);
  EXPECT_GE(probe->knownCells(), known * 9 / 10) << "evidence was worn away while blind";
  EXPECT_TRUE(probe->waitFor([] { return probe->value("scan_grid", "lidar blind for (s)") == 0.0; }, kSettle));
}

TEST(Faults, Item13_CloudsLostInAFullInputQueueAreCountedAndWarned)
{
  setUpPipeline();
  drive(10);  // transforms over the last 1.2 s, which the burst's stamps fall in
  probe->spinFor(0.5);
  // A burst far faster than the ScanGrid (input_queue_size 2) builds, received whole by its intake thread: every
  // cloud is either built or counted lost where the backlog drops it, whatever the scheduling. Stamped 0.9 to 0.6 s
  // before the last fused scan, 5 ms apart: the fusion drops them as out of order (older by less than
  // time_jump_threshold), however long the builds take, so that its state is left alone and no reset can follow.
  const ros::Time base = last_stamp - ros::Duration(0.9);
  constexpr int kBurst = 60;
  std::vector<sensor_msgs::PointCloud2> burst;
  for (int k = 0; k <= kBurst; ++k) burst.push_back(makeCloud({ Box{ 8.0, 3.0, 12.5, 5.0, 1.5 } },
                                                              base + ros::Duration(0.005 * k)));
  const auto settled = [&](const char* key) {
    probe->spinFor(kSettle);
    return probe->value("scan_grid", key);
  };
  // The first cloud is sent alone and built (seen on the ScanGrid's output, at once, unlike the diagnostics).
  std::atomic<bool> first_built{ false };
  ros::NodeHandle nh;
  ros::Subscriber grids = nh.subscribe<nav_msgs::OccupancyGrid>(
      "/map_aided_fusion/scan_grid/occupancy", 100,
      [&](const nav_msgs::OccupancyGrid::ConstPtr& m) { first_built = first_built || m->header.stamp == base; });
  ASSERT_TRUE(probe->waitFor([&] { return grids.getNumPublishers() > 0; }, 5.0));
  const double published0 = settled("clouds published");
  const double lost1 = std::max(0.0, probe->value("scan_grid", "clouds lost in the input queue"));
  probe->points_.publish(burst[0]);
  ASSERT_TRUE(probe->waitFor([&] { return first_built.load(); }, kSettle));
  for (int k = 1; k <= kBurst; ++k) probe->points_.publish(burst[k]);
  ASSERT_TRUE(probe->waitFor(
      [&] { return probe->level("scan_grid") >= diagnostic_msgs::DiagnosticStatus::WARN &&
                   probe->value("scan_grid", "clouds lost in the input queue") > lost1; },
      kSettle));
  const double built = settled("clouds published") - published0 - 1;
  const double counted = probe->value("scan_grid", "clouds lost in the input queue") - lost1;
  ASSERT_LT(built, kBurst) << "the burst did not overflow the input queue";
  EXPECT_GE(built, 1) << "the newest clouds are built";
  EXPECT_EQ(counted, kBurst - built) << "built " << built << " of " << kBurst;
  EXPECT_NE(probe->message("scan_grid").find("lost in the input queue"), std::string::npos)
      << probe->message("scan_grid");
  EXPECT_GE(probe->value("scan_grid", "clouds lost in the input queue in window"), counted);
  drive(3);
  EXPECT_EQ(probe->value("fusion", "grid resets (time jump)"), 0.0);
}

// ------------------------------------------------------------------------------------------------
// Simulated time (test/bag_loop.test): a 3 s drive recorded once, replayed three times with /clock going back
// at each loop, as `rosbag play --clock --loop` does; a transform from the end of a loop arrives after the
// jump, as it did with the real bag.
// ------------------------------------------------------------------------------------------------

TEST(BagLoop, ThreeLoopsResetOnceEachAndLoseNoScan)
{
  ros::NodeHandle nh;
  ros::Publisher clock = nh.advertise<rosgraph_msgs::Clock>("/clock", 10);
  ASSERT_TRUE(probe->waitFor([] { return probe->points_.getNumSubscribers() > 0; }, 30.0));
  constexpr double kStart = 1000.0;
  constexpr int kScansPerLoop = 30;
  // Simulated time runs 5x faster than the wall: a 15 s loop, longer than tf's 10 s cache, as in the real bag
  // whose new loop's transforms tf ignored as too old.
  constexpr double kSimPeriod = 0.5;
  auto tick = [&](double t) {
    rosgraph_msgs::Clock c;
    c.clock = ros::Time(t);
    clock.publish(c);
  };
  tick(kStart);
  probe->spinFor(1.0);
  std::vector<double> fused_per_loop;
  double fused_before = 0.0;
  for (int loop = 0; loop < 3; ++loop)
  {
    for (int k = 0; k < kScansPerLoop; ++k)
    {
      const double t = kStart + kSimPeriod * k;
      tick(t);
      probe->sendPose(ros::Time(t), 0.5 * k * kSimPeriod);
      probe->spinFor(0.02);
      probe->sendCloud(ros::Time(t));
      probe->spinFor(kScanPeriod);
      if (loop > 0 && k == 1)
        probe->sendPose(ros::Time(kStart + kSimPeriod * (kScansPerLoop + 1)), 0.0);  // late tf of the last loop
    }
    tick(kStart + kSimPeriod * kScansPerLoop);
    probe->sendPose(ros::Time(kStart + kSimPeriod * kScansPerLoop), 0.5 * kScansPerLoop * kSimPeriod);
    probe->spinFor(1.5);
    const double fused = probe->value("fusion", "scans fused");
    fused_per_loop.push_back(fused - fused_before);
    fused_before = fused;
  }
  for (std::size_t l = 0; l < fused_per_loop.size(); ++l)
    EXPECT_GE(fused_per_loop[l], kScansPerLoop - 3) << "loop " << l << " fused " << fused_per_loop[l] << " scans";
  EXPECT_EQ(probe->value("fusion", "grid resets (time jump)"), 2.0) << "one reset per backward jump";
  EXPECT_EQ(probe->value("fusion", "scans dropped (out of order)"), 0.0);
  // Diagnostics kept coming after the clock went back (they are on a wall timer) and tell the truth.
  const std::size_t n = probe->messages("fusion");
  probe->spinFor(2.5);
  EXPECT_GE(probe->messages("fusion"), n + 2) << "diagnostics stopped";
  EXPECT_TRUE(probe->waitFor([] { return probe->level("fusion") != diagnostic_msgs::DiagnosticStatus::OK; }, 4.0))
      << "OK while nothing is fused: " << probe->message("fusion");
}

TEST(Faults, Item16_AStartedHeaderOfNoScanToFuseIsRefusedAndTheGridKept)
{
  setUpPipeline();
  drive(5);
  probe->spinFor(0.5);
  const std::size_t known = probe->knownCells();
  ASSERT_GT(known, 100u);
  const double shifts = std::max(0.0, probe->value("fusion", "window shifts ahead (shift_ahead)"));
  const double frame0 = std::max(0.0, probe->value("fusion", "started headers refused (other frame)"));
  const double implausible0 = std::max(0.0, probe->value("fusion", "started headers refused (implausible pose)"));
  // A fixed frame 400 m away resolves at any stamp: during a 1 s lidar pause, 100 Hz of `started` headers in it
  // (a ScanGrid configured in that frame, a replayed topic), then as many in the vehicle's frame whose pose jumped
  // 400 m. Followed, either would move the window off the vehicle and drop every cell it had.
  geometry_msgs::TransformStamped far;
  far.header.frame_id = "map";
  far.header.stamp = ros::Time::now();
  far.child_frame_id = "elsewhere";
  far.transform.translation.x = 400.0;
  far.transform.rotation.w = 1.0;
  tf2_ros::StaticTransformBroadcaster broadcaster;
  broadcaster.sendTransform(far);
  ros::NodeHandle nh;
  ros::Publisher started = nh.advertise<std_msgs::Header>("/map_aided_fusion/scan_grid/started", 100);
  ASSERT_TRUE(probe->waitFor([&] { return started.getNumSubscribers() > 0; }, 5.0));
  probe->spinFor(0.3);
  constexpr int kHeaders = 50;
  for (int k = 0; k < 2 * kHeaders; ++k)
  {
    std_msgs::Header h;
    h.stamp = ros::Time::now();
    h.frame_id = k < kHeaders ? "elsewhere" : "base_link";
    if (k >= kHeaders) probe->sendPose(h.stamp, 400.0);
    probe->spinFor(0.005);
    started.publish(h);
    probe->spinFor(0.005);
  }
  EXPECT_TRUE(probe->waitFor(
      [&] { return probe->value("fusion", "started headers refused (other frame)") - frame0 >= kHeaders * 0.9 &&
                   probe->value("fusion", "started headers refused (implausible pose)") - implausible0 > 0.0 &&
                   probe->level("fusion") >= diagnostic_msgs::DiagnosticStatus::WARN; },
      kSettle))
      << probe->message("fusion");
  EXPECT_NE(probe->message("fusion").find("started headers refused"), std::string::npos) << probe->message("fusion");
  EXPECT_EQ(probe->value("fusion", "window shifts ahead (shift_ahead)"), shifts);
  // The lidar comes back where the vehicle really is: its evidence is all there.
  drive(3);
  probe->spinFor(0.5);
  EXPECT_GE(probe->knownCells(), known * 9 / 10) << "a refused header moved the window";
  EXPECT_EQ(probe->value("fusion", "grid resets (time jump)"), 0.0);
}

TEST(Faults, Item15_EveryMistakeNamesItsCause)
{
  setUpPipeline();
  // A misspelt key: refused, named, with the key meant.
  EXPECT_TRUE(probe->waitFor([] { return probe->level("fusion_typo") == diagnostic_msgs::DiagnosticStatus::ERROR; },
                             kSettle));
  EXPECT_NE(probe->message("fusion_typo").find("decision_treshold"), std::string::npos) << probe->message("fusion_typo");
  EXPECT_NE(probe->message("fusion_typo").find("did you mean 'decision_threshold'"), std::string::npos)
      << probe->message("fusion_typo");
  EXPECT_FALSE(ros::service::exists("/map_aided_fusion/fusion_typo/set_parameters", false));
  // A ScanGrid waiting on a topic nobody publishes says which.
  EXPECT_TRUE(probe->waitFor(
      [] { return probe->message("scan_grid_wrong").find("no cloud received on /no_such_points") != std::string::npos; },
      kSettle))
      << probe->message("scan_grid_wrong");
  // Clouds in a frame tf does not know: ERROR naming the frames once every cloud was rejected for stale_error.
  ros::NodeHandle nh;
  ros::Publisher wrong = nh.advertise<sensor_msgs::PointCloud2>("/no_such_points", 5);
  const boost::function<void(const nav_msgs::OccupancyGrid::ConstPtr&)> ignore = [](const auto&) {};
  ros::Subscriber out = nh.subscribe<nav_msgs::OccupancyGrid>("/map_aided_fusion/scan_grid_wrong/occupancy", 1, ignore);
  ASSERT_TRUE(probe->waitFor([&] { return wrong.getNumSubscribers() > 0 && out.getNumPublishers() > 0; }, 10.0));
  for (int k = 0; k < 20; ++k)
  {
    wrong.publish(makeCloud({}, ros::Time::now(), "nowhere"));
    probe->spinFor(kScanPeriod);
  }
  EXPECT_TRUE(probe->waitFor([] { return probe->level("scan_grid_wrong") == diagnostic_msgs::DiagnosticStatus::ERROR; },
                             kSettle + 3.0))
      << probe->message("scan_grid_wrong");
  EXPECT_NE(probe->message("scan_grid_wrong").find("nowhere"), std::string::npos) << probe->message("scan_grid_wrong");
  EXPECT_NE(probe->message("scan_grid_wrong").find("every cloud on /no_such_points rejected"), std::string::npos)
      << probe->message("scan_grid_wrong");
}

TEST(Faults, Item14_AVehicleFarFromTheMapIsReportedByTheMapLoader)
{
  setUpPipeline();
  probe->sendPose(ros::Time::now());
  EXPECT_TRUE(probe->waitFor([] { return probe->value("prior_grid", "vehicle distance to the map data [m]") >= 0.0 &&
                                         probe->level("prior_grid") == diagnostic_msgs::DiagnosticStatus::OK; },
                             kSettle))
      << probe->message("prior_grid");
  // 5 km east of the town (the localisation in another frame, a wrong origin).
  for (int k = 0; k < 15; ++k)
  {
    probe->sendPose(ros::Time::now(), 5000.0);
    probe->spinFor(kScanPeriod);
  }
  EXPECT_TRUE(probe->waitFor([] { return probe->level("prior_grid") == diagnostic_msgs::DiagnosticStatus::WARN; },
                             kSettle));
  EXPECT_NE(probe->message("prior_grid").find("from the nearest map data"), std::string::npos)
      << probe->message("prior_grid");
  EXPECT_GT(probe->value("prior_grid", "vehicle distance to the map data [m]"), 4000.0);
  probe->sendPose(ros::Time::now());  // back in town
  EXPECT_TRUE(probe->waitFor([] { return probe->level("prior_grid") == diagnostic_msgs::DiagnosticStatus::OK; },
                             kSettle))
      << probe->message("prior_grid");
}

// ------------------------------------------------------------------------------------------------
// Simulated time with the fusion's tf_queue_size at 20 (test/clock_lag.test): a /clock that falls 2 s behind
// the data, as `rosbag play --clock` does on a loaded machine, then a 3 s tf gap.
// ------------------------------------------------------------------------------------------------

class SimClock
{
public:
  SimClock()
  {
    ros::NodeHandle nh;
    pub_ = nh.advertise<rosgraph_msgs::Clock>("/clock", 10);
  }
  void set(double t)
  {
    rosgraph_msgs::Clock c;
    c.clock = ros::Time(t);
    pub_.publish(c);
  }

private:
  ros::Publisher pub_;
};

SimClock* sim_clock = nullptr;
constexpr double kSimStart = 2000.0;
double sim_data = kSimStart;  ///< stamp of the last scan sent

/// One scan at data time @p t with the clock at @p clock; the pose too unless @p with_pose is false.
void simScan(double t, double clock, bool with_pose = true)
{
  sim_clock->set(clock);
  if (with_pose) probe->sendPose(ros::Time(t), 0.5 * (t - kSimStart));
  probe->spinFor(0.02);
  probe->sendCloud(ros::Time(t));
  probe->spinFor(kScanPeriod);
  sim_data = t;
}

TEST(ClockLag, AClockFallingBehindTheDataClearsAndLosesNothing)
{
  static SimClock clock;  // lives for the ClockLag tests that follow
  sim_clock = &clock;
  clock.set(kSimStart);
  ASSERT_TRUE(probe->waitFor([] { return probe->points_.getNumSubscribers() > 0; }, 30.0));
  probe->spinFor(1.0);
  for (int k = 0; k < 10; ++k) simScan(kSimStart + 0.1 * k, kSimStart + 0.1 * k);
  // The clock now advances at half the data's pace, until it is 2 s behind, and stays 2 s behind.
  double lag = 0.0;
  for (int k = 10; k < 60; ++k)
  {
    lag = std::min(2.0, lag + 0.05);
    simScan(kSimStart + 0.1 * k, kSimStart + 0.1 * k - lag);
  }
  ASSERT_EQ(lag, 2.0);
  EXPECT_TRUE(probe->waitFor([] { return probe->value("fusion", "scans fused") >= 59.0; }, kSettle))
      << "fused " << probe->value("fusion", "scans fused") << " of 60";
  EXPECT_EQ(probe->value("fusion", "tf buffer clears"), 0.0);
  EXPECT_EQ(probe->value("fusion", "grid resets (time jump)"), 0.0);
  EXPECT_EQ(probe->value("fusion", "scans dropped (future stamp)"), 0.0);
  EXPECT_EQ(probe->value("fusion", "scans dropped (no transform)"), 0.0);
  EXPECT_EQ(probe->value("scan_grid", "tf buffer clears (time jump)"), 0.0);
  EXPECT_EQ(probe->value("scan_grid", "clouds rejected"), 0.0);
}

TEST(ClockLag, ScansReleasedAfterALongTfGapWithALargeQueueNeverReset)
{
  ASSERT_NE(sim_clock, nullptr) << "runs after AClockFallingBehindTheDataClearsAndLosesNothing";
  double t = sim_data;
  const auto next = [&t] {
    t += 0.1;
    return t;
  };
  for (int k = 0; k < 5; ++k)
  {
    const double d = next();
    simScan(d, d - 0.5);
  }
  probe->spinFor(0.5);
  const std::size_t known = probe->knownCells();
  ASSERT_GT(known, 100u);
  auto accounted = [] {
    return probe->value("fusion", "scans fused") + probe->value("fusion", "scans dropped (no transform)") +
           probe->value("fusion", "scans dropped (out of order)") + probe->value("fusion", "scans dropped (released late)");
  };
  const double before = accounted();
  // 3 s without any transform map <- base_link while the clouds keep coming; then poses again.
  for (int k = 0; k < 40; ++k)
  {
    const double d = next();
    simScan(d, d - 0.5, k >= 30);
  }
  EXPECT_TRUE(probe->waitFor([&] { return accounted() >= before + 39.0; }, kSettle))
      << "fused or dropped: " << accounted() - before << " of 40";
  EXPECT_LE(accounted(), before + 40.0);
  EXPECT_EQ(probe->value("fusion", "grid resets (time jump)"), 0.0) << "the released scans were read as a time jump";
  EXPECT_EQ(probe->value("fusion", "tf buffer clears"), 0.0);
  EXPECT_GE(probe->knownCells(), known * 9 / 10) << "evidence was thrown away";
}

}  // namespace

int main(int argc, char** argv)
{
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_faults");
  ros::NodeHandle nh;
  Probe p;
  probe = &p;
  return RUN_ALL_TESTS();
}

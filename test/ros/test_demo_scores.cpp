// rostest of launch/demo.launch (gui:=false): the three nodelets run on a short simulated drive replayed with
// rosbag play --clock; this node records the live `decision` layer, then scores it against the bag's ground
// truth and checks that the headline scores stay above floors measured on this scenario (a regression guard).
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <tf2/utils.h>

#include "map_aided_fusion/GroundTruthObjectArray.h"
#include "map_aided_fusion/eval/metrics.hpp"
#include "map_aided_fusion/ros/eval_conversions.hpp"

using namespace map_aided_fusion;

namespace {

double param(const std::string& name)
{
  double v = 0.0;
  EXPECT_TRUE(ros::NodeHandle("~").getParam(name, v)) << "missing ~" << name;
  return v;
}

TEST(DemoLaunch, HeadlineScoresStayAboveFloors)
{
  ros::NodeHandle nh;
  std::map<std::uint64_t, nav_msgs::OccupancyGrid> decisions;
  auto sub = nh.subscribe<nav_msgs::OccupancyGrid>(
      "/map_aided_fusion/decision", 50,
      [&decisions](const nav_msgs::OccupancyGrid::ConstPtr& m) { decisions[m->header.stamp.toNSec()] = *m; });
  std::string bag_path;
  ASSERT_TRUE(ros::NodeHandle("~").getParam("bag", bag_path));
  const double duration = param("duration");

  // Wait (wall time: the simulated clock stops with the bag) until decisions stop coming.
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(param("timeout"));
  ros::WallTime last_change = ros::WallTime::now();
  std::size_t last_count = 0;
  while (ros::ok() && ros::WallTime::now() < deadline)
  {
    ros::spinOnce();
    ros::WallDuration(0.05).sleep();
    if (decisions.size() != last_count)
    {
      last_count = decisions.size();
      last_change = ros::WallTime::now();
    }
    if (last_count > 0 && ros::WallTime::now() - last_change > ros::WallDuration(5.0)) break;
  }
  const double expected_scans = duration * 10.0;
  ASSERT_GT(decisions.size(), 0.8 * expected_scans) << "the pipeline published too few decisions";
  ASSERT_TRUE(std::filesystem::exists(bag_path));

  rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
  std::map<std::uint64_t, eval::ClassGrid> truth;
  std::map<std::uint64_t, std::vector<eval::TruthObject>> objects;
  for (const auto& m : rosbag::View(bag, rosbag::TopicQuery(std::vector<std::string>{ "/ground_truth/classes",
                                                                                      "/ground_truth/objects" })))
  {
    if (auto g = m.instantiate<nav_msgs::OccupancyGrid>()) truth[g->header.stamp.toNSec()] = toClassGrid(*g);
    if (auto o = m.instantiate<GroundTruthObjectArray>()) objects[o->header.stamp.toNSec()] = toTruthObjects(*o);
  }
  eval::ConfusionMatrix confusion;
  eval::ObjectScorer scorer;
  std::size_t matched = 0;
  for (const auto& [stamp, d] : decisions)
  {
    auto t = truth.find(stamp);
    if (t == truth.end()) continue;
    ++matched;
    const auto decision = toClassGrid(d);
    eval::accumulate(t->second, decision, confusion);
    auto o = objects.find(stamp);
    scorer.add(stamp * 1e-9, t->second, o == objects.end() ? std::vector<eval::TruthObject>{} : o->second, decision);
  }
  const auto f = eval::flatten(eval::VariantScores{ "live", "", confusion, scorer, matched });
  for (const auto& [k, v] : f) std::cout << "demo score " << k << " = " << v << "\n";
  EXPECT_GT(matched, 0.8 * expected_scans) << "decisions whose stamp matches a ground-truth scan";
  EXPECT_GE(f.at("free.iou"), param("floor_free_iou"));
  EXPECT_GE(f.at("building.iou"), param("floor_building_iou"));
  EXPECT_GE(f.at("stopped.iou"), param("floor_stopped_iou"));
  EXPECT_GE(f.at("moving.recall"), param("floor_moving_recall"));
  EXPECT_GE(f.at("objects.moving.detection_rate"), param("floor_moving_detection_rate"));
  EXPECT_LE(f.at("objects.stopped.called_moving_rate"), param("ceiling_stopped_called_moving"));
  std::filesystem::remove(bag_path);
}

}  // namespace

int main(int argc, char** argv)
{
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_demo_scores");
  return RUN_ALL_TESTS();
}

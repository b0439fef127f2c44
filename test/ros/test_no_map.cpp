// test/no_map.test: the sample launch without a map argument replays a bag with no prior at all.
#include <gtest/gtest.h>

#include <algorithm>
#include <mutex>
#include <string>
#include <vector>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>

namespace {

constexpr double kTimeout = 150.0;  // s: simulation, player delay and the drive
constexpr std::size_t kDecisions = 20;
constexpr std::int8_t kMappedBuilding = 1;  // core::CellClass::kMappedBuilding

TEST(NoMap, NoArgumentMeansNoPrior)
{
  ros::NodeHandle nh;
  std::mutex mutex;
  std::size_t decisions = 0, building_cells = 0, known_cells = 0;
  std::string prior_status;
  ros::Subscriber decision = nh.subscribe<nav_msgs::OccupancyGrid>(
      "/map_aided_fusion/decision", 5, [&](const nav_msgs::OccupancyGrid::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        ++decisions;
        building_cells += static_cast<std::size_t>(std::count(m->data.begin(), m->data.end(), kMappedBuilding));
        known_cells = static_cast<std::size_t>(std::count_if(m->data.begin(), m->data.end(), [](auto v) { return v >= 0; }));
      });
  ros::Subscriber diagnostics = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 20, [&](const diagnostic_msgs::DiagnosticArray::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        for (const auto& s : m->status)
          if (s.name.size() >= 8 && s.name.compare(s.name.size() - 8, 8, ": fusion") == 0)
            for (const auto& kv : s.values)
              if (kv.key == "prior") prior_status = kv.value;
      });
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(kTimeout);
  auto done = [&] {
    std::lock_guard<std::mutex> lock(mutex);
    return decisions >= kDecisions && !prior_status.empty();
  };
  while (ros::ok() && ros::WallTime::now() < end && !done())
  {
    ros::spinOnce();
    ros::WallDuration(0.05).sleep();
  }
  ASSERT_TRUE(done()) << decisions << " decisions, prior status '" << prior_status << "'";
  std::vector<std::string> nodes;
  ros::master::getNodes(nodes);
  EXPECT_EQ(std::find(nodes.begin(), nodes.end(), "/map_aided_fusion/prior_grid"), nodes.end())
      << "the map loader was started without a map";
  ros::master::V_TopicInfo topics;
  ros::master::getTopics(topics);
  for (const auto& t : topics) EXPECT_NE(t.name, "/map_aided_fusion/prior_grid") << "a prior is published";
  std::lock_guard<std::mutex> lock(mutex);
  EXPECT_EQ(prior_status, "none (vacuous)");
  EXPECT_EQ(building_cells, 0u) << "a mapped building was decided without a map";
  EXPECT_GT(known_cells, 100u) << "the lidar alone decided nothing";
}

}  // namespace

int main(int argc, char** argv)
{
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_no_map");
  return RUN_ALL_TESTS();
}

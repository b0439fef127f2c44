// rostest (test/prior_grid.test): the PriorGridNodelet's latched outputs reach a late subscriber with the
// town's known cells; a nodelet with a missing map reports it through ~reload and stays alive.
#include <gtest/gtest.h>

#include <ros/ros.h>
#include <std_srvs/Trigger.h>
#include <nav_msgs/OccupancyGrid.h>
#include <visualization_msgs/MarkerArray.h>

#include "map_aided_fusion/EvidentialGrid.h"

namespace {

using map_aided_fusion::EvidentialGrid;

constexpr double kTimeout = 30.0;  // s
constexpr std::uint8_t kB = 0b00010, kR = 0b11001, kT = 0b11101, kOmega = 0b11111, kW = 0b00011;  // bits F C N S V

template <class M>
boost::shared_ptr<const M> waitFor(const std::string& topic, double timeout = kTimeout)
{
  return ros::topic::waitForMessage<M>(topic, ros::Duration(timeout));
}

/// Mass of focal set @p set at map point (x, y).
double massAt(const EvidentialGrid& g, std::uint8_t set, double x, double y)
{
  const int cx = static_cast<int>(std::floor((x - g.info.origin.position.x) / g.info.resolution));
  const int cy = static_cast<int>(std::floor((y - g.info.origin.position.y) / g.info.resolution));
  const std::size_t n = static_cast<std::size_t>(g.info.width) * g.info.height;
  for (std::size_t k = 0; k < g.focal_sets.size(); ++k)
    if (g.focal_sets[k] == set) return g.masses[k * n + static_cast<std::size_t>(cy) * g.info.width + cx];
  return 0.0;
}

TEST(PriorGridNodelet, LateSubscriberReceivesTheLatchedPrior)
{
  ros::WallDuration(2.0).sleep();  // subscribe well after the nodelet published
  const auto g = waitFor<EvidentialGrid>("/prior_grid");
  ASSERT_TRUE(g != nullptr) << "no latched prior_grid";
  EXPECT_EQ(g->header.frame_id, "map");
  EXPECT_FLOAT_EQ(g->info.resolution, 0.5f);
  ASSERT_EQ(g->classes.size(), 5u);
  // cell_test: coverage adds the outline focal set W = {F, C}.
  ASSERT_EQ(g->focal_sets, (std::vector<std::uint8_t>{ kB, kR, kT, kOmega, kW }));
  const std::size_t n = static_cast<std::size_t>(g->info.width) * g->info.height;
  ASSERT_EQ(g->masses.size(), 5 * n);
  // The town (maps/README.md): about 310 m × 310 m at 0.5 m.
  EXPECT_GT(g->info.width, 600u);
  EXPECT_LT(g->info.width, 640u);
  EXPECT_NEAR(massAt(*g, kB, 40.0, 15.0), 0.9, 1e-6);   // the Cloister
  EXPECT_NEAR(massAt(*g, kT, 40.0, 40.0), 0.8, 1e-6);   // its courtyard
  EXPECT_NEAR(massAt(*g, kR, -80.0, 50.0), 0.9, 1e-6);  // West Avenue
  EXPECT_NEAR(massAt(*g, kOmega, -80.0, 50.0), 0.1, 1e-6);
  for (std::size_t i = 0; i < n; i += 97)
    EXPECT_NEAR(g->masses[i] + g->masses[n + i] + g->masses[2 * n + i] + g->masses[3 * n + i] + g->masses[4 * n + i],
                1.0, 1e-6);

  const auto occ = waitFor<nav_msgs::OccupancyGrid>("/prior_grid/occupancy");
  ASSERT_TRUE(occ != nullptr);
  EXPECT_EQ(occ->info.width, g->info.width);
  EXPECT_EQ(occ->data.size(), n);
  const auto outlines = waitFor<visualization_msgs::MarkerArray>("/prior_grid/outlines");
  ASSERT_TRUE(outlines != nullptr);
  EXPECT_EQ(outlines->markers.size(), 3u);  // buildings, road areas, road centre lines
}

TEST(PriorGridNodelet, ReloadSucceeds)
{
  ASSERT_TRUE(ros::service::waitForService("/prior_grid/reload", ros::Duration(kTimeout)));
  std_srvs::Trigger srv;
  ASSERT_TRUE(ros::service::call("/prior_grid/reload", srv));
  EXPECT_TRUE(srv.response.success) << srv.response.message;
  EXPECT_NE(srv.response.message.find("published"), std::string::npos) << srv.response.message;
}

TEST(PriorGridNodelet, BadMapIsReportedAndTheNodeletStaysAlive)
{
  ASSERT_TRUE(ros::service::waitForService("/bad/prior_grid/reload", ros::Duration(kTimeout)));
  std_srvs::Trigger srv;
  ASSERT_TRUE(ros::service::call("/bad/prior_grid/reload", srv));
  EXPECT_FALSE(srv.response.success);
  EXPECT_NE(srv.response.message.find("missing_map.osm"), std::string::npos) << srv.response.message;
  EXPECT_NE(srv.response.message.find("does not exist"), std::string::npos) << srv.response.message;
  // Nothing published, and the nodelet still answers.
  EXPECT_TRUE(waitFor<EvidentialGrid>("/bad/prior_grid", 1.0) == nullptr);
  ASSERT_TRUE(ros::service::call("/bad/prior_grid/reload", srv));
  EXPECT_FALSE(srv.response.success);
}

TEST(PriorGridNodelet, OutOfRangeParameterIsNamedAndTheNodeletStaysAlive)
{
  ASSERT_TRUE(ros::service::waitForService("/bad_param/prior_grid/reload", ros::Duration(kTimeout)));
  std_srvs::Trigger srv;
  ASSERT_TRUE(ros::service::call("/bad_param/prior_grid/reload", srv));
  EXPECT_FALSE(srv.response.success);
  EXPECT_NE(srv.response.message.find("beta_road"), std::string::npos) << srv.response.message;
  EXPECT_TRUE(waitFor<EvidentialGrid>("/bad_param/prior_grid", 1.0) == nullptr);
}

}  // namespace

int main(int argc, char** argv)
{
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_prior_grid_ros");
  ros::NodeHandle nh;
  ros::AsyncSpinner spinner(1);
  spinner.start();
  return RUN_ALL_TESTS();
}

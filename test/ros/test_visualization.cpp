// Markers of the fusion outputs, without a ROS master.
#include <gtest/gtest.h>

#include "map_aided_fusion/ros/param_loading.hpp"
#include "map_aided_fusion/ros/visualization.hpp"

using namespace map_aided_fusion;
using core::CellClass;

TEST(Visualization, PaperColours)
{
  const auto f = Visualization::classColour(CellClass::kFree);
  EXPECT_EQ(f.r + f.g + f.b, 3.0f);
  const auto c = Visualization::classColour(CellClass::kBuilding);
  EXPECT_EQ(c.b, 1.0f);
  EXPECT_EQ(c.r + c.g, 0.0f);
  const auto n = Visualization::classColour(CellClass::kInfrastructure);
  EXPECT_EQ(n.g + n.b, 2.0f);
  const auto s = Visualization::classColour(CellClass::kStopped);
  EXPECT_GT(s.g, 0.5f);
  EXPECT_EQ(s.r + s.b, 0.0f);
  const auto v = Visualization::classColour(CellClass::kMoving);
  EXPECT_EQ(v.r, 1.0f);
  EXPECT_EQ(v.g + v.b, 0.0f);
  EXPECT_EQ(Visualization::classColour(CellClass::kUnknown).a, 0.0f);
}

TEST(Visualization, OneCubeListPerClassWithACubePerCell)
{
  const core::GridGeometry g{ 0.5, 4, 2, 10.0, 20.0 };
  std::vector<std::int8_t> d = { 0, 1, 2, 3, 4, 4, -1, 0 };
  std_msgs::Header h;
  h.frame_id = "map";
  visualization_msgs::MarkerArray out;
  Visualization::decisionToCells(g, d, h, false, out);
  ASSERT_EQ(out.markers.size(), 5u);
  EXPECT_EQ(out.markers[0].ns, "cells/free");
  EXPECT_TRUE(out.markers[0].points.empty()) << "free cells drawn although include_free is false";
  EXPECT_EQ(out.markers[0].action, visualization_msgs::Marker::DELETE);
  EXPECT_EQ(out.markers[4].ns, "cells/moving");
  ASSERT_EQ(out.markers[4].points.size(), 2u);
  EXPECT_DOUBLE_EQ(out.markers[4].points[0].x, 10.25);
  EXPECT_DOUBLE_EQ(out.markers[4].points[0].y, 20.75);
  EXPECT_DOUBLE_EQ(out.markers[4].points[1].x, 10.75);
  EXPECT_DOUBLE_EQ(out.markers[4].scale.x, 0.5);
  Visualization::decisionToCells(g, d, h, true, out);
  EXPECT_EQ(out.markers[0].points.size(), 2u);
}

TEST(Visualization, ObjectsAreBoxesWithLabels)
{
  core::GridObject car;
  car.cell_class = CellClass::kMoving;
  car.centroid = core::Point2{ 3.0, 4.0 };
  car.yaw = M_PI / 2;
  car.length = 4.5;
  car.width = 2.0;
  car.mean_betp = 0.8;
  core::GridObject bus = car;
  bus.cell_class = CellClass::kStopped;
  bus.mean_betp = 0.645;
  std_msgs::Header h;
  h.frame_id = "map";
  visualization_msgs::MarkerArray out;
  Visualization::objectsToMarkers({ car, bus }, h, 1.5, out);
  ASSERT_EQ(out.markers.size(), 5u);
  EXPECT_EQ(out.markers[0].action, visualization_msgs::Marker::DELETEALL);
  const auto& box = out.markers[1];
  EXPECT_EQ(box.type, visualization_msgs::Marker::CUBE);
  EXPECT_DOUBLE_EQ(box.pose.position.x, 3.0);
  EXPECT_DOUBLE_EQ(box.scale.x, 4.5);
  EXPECT_NEAR(box.pose.orientation.z, std::sqrt(0.5), 1e-12);
  EXPECT_EQ(out.markers[2].type, visualization_msgs::Marker::TEXT_VIEW_FACING);
  EXPECT_EQ(out.markers[2].text, "moving, BetP 0.80, 4.5 x 2.0 m");
  EXPECT_EQ(out.markers[4].text, "stopped, BetP 0.65, 4.5 x 2.0 m");
  EXPECT_NE(out.markers[1].id, out.markers[3].id);
}

TEST(Visualization, TracksBecomeMessagesAndMarkersWithIdVelocityAndMotion)
{
  core::Track moving;
  moving.id = 12;
  moving.state = core::TrackState::kConfirmed;
  moving.motion = core::TrackMotion::kMoving;
  moving.x << 10.0, 5.0, 3.0, 4.0;
  moving.P = Eigen::Matrix4d::Identity() * 0.04;
  moving.extent_yaw = 0.5;
  moving.extent_length = 4.2;
  moving.extent_width = 1.8;
  moving.hits = 7;
  moving.first_stamp = 100.0;
  core::Track coasting = moving;
  coasting.id = 13;
  coasting.state = core::TrackState::kCoasting;
  coasting.motion = core::TrackMotion::kUnknown;
  core::Track tentative = moving;
  tentative.id = 14;
  tentative.state = core::TrackState::kTentative;
  std_msgs::Header h;
  h.frame_id = "map";
  h.stamp.fromSec(101.5);
  TrackedObjectArray msg;
  Visualization::tracksToMessage({ moving, coasting, tentative }, h, 101.5, 1.5, msg);
  ASSERT_EQ(msg.objects.size(), 2u);  // the tentative track is not reported
  const TrackedObject& o = msg.objects[0];
  EXPECT_EQ(o.id, 12u);
  EXPECT_EQ(o.cell_class, TrackedObject::MOVING);
  EXPECT_EQ(o.cell_class, static_cast<int>(CellClass::kMoving));
  EXPECT_EQ(o.state, TrackedObject::CONFIRMED);
  EXPECT_DOUBLE_EQ(o.velocity.x, 3.0);
  EXPECT_DOUBLE_EQ(o.velocity.y, 4.0);
  EXPECT_DOUBLE_EQ(o.velocity_covariance[0], 0.04);
  EXPECT_DOUBLE_EQ(o.velocity_covariance[1], 0.0);
  EXPECT_NEAR(o.speed_sigma, 0.2, 1e-12);
  EXPECT_DOUBLE_EQ(o.age, 1.5);
  EXPECT_DOUBLE_EQ(o.size.x, 4.2);
  EXPECT_NEAR(2.0 * std::atan2(o.pose.orientation.z, o.pose.orientation.w), 0.5, 1e-12);
  EXPECT_EQ(msg.objects[1].state, TrackedObject::COASTING);
  EXPECT_EQ(msg.objects[1].cell_class, TrackedObject::MOTION_UNKNOWN);
  EXPECT_EQ(msg.objects[1].cell_class, static_cast<int>(CellClass::kOccupied));

  // What the tracks report (core::reportedBoxes(), one per track): the pose and size come from it.
  const std::vector<core::ObjectBox> boxes{ { { 12.0, 6.0 }, 0.25, 4.0, 1.9 }, {}, {} };
  TrackedObjectArray reported;
  Visualization::tracksToMessage({ moving, coasting, tentative }, h, 101.5, 1.5, reported, boxes);
  ASSERT_EQ(reported.objects.size(), 2u);
  EXPECT_DOUBLE_EQ(reported.objects[0].pose.position.x, 12.0);
  EXPECT_DOUBLE_EQ(reported.objects[0].pose.position.y, 6.0);
  EXPECT_DOUBLE_EQ(reported.objects[0].size.x, 4.0);
  EXPECT_DOUBLE_EQ(reported.objects[0].size.y, 1.9);
  EXPECT_NEAR(2.0 * std::atan2(reported.objects[0].pose.orientation.z, reported.objects[0].pose.orientation.w), 0.25,
              1e-12);
  EXPECT_DOUBLE_EQ(reported.objects[0].velocity.x, 3.0) << "the velocity stays the track's";
  EXPECT_DOUBLE_EQ(o.pose.position.x, 10.0) << "without boxes: the track's position";

  visualization_msgs::MarkerArray markers;
  Visualization::tracksToMarkers(msg, markers);
  ASSERT_EQ(markers.markers.size(), 1u + 3u * 2u);
  EXPECT_EQ(markers.markers[0].action, visualization_msgs::Marker::DELETEALL);
  const auto& arrow = markers.markers[2];
  EXPECT_EQ(arrow.ns, "tracks/velocity");
  ASSERT_EQ(arrow.points.size(), 2u);
  EXPECT_DOUBLE_EQ(arrow.points[1].x - arrow.points[0].x, 3.0);  // one second ahead
  EXPECT_EQ(markers.markers[3].text, "#12 moving 5.0 m/s");
  EXPECT_EQ(markers.markers[1].id, 12);  // the marker keeps the track's id from scan to scan
  EXPECT_EQ(markers.markers[1].color.r, Visualization::classColour(CellClass::kMoving).r);
}

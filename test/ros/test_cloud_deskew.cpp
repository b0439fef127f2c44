// Deskewing of PointCloud2 sweeps with the motion from a tf buffer (no ROS master needed): the drivers' time
// fields, exact and extrapolated motion, and every reason a cloud is left as it is.
#include <gtest/gtest.h>

#include <cstring>
#include <limits>

#include <geometry_msgs/TransformStamped.h>
#include <sensor_msgs/PointField.h>

#include "map_aided_fusion/ros/cloud_deskew.hpp"
#include "map_aided_fusion/ros/point_cloud_view.hpp"
#include "cloud_helpers.hpp"

using namespace map_aided_fusion;
using sensor_msgs::PointField;

namespace {

constexpr double kStamp = 100.0;     // s
constexpr double kSpeed = 10.0;      // m/s along the map's x
constexpr double kWall = 20.0;       // m, x of a wall in the map frame

/// A Velodyne-style sweep (x y z float32, time float32 at 12) of a wall at x = kWall from a lidar moving at kSpeed:
/// point k taken at τ = k / 100 · 0.1 s.
sensor_msgs::PointCloud2 sweep(const std::string& time_name = "time", std::uint8_t time_type = PointField::FLOAT32)
{
  sensor_msgs::PointCloud2 c;
  c.header.frame_id = "lidar";
  c.header.stamp.fromSec(kStamp);
  c.fields = { test::floatField("x", 0), test::floatField("y", 4), test::floatField("z", 8),
               pointField(time_name, 12, time_type) };
  c.point_step = 16;
  c.width = 100;
  c.height = 1;
  c.row_step = c.width * c.point_step;
  c.data.assign(c.row_step, 0);
  for (std::uint32_t k = 0; k < c.width; ++k)
  {
    const float tau = 0.001f * static_cast<float>(k);
    const float p[4] = { static_cast<float>(kWall - kSpeed * tau), -5.0f + 0.1f * static_cast<float>(k), 0.0f, tau };
    std::memcpy(c.data.data() + k * c.point_step, p, sizeof p);
  }
  return c;
}

/// map → lidar at kSpeed along x, every 10 ms over [t0, t1].
void fillTf(tf2::BufferCore& tf, double t0, double t1)
{
  for (double t = t0; t <= t1 + 1e-9; t += 0.01)
  {
    geometry_msgs::TransformStamped m;
    m.header.frame_id = "map";
    m.header.stamp.fromSec(t);
    m.child_frame_id = "lidar";
    m.transform.translation.x = kSpeed * (t - kStamp);
    m.transform.rotation.w = 1.0;
    tf.setTransform(m, "test");
  }
}

float xAt(const core::PointCloudView& v, std::size_t k)
{
  float x;
  std::memcpy(&x, v.data + k * v.point_step + v.x_offset, sizeof x);
  return x;
}

}  // namespace

TEST(CloudDeskew, FindsTheDriversTimeFields)
{
  core::PointTimeField f;
  EXPECT_EQ(findTimeField(sweep(), "auto", f), "");
  EXPECT_EQ(f.name, "time");
  EXPECT_EQ(f.offset, 12u);
  EXPECT_EQ(findTimeField(sweep("t", PointField::UINT32), "auto", f), "");
  EXPECT_EQ(f.encoding, core::TimeEncoding::kUint32);
  EXPECT_DOUBLE_EQ(f.scale, 1e-9);
  EXPECT_EQ(findTimeField(sweep("offset_time", PointField::UINT32), "auto", f), "");
  EXPECT_EQ(findTimeField(sweep("timestamp", PointField::FLOAT64), "auto", f), "");
  EXPECT_TRUE(f.absolute);
  std::string detail;
  EXPECT_EQ(findTimeField(sweep("time", PointField::INT8), "auto", f, &detail), "time_field_type");
  EXPECT_NE(detail.find("datatype"), std::string::npos);
  EXPECT_EQ(findTimeField(sweep("stamp_ns", PointField::UINT32), "auto", f), "no_time_field");
  EXPECT_EQ(findTimeField(sweep(), "t", f), "no_time_field") << "only the named field";
}

TEST(CloudDeskew, MovesTheSweepToTheStampWithTheMotionFromTf)
{
  tf2::BufferCore tf(ros::Duration(100.0));
  fillTf(tf, kStamp - 1.0, kStamp + 1.0);
  const sensor_msgs::PointCloud2 c = sweep();
  core::PointCloudView raw, out;
  ASSERT_EQ(makePointCloudView(c, raw), CloudRejection::kNone);
  CloudDeskewer d;
  const DeskewResult r = d.apply(c, raw, true, "auto", 0.2, tf, "map", out);
  ASSERT_TRUE(r.applied) << r.status << " " << r.detail;
  EXPECT_EQ(r.status, "applied");
  EXPECT_NEAR(r.span, 0.099, 1e-6);
  EXPECT_GT(kWall - xAt(raw, 99), 0.9);
  for (std::size_t k = 0; k < 100; ++k) EXPECT_NEAR(xAt(out, k), kWall, 2e-3) << k;

  // tf ends at the stamp: the motion is extrapolated from the sweep before it.
  tf2::BufferCore past(ros::Duration(100.0));
  fillTf(past, kStamp - 1.0, kStamp);
  const DeskewResult e = d.apply(c, raw, true, "auto", 0.2, past, "map", out);
  ASSERT_TRUE(e.applied) << e.status << " " << e.detail;
  for (std::size_t k = 0; k < 100; ++k) EXPECT_NEAR(xAt(out, k), kWall, 2e-3) << k;

  // tf stops 50 ms before the stamp: the velocity of the latest interval.
  tf2::BufferCore late(ros::Duration(100.0));
  fillTf(late, kStamp - 1.0, kStamp - 0.05);
  const DeskewResult l = d.apply(c, raw, true, "auto", 0.2, late, "map", out);
  ASSERT_TRUE(l.applied) << l.status << " " << l.detail;
  for (std::size_t k = 0; k < 100; ++k) EXPECT_NEAR(xAt(out, k), kWall, 2e-3) << k;
}

TEST(CloudDeskew, CloudsLeftAsTheyAreSayWhy)
{
  tf2::BufferCore tf(ros::Duration(100.0));
  fillTf(tf, kStamp - 1.0, kStamp + 1.0);
  CloudDeskewer d;
  core::PointCloudView raw, out;
  const auto run = [&](const sensor_msgs::PointCloud2& c, bool enabled = true, const std::string& fixed = "map") {
    EXPECT_EQ(makePointCloudView(c, raw), CloudRejection::kNone);
    const DeskewResult r = d.apply(c, raw, enabled, "auto", 0.2, tf, fixed, out);
    EXPECT_FALSE(r.applied);
    EXPECT_EQ(out.data, raw.data) << "the cloud's own points are used";
    return r.status;
  };
  EXPECT_EQ(run(sweep(), false), "off");
  EXPECT_EQ(run(sweep("stamp_ns", PointField::UINT32)), "no_time_field");
  EXPECT_EQ(run(sweep("time", PointField::INT8)), "time_field_type");
  EXPECT_EQ(run(sweep(), true, "odom"), "no_motion");
  const auto withTime = [](std::size_t k, float t) {
    sensor_msgs::PointCloud2 c = sweep();
    std::memcpy(c.data.data() + k * c.point_step + 12, &t, sizeof t);
    return c;
  };
  EXPECT_EQ(run(withTime(7, std::numeric_limits<float>::quiet_NaN())), "time_non_finite");
  EXPECT_EQ(run(withTime(7, -0.05f)), "time_negative");
  EXPECT_EQ(run(withTime(7, 0.5f)), "time_out_of_sweep");
  sensor_msgs::PointCloud2 zeros = sweep();  // the field is there, every time 0: not "applied"
  for (std::uint32_t k = 0; k < zeros.width; ++k) std::memset(zeros.data.data() + k * zeros.point_step + 12, 0, 4);
  EXPECT_EQ(run(zeros), "time_field_constant");
}

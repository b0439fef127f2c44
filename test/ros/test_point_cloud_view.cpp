// makePointCloudView: which PointCloud2 messages are readable, and the view it makes (no ROS master needed).
#include <gtest/gtest.h>

#include <cstring>

#include <sensor_msgs/PointField.h>

#include "cloud_helpers.hpp"
#include "map_aided_fusion/ros/point_cloud_view.hpp"

using namespace map_aided_fusion;
using sensor_msgs::PointField;

namespace {

/// An unorganized cloud with fields intensity, x, y, z (x at offset 4) and 20-byte points.
sensor_msgs::PointCloud2 cloud(const std::vector<std::array<float, 3>>& pts)
{
  sensor_msgs::PointCloud2 c;
  c.header.frame_id = "lidar";
  c.fields = { test::floatField("intensity", 0), test::floatField("x", 4), test::floatField("y", 8),
               test::floatField("z", 12), pointField("ring", 16, PointField::UINT16) };
  c.point_step = 20;
  c.width = static_cast<std::uint32_t>(pts.size());
  c.height = 1;
  c.row_step = c.width * c.point_step;
  c.data.assign(c.row_step, 0);
  for (std::size_t i = 0; i < pts.size(); ++i) std::memcpy(c.data.data() + i * 20 + 4, pts[i].data(), 12);
  return c;
}

float readX(const core::PointCloudView& v, std::size_t row, std::size_t col)
{
  float x;
  std::memcpy(&x, v.data + row * v.row_step + col * v.point_step + v.x_offset, sizeof x);
  return x;
}

}  // namespace

TEST(PointCloudView, ReadsAnyFieldLayoutWithoutCopy)
{
  const auto c = cloud({ { 1.f, 2.f, 3.f }, { 4.f, 5.f, 6.f } });
  core::PointCloudView v;
  std::string detail = "stale";
  ASSERT_EQ(makePointCloudView(c, v, &detail), CloudRejection::kNone);
  EXPECT_TRUE(detail.empty());
  EXPECT_EQ(v.data, c.data.data());
  EXPECT_EQ(v.size(), 2u);
  EXPECT_EQ(v.point_step, 20u);
  EXPECT_EQ(v.x_offset, 4u);
  EXPECT_EQ(v.y_offset, 8u);
  EXPECT_EQ(v.z_offset, 12u);
  EXPECT_EQ(readX(v, 0, 1), 4.f);
  EXPECT_TRUE(v.consistent());
}

TEST(PointCloudView, OrganizedCloudWithRowPadding)
{
  auto c = cloud({ { 1.f, 0.f, 0.f }, { 2.f, 0.f, 0.f }, { 3.f, 0.f, 0.f }, { 4.f, 0.f, 0.f } });
  // Re-lay as 2 rows of 2 points with 8 padding bytes per row.
  sensor_msgs::PointCloud2 o = c;
  o.width = 2;
  o.height = 2;
  o.row_step = 2 * 20 + 8;
  o.data.assign(o.row_step * 2, 0xFF);
  for (int r = 0; r < 2; ++r) std::memcpy(o.data.data() + r * o.row_step, c.data.data() + r * 40, 40);
  core::PointCloudView v;
  ASSERT_EQ(makePointCloudView(o, v), CloudRejection::kNone);
  EXPECT_EQ(v.width, 2u);
  EXPECT_EQ(v.height, 2u);
  EXPECT_EQ(v.row_step, 48u);
  EXPECT_EQ(readX(v, 1, 1), 4.f);
  // The last row needs no padding: data of row_step + width * point_step bytes is enough.
  o.data.resize(48 + 40);
  EXPECT_EQ(makePointCloudView(o, v), CloudRejection::kNone);
  o.data.resize(48 + 39);
  EXPECT_EQ(makePointCloudView(o, v), CloudRejection::kShortData);
  o.data.resize(96);
  o.row_step = 39;
  EXPECT_EQ(makePointCloudView(o, v), CloudRejection::kLayout);
}

TEST(PointCloudView, EmptyCloudIsReadable)
{
  auto c = cloud({});
  core::PointCloudView v;
  ASSERT_EQ(makePointCloudView(c, v), CloudRejection::kNone);
  EXPECT_EQ(v.size(), 0u);
  EXPECT_TRUE(v.consistent());
}

TEST(PointCloudView, MalformedCloudsAreRejectedWithAReason)
{
  core::PointCloudView v;
  std::string detail;

  auto no_z = cloud({ { 1.f, 2.f, 3.f } });
  no_z.fields.erase(no_z.fields.begin() + 3);
  EXPECT_EQ(makePointCloudView(no_z, v, &detail), CloudRejection::kMissingField);
  EXPECT_NE(detail.find("'z'"), std::string::npos) << detail;
  EXPECT_STREQ(toString(CloudRejection::kMissingField), "missing_field");

  auto double_x = cloud({ { 1.f, 2.f, 3.f } });
  double_x.fields[1].datatype = PointField::FLOAT64;
  EXPECT_EQ(makePointCloudView(double_x, v, &detail), CloudRejection::kFieldType);
  auto counted_x = cloud({ { 1.f, 2.f, 3.f } });
  counted_x.fields[1].count = 3;
  EXPECT_EQ(makePointCloudView(counted_x, v, &detail), CloudRejection::kFieldType);

  auto outside = cloud({ { 1.f, 2.f, 3.f } });
  outside.fields[3].offset = 18;  // z would end at byte 22 of a 20-byte point
  EXPECT_EQ(makePointCloudView(outside, v, &detail), CloudRejection::kLayout);

  auto short_data = cloud({ { 1.f, 2.f, 3.f }, { 4.f, 5.f, 6.f } });
  short_data.data.resize(39);
  EXPECT_EQ(makePointCloudView(short_data, v, &detail), CloudRejection::kShortData);
  EXPECT_NE(detail.find("39"), std::string::npos) << detail;

  auto huge = cloud({ { 1.f, 2.f, 3.f } });
  huge.width = 0xFFFFFFFFu;
  huge.height = 0xFFFFFFFFu;
  huge.row_step = 0xFFFFFFFFu;
  EXPECT_NE(makePointCloudView(huge, v, &detail), CloudRejection::kNone);

  auto big_endian = cloud({ { 1.f, 2.f, 3.f } });
  big_endian.is_bigendian = true;
  EXPECT_EQ(makePointCloudView(big_endian, v, &detail), CloudRejection::kByteOrder);
}

TEST(PointCloudView, ViewFeedsTheScanGridBuilder)
{
  // An obstacle 10.25 m ahead through the message view gives the same grid as through a packed view.
  const auto c = cloud({ { 10.25f, 0.25f, 1.0f }, { 5.25f, -3.25f, 0.0f } });
  core::PointCloudView v;
  ASSERT_EQ(makePointCloudView(c, v), CloudRejection::kNone);
  core::ScanGridParams p;
  p.grid_size_x = p.grid_size_y = 40.0;
  core::ScanGridBuilder builder(p, Eigen::Isometry3d::Identity());
  core::ScanMassGrid grid;
  core::ScanGridStats st;
  ASSERT_TRUE(builder.build(v, grid, &st));
  EXPECT_EQ(st.obstacle, 1u);
  EXPECT_EQ(st.ground, 1u);
  const std::size_t i = grid.geometry().index(60, 40);
  EXPECT_FLOAT_EQ(grid.plane(core::FrameSG::kO)[i], 0.8f);
}

// libFuzzer target: bytes -> a sensor_msgs/PointCloud2 (fields, layout and data from the input) -> the
// PointCloud2 view -> ScanGridBuilder::build on a small grid. Built and run by scripts/fuzz.
#include <cstddef>
#include <cstdint>
#include <cstring>

#include <sensor_msgs/PointCloud2.h>

#include "fuzz_input.hpp"
#include "map_aided_fusion/core/scan_grid.hpp"
#include "map_aided_fusion/ros/point_cloud_view.hpp"

namespace {

using maf_fuzz::take;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  using namespace map_aided_fusion;
  static core::ScanGridBuilder builder = [] {
    core::ScanGridParams params;
    params.grid_size_x = params.grid_size_y = 40.0;
    params.max_range = 30.0;
    params.free_margin = 0.5;
    return core::ScanGridBuilder(params, Eigen::Isometry3d::Identity());
  }();
  static core::ScanMassGrid grid;
  const std::uint8_t* p = data;
  std::size_t n = size;
  sensor_msgs::PointCloud2 cloud;
  const std::uint8_t num_fields = take<std::uint8_t>(p, n) % 6;
  static const char* const kNames[] = { "x", "y", "z", "intensity", "t", "x" };
  for (std::uint8_t f = 0; f < num_fields; ++f)
  {
    sensor_msgs::PointField field;
    field.name = kNames[take<std::uint8_t>(p, n) % 6];
    field.offset = take<std::uint8_t>(p, n);
    field.datatype = take<std::uint8_t>(p, n) % 10;
    field.count = take<std::uint8_t>(p, n) % 3;
    cloud.fields.push_back(field);
  }
  cloud.is_bigendian = take<std::uint8_t>(p, n) & 1;
  cloud.point_step = take<std::uint8_t>(p, n);
  cloud.width = take<std::uint16_t>(p, n);
  cloud.height = take<std::uint8_t>(p, n) % 4;
  cloud.row_step = take<std::uint16_t>(p, n);
  const float tx = take<float>(p, n), ty = take<float>(p, n), tz = take<float>(p, n);
  cloud.data.assign(p, p + n);
  core::PointCloudView view;
  if (makePointCloudView(cloud, view, nullptr) != CloudRejection::kNone) return 0;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(tx, ty, tz);
  try
  {
    builder.setSensorPose(pose);
  }
  catch (const core::ParameterError&)
  {
    builder.setSensorPose(Eigen::Isometry3d::Identity());
  }
  core::ScanGridStats stats;
  builder.build(view, grid, &stats);
  return 0;
}

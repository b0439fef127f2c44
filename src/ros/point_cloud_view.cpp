#include "map_aided_fusion/ros/point_cloud_view.hpp"

#include <cstdint>

#include <sensor_msgs/PointField.h>

namespace map_aided_fusion {

namespace {

bool hostIsBigEndian()
{
  const std::uint16_t probe = 1;
  return *reinterpret_cast<const std::uint8_t*>(&probe) == 0;
}

CloudRejection fail(CloudRejection r, std::string* detail, const std::string& text)
{
  if (detail) *detail = text;
  return r;
}

}  // namespace

const char* toString(CloudRejection r)
{
  switch (r)
  {
    case CloudRejection::kNone: return "none";
    case CloudRejection::kMissingField: return "missing_field";
    case CloudRejection::kFieldType: return "field_type";
    case CloudRejection::kByteOrder: return "byte_order";
    case CloudRejection::kLayout: return "layout";
    case CloudRejection::kShortData: return "short_data";
  }
  return "unknown";
}

CloudRejection makePointCloudView(const sensor_msgs::PointCloud2& cloud, core::PointCloudView& view,
                                  std::string* detail)
{
  const char* const names[3] = { "x", "y", "z" };
  std::size_t offsets[3] = { 0, 0, 0 };
  for (int k = 0; k < 3; ++k)
  {
    const sensor_msgs::PointField* field = nullptr;
    for (const auto& f : cloud.fields)
      if (f.name == names[k]) field = &f;
    if (!field)
    {
      std::string have;
      for (const auto& f : cloud.fields) have += (have.empty() ? "" : ", ") + f.name;
      return fail(CloudRejection::kMissingField, detail,
                  std::string("no field '") + names[k] + "' (fields: [" + have + "])");
    }
    if (field->datatype != sensor_msgs::PointField::FLOAT32 || field->count != 1)
      return fail(CloudRejection::kFieldType, detail,
                  std::string("field '") + names[k] + "' has datatype " + std::to_string(field->datatype) +
                      " and count " + std::to_string(field->count) + ", expected FLOAT32 (7) and 1");
    offsets[k] = field->offset;
    if (std::size_t(field->offset) + sizeof(float) > cloud.point_step)
      return fail(CloudRejection::kLayout, detail,
                  std::string("field '") + names[k] + "' at offset " + std::to_string(field->offset) +
                      " does not fit in point_step " + std::to_string(cloud.point_step));
  }
  if (static_cast<bool>(cloud.is_bigendian) != hostIsBigEndian())
    return fail(CloudRejection::kByteOrder, detail, "is_bigendian differs from this machine's byte order");

  const std::uint64_t width = cloud.width, height = cloud.height;
  const std::uint64_t row_bytes = width * cloud.point_step;
  if (width > 0 && height > 0)
  {
    if (height > 1 && cloud.row_step < row_bytes)
      return fail(CloudRejection::kLayout, detail,
                  "row_step " + std::to_string(cloud.row_step) + " < width * point_step " + std::to_string(row_bytes));
    const std::uint64_t row_step = height > 1 ? cloud.row_step : row_bytes;
    const std::uint64_t needed = (height - 1) * row_step + row_bytes;
    if (cloud.data.size() < needed)
      return fail(CloudRejection::kShortData, detail,
                  "data has " + std::to_string(cloud.data.size()) + " bytes, " + std::to_string(width) + " x " +
                      std::to_string(height) + " points need " + std::to_string(needed));
  }

  view = core::PointCloudView{};
  view.data = cloud.data.empty() ? nullptr : cloud.data.data();
  view.width = width * height == 0 ? 0 : width;
  view.height = width * height == 0 ? 1 : height;
  view.point_step = cloud.point_step;
  view.row_step = height > 1 ? cloud.row_step : row_bytes;
  view.x_offset = offsets[0];
  view.y_offset = offsets[1];
  view.z_offset = offsets[2];
  if (detail) detail->clear();
  return CloudRejection::kNone;
}

}  // namespace map_aided_fusion

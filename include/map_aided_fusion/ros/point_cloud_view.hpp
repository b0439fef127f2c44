/**
 * @file point_cloud_view.hpp
 * @brief A core::PointCloudView on a sensor_msgs/PointCloud2 buffer (no copy), after checking that the
 *        message can be read safely: float32 x, y, z fields inside a point, native byte order, steps and
 *        data size consistent with width × height.
 */
#pragma once

#include <string>

#include <sensor_msgs/PointCloud2.h>

#include "map_aided_fusion/core/scan_grid.hpp"

namespace map_aided_fusion {

/// Why a cloud was refused.
enum class CloudRejection
{
  kNone,           ///< readable
  kMissingField,   ///< no x, y or z field
  kFieldType,      ///< x, y or z is not a single float32 inside a point
  kByteOrder,      ///< is_bigendian differs from this machine
  kLayout,         ///< point_step or row_step too small for the fields or the row
  kShortData,      ///< data shorter than the layout needs
};

/// Short name of a rejection for logs and diagnostics ("missing_field", …).
const char* toString(CloudRejection r);

/**
 * @brief Points @p view at the x, y, z of @p cloud (which must outlive the view).
 * @return kNone on success; otherwise the reason, with details in @p detail when given.
 */
CloudRejection makePointCloudView(const sensor_msgs::PointCloud2& cloud, core::PointCloudView& view,
                                  std::string* detail = nullptr);

}  // namespace map_aided_fusion

/**
 * @file return_class.hpp
 * @brief What the ScanGrid's sensor model makes of one lidar return (core/scan_grid.hpp), ROS-free.
 */
#pragma once

#include <cstdint>

namespace map_aided_fusion {
namespace core {

/// What the sensor model made of one point of a build() (ScanGridBuilder::returnClasses()).
enum class ReturnClass : std::uint8_t
{
  kRejected = 0,        ///< invalid: non-finite, no return, outside [min_range, max_range], the vehicle's body
  kGround = 1,          ///< ground return: evidence of free space
  kObstacle = 2,        ///< obstacle return: an occupied cell
  kBelowGround = 3,     ///< below the ground band (neither)
  kHeightGap = 4,       ///< between the ground band and the obstacle band (neither)
  kAboveClearance = 5,  ///< above obstacle_max_height (neither)
  kLowRelief = 6,       ///< in the obstacle band, too close to the local lowest return (neither)
  kDisputed = 7,        ///< ground for one ground model, obstacle for the other (step ground consensus): neither
};

}  // namespace core
}  // namespace map_aided_fusion

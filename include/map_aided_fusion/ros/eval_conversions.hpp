/**
 * @file eval_conversions.hpp
 * @brief Ground-truth and decision messages → the evaluation's ROS-free types (eval/metrics.hpp).
 */
#pragma once

#include <stdexcept>
#include <vector>

#include <nav_msgs/OccupancyGrid.h>
#include <tf2/utils.h>

#include "map_aided_fusion/GroundTruthObjectArray.h"
#include "map_aided_fusion/eval/metrics.hpp"

namespace map_aided_fusion {

/// A class-coded OccupancyGrid (`decision`, `/ground_truth/classes`) → eval::ClassGrid.
/// @throws std::runtime_error when data does not hold width × height cells.
inline eval::ClassGrid toClassGrid(const nav_msgs::OccupancyGrid& g)
{
  eval::ClassGrid c;
  c.geometry = core::GridGeometry{ g.info.resolution, static_cast<int>(g.info.width), static_cast<int>(g.info.height),
                                   g.info.origin.position.x, g.info.origin.position.y };
  c.cells = g.data;
  if (c.cells.size() != c.geometry.numCells()) throw std::runtime_error("class grid with a wrong data size");
  return c;
}

/// `/ground_truth/objects` → eval::TruthObject list.
inline std::vector<eval::TruthObject> toTruthObjects(const GroundTruthObjectArray& a)
{
  std::vector<eval::TruthObject> out;
  out.reserve(a.objects.size());
  for (const auto& o : a.objects)
  {
    eval::TruthObject t;
    t.id = o.id;
    t.cell_class = static_cast<core::CellClass>(o.cell_class);
    t.kind = o.kind;
    t.centre = core::Point2{ o.pose.position.x, o.pose.position.y };
    t.yaw = tf2::getYaw(o.pose.orientation);
    t.length = o.size.x;
    t.width = o.size.y;
    t.speed = std::hypot(o.velocity.x, o.velocity.y);
    t.vx = o.velocity.x;
    t.vy = o.velocity.y;
    t.z = o.pose.position.z;
    t.height = o.size.z;
    out.push_back(t);
  }
  return out;
}

}  // namespace map_aided_fusion

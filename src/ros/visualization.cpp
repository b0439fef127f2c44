#include "map_aided_fusion/ros/visualization.hpp"

#include <cmath>
#include <cstdio>
#include <string>

namespace map_aided_fusion {

using core::CellClass;

namespace {

constexpr float kCellHeight = 0.1f;
constexpr float kLabelSize = 0.8f;
constexpr double kLabelLift = 1.0;

std_msgs::ColorRGBA rgba(float r, float g, float b, float a)
{
  std_msgs::ColorRGBA c;
  c.r = r;
  c.g = g;
  c.b = b;
  c.a = a;
  return c;
}

}  // namespace

std_msgs::ColorRGBA Visualization::classColour(CellClass c)
{
  switch (c)
  {
    case CellClass::kFree:
      return rgba(1.0f, 1.0f, 1.0f, 1.0f);
    case CellClass::kBuilding:
      return rgba(0.0f, 0.0f, 1.0f, 1.0f);
    case CellClass::kInfrastructure:
      return rgba(0.0f, 1.0f, 1.0f, 1.0f);
    case CellClass::kStopped:
      return rgba(0.0f, 0.8f, 0.0f, 1.0f);
    case CellClass::kMoving:
      return rgba(1.0f, 0.0f, 0.0f, 1.0f);
    case CellClass::kOccupied:
      return rgba(1.0f, 0.6f, 0.0f, 1.0f);
    case CellClass::kUnknown:
      break;
  }
  return rgba(0.5f, 0.5f, 0.5f, 0.0f);
}

void Visualization::decisionToCells(const core::GridGeometry& g, const std::vector<std::int8_t>& decision,
                                    const std_msgs::Header& header, bool include_free,
                                    visualization_msgs::MarkerArray& out)
{
  out.markers.clear();
  for (int k = 0; k < core::kNumCellClasses; ++k)
  {
    const auto cls = static_cast<CellClass>(k);
    visualization_msgs::Marker m;
    m.header = header;
    m.ns = "cells/" + std::string(core::kCellClassLongNames[k]);
    m.id = k;
    m.type = visualization_msgs::Marker::CUBE_LIST;
    m.action = visualization_msgs::Marker::ADD;
    m.pose.orientation.w = 1.0;
    m.scale.x = m.scale.y = g.resolution;
    m.scale.z = kCellHeight;
    m.color = classColour(cls);
    if (cls != CellClass::kFree || include_free)
      for (std::size_t i = 0; i < decision.size(); ++i)
      {
        if (decision[i] != k) continue;
        const core::Point2 p = g.cellCentre(g.cellOf(i));
        geometry_msgs::Point q;
        q.x = p.x;
        q.y = p.y;
        q.z = 0.0;
        m.points.push_back(q);
      }
    if (m.points.empty()) m.action = visualization_msgs::Marker::DELETE;
    out.markers.push_back(m);
  }
}

void Visualization::objectsToMarkers(const std::vector<core::GridObject>& objects, const std_msgs::Header& header,
                                     double box_height, visualization_msgs::MarkerArray& out)
{
  out.markers.clear();
  visualization_msgs::Marker clear;
  clear.header = header;
  clear.action = visualization_msgs::Marker::DELETEALL;
  out.markers.push_back(clear);
  int id = 0;
  for (const auto& o : objects)
  {
    visualization_msgs::Marker box;
    box.header = header;
    box.ns = "objects/box";
    box.id = id;
    box.type = visualization_msgs::Marker::CUBE;
    box.action = visualization_msgs::Marker::ADD;
    box.pose.position.x = o.centroid.x;
    box.pose.position.y = o.centroid.y;
    box.pose.position.z = 0.5 * box_height;
    box.pose.orientation.z = std::sin(0.5 * o.yaw);
    box.pose.orientation.w = std::cos(0.5 * o.yaw);
    box.scale.x = o.length;
    box.scale.y = o.width;
    box.scale.z = box_height;
    box.color = classColour(o.cell_class);
    box.color.a = 0.5f;
    out.markers.push_back(box);

    visualization_msgs::Marker label = box;
    label.ns = "objects/label";
    label.type = visualization_msgs::Marker::TEXT_VIEW_FACING;
    label.pose.position.z = box_height + kLabelLift;
    label.pose.orientation.z = 0.0;
    label.pose.orientation.w = 1.0;
    label.scale.x = label.scale.y = 0.0;
    label.scale.z = kLabelSize;
    label.color.a = 1.0f;
    char text[64];
    std::snprintf(text, sizeof text, "%s %.2f", o.cell_class == CellClass::kMoving ? "moving" : "stopped", o.mean_betp);
    label.text = text;
    out.markers.push_back(label);
    ++id;
  }
}

}  // namespace map_aided_fusion

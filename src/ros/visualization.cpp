#include "map_aided_fusion/ros/visualization.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace map_aided_fusion {

using core::CellClass;

namespace {

constexpr float kCellHeight = 0.1f;
constexpr float kLabelSize = 1.5f;  // m: readable at the default rviz zoom
constexpr double kLabelLift = 1.0;
constexpr double kMinTrackBox = 0.3;     // m, the smallest drawn side of a track's box
constexpr double kArrowShaft = 0.15;     // m
constexpr double kArrowHead = 0.4;       // m
constexpr double kTrackLabelSize = 1.5;  // m: readable from a car's length away at the default rviz zoom

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
    char text[96];
    std::snprintf(text, sizeof text, "%s, BetP %.2f, %.1f x %.1f m",
                  o.cell_class == CellClass::kMoving ? "moving" : "stopped", o.mean_betp, o.length, o.width);
    label.text = text;
    out.markers.push_back(label);
    ++id;
  }
}

void Visualization::tracksToMessage(const std::vector<core::Track>& tracks, const std_msgs::Header& header, double now,
                                    double box_height, TrackedObjectArray& out, const std::vector<core::ObjectBox>& boxes)
{
  out.header = header;
  out.objects.clear();
  for (std::size_t i = 0; i < tracks.size(); ++i)
  {
    const core::Track& t = tracks[i];
    if (!t.published()) continue;
    const core::ObjectBox b = boxes.size() == tracks.size() ? boxes[i] : core::ownBox(t);
    TrackedObject o;
    o.id = t.id;
    o.cell_class = t.motion == core::TrackMotion::kMoving    ? TrackedObject::MOVING
                   : t.motion == core::TrackMotion::kStopped ? TrackedObject::STOPPED
                                                             : TrackedObject::MOTION_UNKNOWN;
    o.state = t.state == core::TrackState::kCoasting ? TrackedObject::COASTING : TrackedObject::CONFIRMED;
    o.pose.position.x = b.centre.x;
    o.pose.position.y = b.centre.y;
    o.pose.position.z = 0.5 * box_height;
    o.pose.orientation.z = std::sin(0.5 * b.yaw);
    o.pose.orientation.w = std::cos(0.5 * b.yaw);
    o.size.x = b.length;
    o.size.y = b.width;
    o.size.z = box_height;
    o.velocity.x = t.x(2);
    o.velocity.y = t.x(3);
    const Eigen::Matrix2d pv = t.P.bottomRightCorner<2, 2>();
    o.velocity_covariance = { pv(0, 0), pv(0, 1), pv(1, 0), pv(1, 1) };
    o.speed_sigma = t.speedSigma();
    o.age = t.age(now);
    o.hits = static_cast<std::uint32_t>(t.hits);
    out.objects.push_back(o);
  }
}

void Visualization::tracksToMarkers(const TrackedObjectArray& tracks, visualization_msgs::MarkerArray& out)
{
  out.markers.clear();
  visualization_msgs::Marker clear;
  clear.header = tracks.header;
  clear.action = visualization_msgs::Marker::DELETEALL;
  out.markers.push_back(clear);
  // One marker of each kind per track, its id the track's: rviz keeps it in place from scan to scan.
  auto marker = [&](const char* ns, const TrackedObject& o, int type) {
    visualization_msgs::Marker m;
    m.header = tracks.header;
    m.ns = ns;
    m.id = static_cast<int>(o.id);
    m.type = type;
    m.action = visualization_msgs::Marker::ADD;
    m.pose.orientation.w = 1.0;
    return m;
  };
  for (const TrackedObject& o : tracks.objects)
  {
    const auto cls = static_cast<CellClass>(o.cell_class);
    visualization_msgs::Marker box = marker("tracks/box", o, visualization_msgs::Marker::CUBE);
    box.pose = o.pose;
    box.scale.x = std::max(o.size.x, kMinTrackBox);
    box.scale.y = std::max(o.size.y, kMinTrackBox);
    box.scale.z = o.size.z;
    box.color = classColour(cls);
    box.color.a = o.state == TrackedObject::COASTING ? 0.25f : 0.6f;
    out.markers.push_back(box);

    visualization_msgs::Marker arrow = marker("tracks/velocity", o, visualization_msgs::Marker::ARROW);
    geometry_msgs::Point a, b;
    a.x = o.pose.position.x;
    a.y = o.pose.position.y;
    a.z = o.size.z;
    b = a;
    b.x += o.velocity.x;  // where it will be in one second
    b.y += o.velocity.y;
    arrow.points = { a, b };
    arrow.scale.x = kArrowShaft;
    arrow.scale.y = kArrowHead;
    arrow.scale.z = kArrowHead;
    arrow.color = box.color;
    arrow.color.a = 1.0f;
    out.markers.push_back(arrow);

    visualization_msgs::Marker label = marker("tracks/label", o, visualization_msgs::Marker::TEXT_VIEW_FACING);
    label.pose.position = o.pose.position;
    label.pose.position.z = o.size.z + kLabelLift;
    label.scale.z = kTrackLabelSize;
    label.color = box.color;
    label.color.a = 1.0f;
    char text[96];
    std::snprintf(text, sizeof text, "#%u %s %.1f m/s", o.id,
                  cls == CellClass::kMoving    ? "moving"
                  : cls == CellClass::kStopped ? "stopped"
                                               : "motion unknown",
                  std::hypot(o.velocity.x, o.velocity.y));
    label.text = text;
    out.markers.push_back(label);
  }
}

}  // namespace map_aided_fusion

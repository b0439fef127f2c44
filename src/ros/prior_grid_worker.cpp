#include "map_aided_fusion/ros/prior_grid_worker.hpp"

#ifdef __GLIBC__
#include <malloc.h>
#endif

#include <algorithm>
#include <utility>
#include <vector>

#include <geometry_msgs/Point.h>
#include <nav_msgs/OccupancyGrid.h>
#include <visualization_msgs/MarkerArray.h>

#include "map_aided_fusion/EvidentialGrid.h"
#include "map_aided_fusion/core/parameters.hpp"
#include "map_aided_fusion/core/prior_uncertainty.hpp"
#include "map_aided_fusion/ros/conversions.hpp"
#include "map_aided_fusion/ros/param_loading.hpp"

namespace map_aided_fusion {

namespace {

constexpr std::size_t kMaxLoggedSkips = 10;
constexpr double kOutlineWidth = 0.2;  // metres
constexpr int kQueueSize = 1;
constexpr double kDiagnosticPeriod = 1.0;  // s, wall time
constexpr double kVehicleCheckPeriod = 1.0;  // s, wall time, between looks at where the vehicle is

struct Rgba
{
  float r, g, b, a;
};
constexpr Rgba kBuildingColour{ 0.0f, 0.0f, 1.0f, 1.0f };
constexpr Rgba kRoadAreaColour{ 1.0f, 1.0f, 1.0f, 1.0f };
constexpr Rgba kRoadLineColour{ 0.8f, 0.8f, 0.8f, 1.0f };

bool inside(const core::GridGeometry& g, const core::Point2& p)
{
  return p.x >= g.origin_x && p.y >= g.origin_y && p.x <= g.origin_x + g.sizeX() && p.y <= g.origin_y + g.sizeY();
}

bool touches(const core::GridGeometry& g, const std::vector<core::Point2>& pts)
{
  return std::any_of(pts.begin(), pts.end(), [&](const core::Point2& p) { return inside(g, p); });
}

geometry_msgs::Point point(const core::Point2& p)
{
  geometry_msgs::Point q;
  q.x = p.x;
  q.y = p.y;
  q.z = 0.0;
  return q;
}

void addRing(const std::vector<core::Point2>& ring, bool closed, visualization_msgs::Marker& m)
{
  const std::size_t n = ring.size();
  if (n < 2) return;
  const std::size_t edges = closed ? n : n - 1;
  for (std::size_t i = 0; i < edges; ++i)
  {
    m.points.push_back(point(ring[i]));
    m.points.push_back(point(ring[(i + 1) % n]));
  }
}

visualization_msgs::Marker lineList(const std_msgs::Header& header, const std::string& ns, int id, Rgba c)
{
  visualization_msgs::Marker m;
  m.header = header;
  m.ns = ns;
  m.id = id;
  m.type = visualization_msgs::Marker::LINE_LIST;
  m.action = visualization_msgs::Marker::ADD;
  m.pose.orientation.w = 1.0;
  m.scale.x = kOutlineWidth;
  m.color.r = c.r;
  m.color.g = c.g;
  m.color.b = c.b;
  m.color.a = c.a;
  return m;
}

}  // namespace

map_io::PriorGridParams readPriorGridParams(const ros::NodeHandle& pnh)
{
  map_io::PriorGridParams p;
  map_io::forEachPriorGridParam(p, parameterServerReader(pnh));
  return p;
}

PriorGridWorker::PriorGridWorker(ros::NodeHandle nh, ros::NodeHandle pnh) : nh_(nh), pnh_(pnh)
{
  const bool latched = true;
  prior_pub_ = nh_.advertise<EvidentialGrid>("prior_grid", kQueueSize, latched);
  occupancy_pub_ = nh_.advertise<nav_msgs::OccupancyGrid>("prior_grid/occupancy", kQueueSize, latched);
  outlines_pub_ = nh_.advertise<visualization_msgs::MarkerArray>("prior_grid/outlines", kQueueSize, latched);
  reload_srv_ = pnh_.advertiseService("reload", &PriorGridWorker::reload, this);
  diagnostics_ = std::make_unique<diagnostic_updater::Updater>(nh_, pnh_, pnh_.getNamespace());
  diagnostics_->setHardwareID("map_loader");
  diagnostics_->add("PriorGrid", this, &PriorGridWorker::diagnose);
  tf_listener_ = std::make_unique<tf2_ros::TransformListener>(tf_buffer_, nh_);
  load();
  diagnostics_->force_update();
  vehicle_timer_ = nh_.createWallTimer(ros::WallDuration(kVehicleCheckPeriod),
                                       [this](const ros::WallTimerEvent&) { checkVehicle(); });
  diagnostics_timer_ = nh_.createWallTimer(ros::WallDuration(kDiagnosticPeriod),
                                           [this](const ros::WallTimerEvent&) { diagnostics_->force_update(); });
}

void PriorGridWorker::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status)
{
  std::lock_guard<std::mutex> lock(mutex_);
  if (loaded_ && vehicle_far_)
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                   "the vehicle is " + std::to_string(static_cast<long>(vehicle_distance_)) +
                       " m from the nearest map data (max_vehicle_distance " +
                       std::to_string(static_cast<long>(params_.max_vehicle_distance)) +
                       " m): the prior does not cover it; wrong map, origin or frame?");
  else if (loaded_)
    status.summary(report_.skipped_geometries > 0 ? diagnostic_msgs::DiagnosticStatus::WARN :
                                                    diagnostic_msgs::DiagnosticStatus::OK,
                   report_.skipped_geometries > 0 ? "published; some geometries skipped (see the counts)" :
                                                    "published");
  else
    status.summary(diagnostic_msgs::DiagnosticStatus::ERROR, "nothing published: " + status_);
  status.add("file", report_.file);
  status.add("vehicle distance to the map data [m]", vehicle_distance_);
  status.add("driver", report_.driver);
  status.add("loads", loads_);
  status.add("last load", status_);
  status.add("origin latitude [deg]", report_.origin_latitude);
  status.add("origin longitude [deg]", report_.origin_longitude);
  status.add("origin altitude [m]", report_.origin_altitude);
  status.add("features read", report_.features_read);
  status.add("buildings kept", report_.buildings);
  status.add("road areas kept", report_.road_areas);
  status.add("road lines kept", report_.road_lines);
  status.add("geometries repaired", report_.repaired_geometries);
  status.add("holes dropped (outside or around their shell)", report_.dropped_holes);
  status.add("geometries skipped", report_.skipped_geometries);
  status.add("skipped: unclosed", report_.skipped_unclosed);
  status.add("skipped: missing nodes", report_.skipped_missing_nodes);
  status.add("skipped: incomplete relations", report_.skipped_incomplete_relations);
  status.add("skipped: degenerate or out of range coordinates", report_.skipped_degenerate);
  status.add("skipped: invalid", report_.skipped_invalid);
  status.add("skipped: too many vertices", report_.skipped_too_many_vertices);
  status.add("skipped: farther than max_origin_distance", report_.skipped_out_of_range);
  status.add("grid [cells]", std::to_string(published_.width) + " x " + std::to_string(published_.height));
  status.add("grid resolution [m]", published_.resolution);
  status.add("grid origin [m]", std::to_string(published_.origin_x) + ", " + std::to_string(published_.origin_y));
}

bool PriorGridWorker::reload(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res)
{
  res.success = load();
  res.message = status_;
  return true;
}

bool PriorGridWorker::load()
{
  std::lock_guard<std::mutex> lock(mutex_);
  try
  {
    map_io::PriorGridParams params = readPriorGridParams(pnh_);
    refuseUnknownParams(pnh_);
    params.validate();
    ++loads_;
    report_ = map_io::MapLoadReport{};
    report_.file = params.map.file;  // shown even when the load fails early
    core::VectorMap map = map_io::loadVectorMap(params.map, &report_);
    ROS_INFO_STREAM("prior_grid: " << map_io::summary(report_));
    for (std::size_t i = 0; i < std::min(kMaxLoggedSkips, report_.messages.size()); ++i)
      ROS_WARN_STREAM("prior_grid: skipped " << report_.messages[i]);
    publish(params, map);
    loaded_ = true;
    map_ = std::move(map);  // kept for the vehicle's distance to the data
    params_ = params;
    vehicle_far_ = false;
  }
  catch (const core::ParameterError& e)
  {
    status_ = std::string("invalid parameter ") + e.what();
    loaded_ = false;
  }
  catch (const std::exception& e)
  {
    status_ = e.what();
    loaded_ = false;
  }
  if (!loaded_) ROS_ERROR_STREAM("prior_grid: " << status_ << "; nothing published");
#ifdef __GLIBC__
  malloc_trim(0);  // the vector map and the previous grid are freed: give the pages back (a huge map, then a small one)
#endif
  return loaded_;
}

void PriorGridWorker::checkVehicle()
{
  std::lock_guard<std::mutex> lock(mutex_);
  if (!loaded_ || params_.max_vehicle_distance <= 0.0) return;
  geometry_msgs::TransformStamped t;
  try
  {
    t = tf_buffer_.lookupTransform(params_.frame_id, params_.vehicle_frame, ros::Time(0));
  }
  catch (const tf2::TransformException&)
  {
    return;  // no localisation yet: nothing to say
  }
  const core::Point2 at{ t.transform.translation.x, t.transform.translation.y };
  vehicle_distance_ = core::distanceToMapData(map_, at);
  const bool far = vehicle_distance_ > params_.max_vehicle_distance;
  if (far && !vehicle_far_)
    ROS_WARN("prior_grid: the vehicle (%s at %.0f, %.0f in %s) is %.0f m from the nearest data of %s "
             "(max_vehicle_distance %.0f m): the prior does not cover it. Wrong map, origin (origin_latitude, "
             "origin_longitude) or frame?",
             params_.vehicle_frame.c_str(), at.x, at.y, params_.frame_id.c_str(), vehicle_distance_,
             report_.file.c_str(), params_.max_vehicle_distance);
  else if (!far && vehicle_far_)
    ROS_INFO("prior_grid: the vehicle is within %.0f m of the map's data again", params_.max_vehicle_distance);
  vehicle_far_ = far;
}

void PriorGridWorker::publish(const map_io::PriorGridParams& params, const core::VectorMap& map)
{
  const core::GridGeometry extent = core::PriorGrid::extentOf(map, params.resolution, params.margin);
  bool cropped = false;
  const core::GridGeometry window = map_io::publishedWindow(extent, params, cropped);
  if (cropped)
    ROS_WARN_STREAM("prior_grid: the map's extent (" << extent.sizeX() << " m x " << extent.sizeY() << " m) exceeds "
                    << "max_published_cells = " << params.max_published_cells << "; publishing " << window.sizeX()
                    << " m x " << window.sizeY() << " m around (" << params.publish_centre_x << ", "
                    << params.publish_centre_y << ")");
  core::PriorBuildStats stats;
  grid_.build(map, window, &stats, params.options.cell_test);
  published_ = window;
  const core::PriorClassCounts n = grid_.classCounts();
  status_ = "published " + std::to_string(window.width) + " x " + std::to_string(window.height) + " cells: " +
            std::to_string(n[static_cast<int>(core::PriorClass::kBuilding)]) + " building, " +
            std::to_string(n[static_cast<int>(core::PriorClass::kRoad)]) + " road, " +
            std::to_string(n[static_cast<int>(core::PriorClass::kOther)]) + " other; " +
            std::to_string(stats.buildings_rasterised) + " buildings rasterised, " +
            std::to_string(stats.outline_cells) + " outline cells (cell_test " + core::toString(params.options.cell_test) +
            "), " +
            std::to_string(map.skipped_geometries + stats.skipped_invalid) + " geometries skipped";
  ROS_INFO_STREAM("prior_grid: " << status_);

  std_msgs::Header header;
  header.stamp = ros::Time::now();
  header.frame_id = params.frame_id;

  core::PriorWindow prior;
  core::mapPrior(grid_, window, params.beta, params.options, prior);
  EvidentialGrid msg;
  GridConversions::toMessage(prior, header, msg);
  prior_pub_.publish(msg);

  nav_msgs::OccupancyGrid occ;
  occ.header = header;
  GridConversions::toMapMetaData(window, occ.info);
  occ.info.map_load_time = header.stamp;
  occ.data.resize(window.numCells());
  const auto& labels = grid_.labels();
  for (std::size_t i = 0; i < labels.size(); ++i)
  {
    switch (labels[i])
    {
      case core::PriorClass::kBuilding: occ.data[i] = kPriorOccupancyBuilding; break;
      case core::PriorClass::kRoad: occ.data[i] = kPriorOccupancyRoad; break;
      case core::PriorClass::kOther: occ.data[i] = kPriorOccupancyOther; break;
      case core::PriorClass::kUnknown: occ.data[i] = kPriorOccupancyUnknown; break;
    }
  }
  occupancy_pub_.publish(occ);

  if (!params.publish_outlines) return;
  visualization_msgs::MarkerArray outlines;
  visualization_msgs::Marker buildings = lineList(header, "buildings", 0, kBuildingColour);
  visualization_msgs::Marker areas = lineList(header, "road_areas", 1, kRoadAreaColour);
  visualization_msgs::Marker lines = lineList(header, "road_lines", 2, kRoadLineColour);
  for (const auto& b : map.buildings)
  {
    if (!touches(window, b.footprint.outer)) continue;
    addRing(b.footprint.outer, true, buildings);
    for (const auto& h : b.footprint.holes) addRing(h, true, buildings);
  }
  for (const auto& a : map.road_areas)
  {
    if (!touches(window, a.outer)) continue;
    addRing(a.outer, true, areas);
    for (const auto& h : a.holes) addRing(h, true, areas);
  }
  for (const auto& l : map.road_lines)
    if (touches(window, l.points)) addRing(l.points, false, lines);
  for (auto* m : { &buildings, &areas, &lines })
    if (!m->points.empty()) outlines.markers.push_back(*m);
  outlines_pub_.publish(outlines);
}

}  // namespace map_aided_fusion

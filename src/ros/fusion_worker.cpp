#include "map_aided_fusion/ros/fusion_worker.hpp"

#include <chrono>

#include <nav_msgs/OccupancyGrid.h>
#include <tf2/utils.h>
#include <visualization_msgs/MarkerArray.h>

#include "map_aided_fusion/ros/conversions.hpp"
#include "map_aided_fusion/ros/param_loading.hpp"
#include "map_aided_fusion/ros/visualization.hpp"

namespace map_aided_fusion {

namespace {

constexpr int kQueueSize = 5;
constexpr double kDiagnosticsPeriod = 1.0;
/// Scans whose stamp goes back by more than this reset the grid.
const ros::Duration kBackwardTolerance(0.001);
constexpr const char* kBetpTopics[core::FrameMG::kSize] = { "betp/free", "betp/building", "betp/infrastructure",
                                                             "betp/stopped", "betp/moving" };

std::string reasonName(tf2_ros::FilterFailureReason r)
{
  switch (r)
  {
    case tf2_ros::filter_failure_reasons::OutTheBack:
      return "the transform is older than the tf buffer";
    case tf2_ros::filter_failure_reasons::EmptyFrameID:
      return "the scan has an empty frame_id";
    default:
      break;
  }
  return "no transform arrived in time";
}

}  // namespace

FusionWorker::FusionWorker(ros::NodeHandle nh, ros::NodeHandle pnh)
  : nh_(nh)
  , pnh_(pnh)
  , grid_(loadMapGridParams(pnh))
  , tf_listener_(tf_buffer_, nh)
  , reconfigure_(pnh)
{
  pnh_.param<std::string>("map_frame", map_frame_, "map");
  pnh_.param<std::string>("base_frame", base_frame_, "base_link");
  pnh_.param("publish_free_cells", publish_free_cells_, false);
  readParam(pnh_, "object_box_height", object_box_height_);
  int queue_size = kQueueSize;
  readParam(pnh_, "tf_queue_size", queue_size);
  core::requireInRange("tf_queue_size", queue_size, 1, 1000);

  map_grid_pub_ = nh_.advertise<EvidentialGrid>("map_grid", 1);
  for (int e = 0; e < core::FrameMG::kSize; ++e) betp_pub_[e] = nh_.advertise<nav_msgs::OccupancyGrid>(kBetpTopics[e], 1);
  decision_pub_ = nh_.advertise<nav_msgs::OccupancyGrid>("decision", 1);
  cells_pub_ = nh_.advertise<visualization_msgs::MarkerArray>("cells", 1);
  objects_pub_ = nh_.advertise<visualization_msgs::MarkerArray>("objects", 1);

  prior_sub_ = nh_.subscribe("prior_grid", 1, &FusionWorker::onPrior, this);
  scan_sub_.subscribe(nh_, "scan_grid", static_cast<uint32_t>(queue_size));
  scan_filter_ = std::make_unique<tf2_ros::MessageFilter<EvidentialGrid>>(
      scan_sub_, tf_buffer_, map_frame_, static_cast<uint32_t>(queue_size), nh_);
  scan_filter_->registerCallback(&FusionWorker::onScan, this);
  scan_filter_->registerFailureCallback(
      [this](const EvidentialGrid::ConstPtr& msg, tf2_ros::FilterFailureReason reason) { onScanDropped(msg, reason); });

  reconfigure_.setCallback([this](FusionConfig& config, uint32_t level) { onReconfigure(config, level); });

  diagnostics_.setHardwareID("map_aided_fusion");
  diagnostics_.add("fusion", this, &FusionWorker::diagnose);
  diagnostics_timer_ =
      nh_.createTimer(ros::Duration(kDiagnosticsPeriod), [this](const ros::TimerEvent&) { diagnostics_.update(); });
  ROS_INFO_STREAM("fusion: MapGrid " << grid_.geometry().width << "x" << grid_.geometry().height << " cells at "
                                     << grid_.geometry().resolution << " m, frames " << map_frame_ << " <- "
                                     << base_frame_);
}

FusionWorker::~FusionWorker() = default;

void FusionWorker::onReconfigure(FusionConfig& c, uint32_t)
{
  std::lock_guard<std::mutex> lock(mutex_);
  core::MapGridParams p = pending_params_ ? *pending_params_ : grid_.params();
  p.fusion.discount = core::ContextualRates{ c.alpha_static, c.alpha_dynamic, c.alpha_free };
  p.rates_per_second = c.alpha_per_second;
  p.fusion.counter.delta_inc = c.delta_inc;
  p.fusion.counter.delta_dec = c.delta_dec;
  p.fusion.counter.gamma_occupied = c.gamma_occupied;
  p.fusion.counter.gamma_conflict = c.gamma_conflict;
  p.fusion.counter.mode =
      c.specialise_literal ? core::SpecialisationMode::kLiteral : core::SpecialisationMode::kMovingToStopped;
  p.decision_threshold = c.decision_threshold;
  p.min_object_cells = c.min_object_cells;
  try
  {
    p.validate();
    pending_params_ = p;  // applied before the next scan, never mid-scan
  }
  catch (const core::ParameterError& e)
  {
    ROS_ERROR_STREAM("fusion: reconfigure rejected: " << e.what());
  }
}

void FusionWorker::onPrior(const EvidentialGrid::ConstPtr& msg)
{
  auto prior = std::make_shared<core::PriorWindow>();
  try
  {
    GridConversions::fromMessage(*msg, *prior);
  }
  catch (const ConversionError& e)
  {
    ROS_ERROR_STREAM("fusion: prior_grid rejected: " << e.what());
    return;
  }
  if (!msg->header.frame_id.empty() && msg->header.frame_id != map_frame_)
  {
    ROS_ERROR_STREAM("fusion: prior_grid is in frame '" << msg->header.frame_id << "', expected '" << map_frame_
                                                        << "'; ignored");
    return;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  prior_ = prior;
  ROS_INFO_STREAM("fusion: prior grid " << prior->geometry.width << "x" << prior->geometry.height << " cells at "
                                        << prior->geometry.resolution << " m");
}

void FusionWorker::onScanDropped(const EvidentialGrid::ConstPtr& msg, tf2_ros::FilterFailureReason reason)
{
  std::lock_guard<std::mutex> lock(mutex_);
  ++counters_.dropped_no_transform;
  ROS_WARN_STREAM_THROTTLE(1.0, "fusion: scan at " << msg->header.stamp << " dropped: " << reasonName(reason) << " ("
                                                   << map_frame_ << " <- " << msg->header.frame_id << "); "
                                                   << counters_.dropped_no_transform << " dropped so far");
}

void FusionWorker::onScan(const EvidentialGrid::ConstPtr& msg)
{
  const auto wall0 = std::chrono::steady_clock::now();
  core::ScanMassGrid scan;
  try
  {
    GridConversions::fromMessage(*msg, scan);
    for (std::size_t i = 0; i < scan.numCells(); ++i)
    {
      const float s = scan.plane(0)[i] + scan.plane(1)[i] + scan.plane(2)[i] + scan.plane(3)[i];
      if (!(std::abs(s - 1.0f) < 1e-3f) || scan.plane(1)[i] < 0.0f || scan.plane(2)[i] < 0.0f || scan.plane(3)[i] < 0.0f)
        throw ConversionError("cell " + std::to_string(i) + " is not a mass function (sum " + std::to_string(s) + ")");
    }
  }
  catch (const ConversionError& e)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++counters_.rejected;
    ROS_ERROR_STREAM_THROTTLE(1.0, "fusion: scan_grid rejected (" << counters_.rejected << " so far): " << e.what());
    return;
  }
  geometry_msgs::TransformStamped tf;
  try
  {
    tf = tf_buffer_.lookupTransform(map_frame_, msg->header.frame_id, msg->header.stamp);
  }
  catch (const tf2::TransformException& e)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++counters_.dropped_no_transform;
    ROS_WARN_STREAM_THROTTLE(1.0, "fusion: scan dropped: " << e.what());
    return;
  }
  core::Pose2 pose;
  pose.x = tf.transform.translation.x;
  pose.y = tf.transform.translation.y;
  pose.yaw = tf2::getYaw(tf.transform.rotation);

  std::lock_guard<std::mutex> lock(mutex_);
  if (pending_params_)
  {
    grid_.setParams(*pending_params_);
    pending_params_.reset();
  }
  if (last_stamp_ && msg->header.stamp + kBackwardTolerance < *last_stamp_)
  {
    ROS_WARN_STREAM("fusion: time went backwards (" << *last_stamp_ << " -> " << msg->header.stamp
                                                     << "); resetting the MapGrid");
    grid_.reset();
    ++counters_.resets;
  }
  if (!prior_ && !warned_no_prior_)
  {
    ROS_INFO("fusion: no prior_grid received yet: fusing with a vacuous prior");
    warned_no_prior_ = true;
  }
  core::StageTimes times;
  const auto stats = grid_.update(scan, pose, msg->header.stamp.toSec(), prior_.get(), &times);
  last_stamp_ = msg->header.stamp;
  ++counters_.fused;
  last_times_ = times;
  last_mean_conflict_ = stats.meanConflict();
  const auto now = ros::WallTime::now();
  if (!last_scan_wall_.isZero())
  {
    const double dt = (now - last_scan_wall_).toSec();
    if (dt > 0.0) scan_rate_ = 1.0 / dt;
  }
  last_scan_wall_ = now;

  std_msgs::Header header;
  header.stamp = msg->header.stamp;
  header.frame_id = map_frame_;
  publish(header);
  last_total_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
}

void FusionWorker::publish(const std_msgs::Header& header)
{
  const auto& grid = grid_.masses();
  if (map_grid_pub_.getNumSubscribers() > 0)
  {
    auto out = boost::make_shared<EvidentialGrid>();
    GridConversions::toMessage(grid, header, *out, PlaneSelection::kNonZero, true);
    map_grid_pub_.publish(out);
  }
  bool need_betp = decision_pub_.getNumSubscribers() + cells_pub_.getNumSubscribers() + objects_pub_.getNumSubscribers() > 0;
  for (const auto& p : betp_pub_) need_betp = need_betp || p.getNumSubscribers() > 0;
  if (!need_betp) return;
  const core::PignisticPlanes& betp = grid_.pignistic();
  for (int e = 0; e < core::FrameMG::kSize; ++e)
  {
    if (betp_pub_[e].getNumSubscribers() == 0) continue;
    auto occ = boost::make_shared<nav_msgs::OccupancyGrid>();
    GridConversions::pignisticToOccupancy(grid, betp, e, header, *occ);
    betp_pub_[e].publish(occ);
  }
  std::vector<std::int8_t> decision;
  core::decide(grid, betp, grid_.params().decision_threshold, decision);
  if (decision_pub_.getNumSubscribers() > 0)
  {
    auto occ = boost::make_shared<nav_msgs::OccupancyGrid>();
    occ->header = header;
    GridConversions::toMapMetaData(grid.geometry(), occ->info);
    occ->info.map_load_time = header.stamp;
    occ->data = decision;
    decision_pub_.publish(occ);
  }
  if (cells_pub_.getNumSubscribers() > 0)
  {
    auto cells = boost::make_shared<visualization_msgs::MarkerArray>();
    Visualization::decisionToCells(grid.geometry(), decision, header, publish_free_cells_, *cells);
    cells_pub_.publish(cells);
  }
  if (objects_pub_.getNumSubscribers() > 0)
  {
    auto markers = boost::make_shared<visualization_msgs::MarkerArray>();
    const auto objects = core::extractObjects(grid.geometry(), decision, betp, grid_.params().min_object_cells);
    Visualization::objectsToMarkers(objects, header, object_box_height_, *markers);
    objects_pub_.publish(markers);
  }
}

void FusionWorker::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status)
{
  std::lock_guard<std::mutex> lock(mutex_);
  if (counters_.fused == 0)
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "no scan fused yet");
  else if (counters_.dropped_no_transform + counters_.rejected > 0)
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "scans dropped or rejected");
  else
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "fusing");
  status.add("scans fused", counters_.fused);
  status.add("scans dropped (no transform)", counters_.dropped_no_transform);
  status.add("scans rejected (malformed)", counters_.rejected);
  status.add("grid resets (time backwards)", counters_.resets);
  status.add("scan rate [Hz]", scan_rate_);
  status.add("time shift [ms]", 1e3 * last_times_.shift);
  status.add("time project scan [ms]", 1e3 * last_times_.project_scan);
  status.add("time prior window [ms]", 1e3 * last_times_.prior_window);
  status.add("time fusion [ms]", 1e3 * last_times_.fusion);
  status.add("time total with outputs [ms]", 1e3 * last_total_seconds_);
  status.add("mean conflict", last_mean_conflict_);
  status.add("prior", prior_ ? "received" : "none (vacuous)");
}

}  // namespace map_aided_fusion

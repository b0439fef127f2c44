#include "map_aided_fusion/ros/scan_grid_worker.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <boost/make_shared.hpp>
#include <nav_msgs/OccupancyGrid.h>
#include <std_msgs/Header.h>

#include "map_aided_fusion/EvidentialGrid.h"
#include "map_aided_fusion/core/parameters.hpp"
#include "map_aided_fusion/ros/conversions.hpp"
#include "map_aided_fusion/ros/param_loading.hpp"
#include "map_aided_fusion/ros/point_cloud_view.hpp"
#include "map_aided_fusion/ros/startup_failure.hpp"
#include "map_aided_fusion/ros/tf_helpers.hpp"

namespace map_aided_fusion {

namespace {

constexpr int kMaxQueueSize = 1000;
constexpr double kMillisecondsPerSecond = 1000.0;

/// Clouds roscpp holds for the intake thread (onCloud takes microseconds, and waits at most for one build's lock):
/// far more than arrive while a build holds the lock, so that none is lost there unseen.
constexpr std::uint32_t kIntakeQueue = 200;
constexpr double kMaxFutureTolerance = 3600.0;
constexpr double kMinJumpThreshold = 0.001;
constexpr double kMaxJumpThreshold = 3600.0;
/// Wall period of the clock watch (backward /clock jumps), s.
constexpr double kClockCheckPeriod = 0.1;

/// The reconfigurable fields of @p m, written into @p c (what the server then shows and replies).
void toConfig(const core::ScanGridParams& m, ScanGridConfig& c)
{
  c.azimuth_resolution_deg = m.azimuth_resolution_deg;
  c.min_range = m.min_range;
  c.max_range = m.max_range;
  c.ground_height = m.ground_height;
  c.ground_tolerance = m.ground_tolerance;
  c.obstacle_min_height = m.obstacle_min_height;
  c.obstacle_max_height = m.obstacle_max_height;
  c.mu_free = m.mu_free;
  c.mu_occupied = m.mu_occupied;
  c.free_decay_length = m.free_decay_length;
  c.free_margin = m.free_margin;
  c.ambiguous_unknown = m.ambiguous_unknown;
  c.ground_cells_free = m.ground_cells_free;
  c.ground_consensus = m.ground_consensus;
  c.deskew = m.deskew;
  c.ground_model = m.ground_model;
}

}  // namespace

void ScanGridNodeParams::validate() const
{
  if (base_frame.empty()) throw core::ParameterError("base_frame", "must not be empty");
  if (deskew_fixed_frame.empty()) throw core::ParameterError("deskew_fixed_frame", "must not be empty");
  const auto& known = knownTimeFields();
  if (deskew_time_field != "auto" && std::find(known.begin(), known.end(), deskew_time_field) == known.end())
    throw core::ParameterError("deskew_time_field", "unknown field '" + deskew_time_field +
                                                        "' (auto, time, t, timestamp, offset_time)");
  core::requireInRange("input_queue_size", input_queue_size, 1, kMaxQueueSize);
  core::requireInRange("tf_queue_size", tf_queue_size, 1, kMaxQueueSize);
  core::requireInRange("future_tolerance", future_tolerance, 0.0, kMaxFutureTolerance);
  core::requireInRange("time_jump_threshold", time_jump_threshold, kMinJumpThreshold, kMaxJumpThreshold);
  health.validate();
  input.validate();
  model.validate();
}

ScanGridNodeParams ScanGridNodeParams::load(const ros::NodeHandle& pnh)
{
  ScanGridNodeParams p;
  forEachParam(p, parameterServerReader(pnh));
  p.validate();
  return p;
}

ScanGridWorker::ScanGridWorker(ros::NodeHandle nh, ros::NodeHandle pnh) : nh_(nh), pnh_(pnh)
{
  try
  {
    params_ = ScanGridNodeParams::load(pnh_);
    refuseUnknownParams(pnh_, reconfigureNames<ScanGridConfig>());
    builder_.configure(params_.model, Eigen::Isometry3d::Identity());
  }
  catch (const core::ParameterError& e)
  {
    ROS_ERROR("scan_grid: invalid parameter %s/%s; the node stays idle until restarted with valid parameters",
              pnh_.getNamespace().c_str(), e.what());
    failure_ = std::make_unique<StartupFailure>(nh_, pnh_, "ScanGrid", std::string("invalid parameter ") + e.what());
    return;
  }
  grid_.reset(builder_.geometry());

  tf_buffer_ = std::make_unique<tf2_ros::Buffer>();
  tf_listener_ = std::make_unique<tf2_ros::TransformListener>(*tf_buffer_, nh_);
  tf_filter_ = std::make_unique<tf2_ros::MessageFilter<sensor_msgs::PointCloud2>>(
      *tf_buffer_, params_.base_frame, static_cast<std::uint32_t>(params_.tf_queue_size), nh_);
  tf_filter_->registerCallback(&ScanGridWorker::onCloudWithTransform, this);
  tf_filter_->registerFailureCallback(
      [this](const sensor_msgs::PointCloud2ConstPtr& cloud,
             tf2_ros::filter_failure_reasons::FilterFailureReason reason) { onTransformFailure(cloud, reason); });

  updater_ = std::make_unique<diagnostic_updater::Updater>(nh_, pnh_, pnh_.getNamespace());
  updater_->setHardwareID("scan_grid");
  updater_->add("ScanGrid", this, &ScanGridWorker::diagnose);
  gaps_ = core::InputGapCounter(params_.input.input_period);
  for (auto* w : { &received_window_, &published_window_, &rejected_window_, &deskew_skipped_window_,
                   &ground_fallback_window_, &lost_window_, &overrun_window_, &stream_gap_window_ })
    w->setSpan(params_.health.diagnostic_window);
  processing_samples_.setSpan(params_.health.diagnostic_window);
  cloud_to_published_.setSpan(params_.health.diagnostic_window);
  start_wall_ = core::steadySeconds();
  clock_jump_.setThreshold(params_.time_jump_threshold);
  diagnostic_timer_ = nh_.createWallTimer(ros::WallDuration(params_.health.diagnostic_period),
                                          [this](const ros::WallTimerEvent&) { updater_->force_update(); });
  clock_timer_ =
      nh_.createWallTimer(ros::WallDuration(kClockCheckPeriod), [this](const ros::WallTimerEvent&) { checkClock(); });

  reconfigure_ = std::make_unique<dynamic_reconfigure::Server<ScanGridConfig>>(pnh_);
  reconfigure_->setCallback(
      [this](ScanGridConfig& config, std::uint32_t level) { onReconfigure(config, level); });

  grid_pub_ = nh_.advertise<EvidentialGrid>("scan_grid", 1);
  occupancy_pub_ = nh_.advertise<nav_msgs::OccupancyGrid>("scan_grid/occupancy", 1);
  started_pub_ = nh_.advertise<std_msgs::Header>("scan_grid/started", 1);
  ros::SubscribeOptions intake = ros::SubscribeOptions::create<sensor_msgs::PointCloud2>(
      "points", kIntakeQueue, [this](const sensor_msgs::PointCloud2ConstPtr& cloud) { onCloud(cloud); },
      ros::VoidPtr(), &intake_queue_);
  intake.transport_hints = ros::TransportHints().tcpNoDelay();
  cloud_sub_ = nh_.subscribe(intake);
  intake_spinner_ = std::make_unique<ros::AsyncSpinner>(1, &intake_queue_);
  intake_spinner_->start();
  active_ = true;
  const core::GridGeometry& g = builder_.geometry();
  ROS_INFO("scan_grid: %s -> %s and %s in %s, %d x %d cells of %.2f m, %d sectors",
           cloud_sub_.getTopic().c_str(), grid_pub_.getTopic().c_str(), occupancy_pub_.getTopic().c_str(),
           params_.base_frame.c_str(), g.width, g.height, g.resolution, builder_.numSectors());
}

ScanGridWorker::~ScanGridWorker()
{
  cloud_sub_.shutdown();
  if (intake_spinner_) intake_spinner_->stop();
  diagnostic_timer_.stop();
  clock_timer_.stop();
  tf_filter_.reset();
}

void ScanGridWorker::reject(const std::string& reason, const std::string& detail)
{
  ++counters_.clouds_rejected;
  ++counters_.rejections[reason];
  rejected_window_.add(core::steadySeconds());
  last_rejection_ = reason + ": " + detail;
  if (reported_.insert(reason).second)
    ROS_ERROR("scan_grid: rejected a cloud on %s (%s): %s. Further clouds rejected for this reason are only "
              "counted (see diagnostics).",
              cloud_sub_.getTopic().c_str(), reason.c_str(), detail.c_str());
  else
    ROS_DEBUG("scan_grid: rejected a cloud (%s): %s", reason.c_str(), detail.c_str());
}

bool ScanGridWorker::viewOf(const sensor_msgs::PointCloud2& cloud, core::PointCloudView& view)
{
  std::string detail;
  const CloudRejection r = makePointCloudView(cloud, view, &detail);
  if (r == CloudRejection::kNone) return true;
  reject(toString(r), detail);
  return false;
}

void ScanGridWorker::checkClock()
{
  const ros::Time now = ros::Time::now();
  if (now.isZero()) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!clock_jump_.observe(now.toSec())) return;
    ++tf_clears_;
    last_jump_wall_ = core::steadySeconds();
    ROS_WARN("scan_grid: ROS time went back by more than time_jump_threshold (%.3f s) to %.3f; clearing the tf "
             "buffer and the clouds waiting for a transform",
             params_.time_jump_threshold, now.toSec());
    tf_buffer_->clear();
    pending_builds_ = 0;
  }
  tf_filter_->clear();
}

void ScanGridWorker::onCloud(const sensor_msgs::PointCloud2ConstPtr& cloud)
{
  checkClock();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++counters_.clouds_received;
    received_window_.add(core::steadySeconds());
    // Every cloud received, rejected or not, is one the stream did not miss; a gap in the stamps is the stream's.
    if (!cloud->header.stamp.isZero())
      if (const std::size_t missing = gaps_.observe(cloud->header.stamp.toSec()); missing > 0)
      {
        stream_gaps_ += missing;
        stream_gap_window_.add(core::steadySeconds(), missing);
      }
    core::PointCloudView view;
    if (!viewOf(*cloud, view)) return;
    if (cloud->header.frame_id.empty())
    {
      reject("no_frame_id", "header.frame_id is empty");
      return;
    }
    if (cloud->header.stamp.isZero())
    {
      reject("zero_stamp", "header.stamp is 0: no transform can be looked up for it");
      return;
    }
    const ros::Time now = ros::Time::now();
    const double ahead = now.isZero() ? 0.0 : (cloud->header.stamp - now).toSec();
    if (ahead > params_.future_tolerance)
    {
      reject("future_stamp", "stamped " + std::to_string(ahead) + " s ahead of the clock (future_tolerance " +
                                 std::to_string(params_.future_tolerance) + " s)");
      return;
    }
    if (core::steadySeconds() - last_jump_wall_ < core::kAfterJumpWatch && ahead > params_.time_jump_threshold)
    {
      reject("before_time_jump", "stamped " + std::to_string(ahead) +
                                     " s ahead of a clock that went back: a cloud of before the jump");
      return;
    }
    const std::string& frame = cloud->header.frame_id;
    const std::string source = tfFrame(frame);
    if (!tf_buffer_->_frameExists(source))
      ROS_WARN_THROTTLE(1.0, "scan_grid: frame '%s' of %s is unknown to tf so far; the cloud waits for a transform "
                             "to %s",
                        frame.c_str(), cloud_sub_.getTopic().c_str(), params_.base_frame.c_str());
    if (grid_pub_.getNumSubscribers() == 0 && occupancy_pub_.getNumSubscribers() == 0)
    {
      ++counters_.clouds_skipped;
      return;
    }
    ++pending_builds_;
  }
  tf_filter_->add(cloud);
}

bool ScanGridWorker::takePendingBuild(const sensor_msgs::PointCloud2& cloud)
{
  if (pending_builds_ > 0) --pending_builds_;
  if (pending_builds_ < static_cast<std::size_t>(params_.input_queue_size)) return true;
  ++clouds_lost_;
  lost_window_.add(core::steadySeconds(), 1);
  ROS_WARN_THROTTLE(1.0, "scan_grid: a cloud on %s stamped %.3f dropped unbuilt: %zu newer clouds wait behind it "
                         "(input_queue_size %d): processing is slower than the input; raise input_queue_size or "
                         "lighten the load; %zu lost so far",
                    cloud_sub_.getTopic().c_str(), cloud.header.stamp.toSec(), pending_builds_,
                    params_.input_queue_size, clouds_lost_);
  return false;
}

void ScanGridWorker::onTransformFailure(const sensor_msgs::PointCloud2ConstPtr& cloud,
                                        tf2_ros::filter_failure_reasons::FilterFailureReason reason)
{
  std::lock_guard<std::mutex> lock(mutex_);
  if (pending_builds_ > 0) --pending_builds_;
  const char* why = reason == tf2_ros::filter_failure_reasons::OutTheBack ? "older than the transform buffer" :
                    reason == tf2_ros::filter_failure_reasons::EmptyFrameID ? "empty frame_id" :
                                                                               "transform not available in time";
  reject("no_transform", "no transform " + params_.base_frame + " <- " + cloud->header.frame_id + " at " +
                             std::to_string(cloud->header.stamp.toSec()) + ": " + why);
}

void ScanGridWorker::onCloudWithTransform(const sensor_msgs::PointCloud2ConstPtr& cloud)
{
  const ros::WallTime start = ros::WallTime::now();
  std::lock_guard<std::mutex> lock(mutex_);
  if (!takePendingBuild(*cloud) || !setSensorPose(*cloud)) return;
  core::PointCloudView raw, view;
  if (!viewOf(*cloud, raw)) return;
  noteDeskew(deskewer_.apply(*cloud, raw, params_.model.deskew, params_.deskew_time_field,
                             params_.model.deskew_max_sweep_duration, *tf_buffer_, params_.deskew_fixed_frame, view));
  if (started_pub_.getNumSubscribers() > 0)
  {
    auto started = boost::make_shared<std_msgs::Header>();
    started->stamp = cloud->header.stamp;
    started->frame_id = params_.base_frame;
    started_pub_.publish(started);
  }
  if (!builder_.build(view, grid_, &last_stats_))
  {
    reject("layout", "the point view is inconsistent");
    return;
  }
  counters_.points_rejected += last_stats_.rejected();
  if (blindCloud(last_stats_)) return;
  if (last_stats_.ground_fit.flat_fallback)
  {
    ++ground_flat_fallbacks_;
    ground_fallback_window_.add(core::steadySeconds());
    ROS_WARN_THROTTLE(1.0, "scan_grid: the ground model fitted no zone of a cloud on %s; that scan used the flat "
                           "ground (%zu zones with too few points, %zu too steep)",
                      cloud_sub_.getTopic().c_str(), last_stats_.ground_fit.few_points,
                      last_stats_.ground_fit.too_steep);
  }

  std_msgs::Header header;
  header.stamp = cloud->header.stamp;
  header.frame_id = params_.base_frame;
  publishGrid(header);
  recordPublished(start, cloud->header.stamp);
}

bool ScanGridWorker::setSensorPose(const sensor_msgs::PointCloud2& cloud)
{
  try
  {
    const std::string source = tfFrame(cloud.header.frame_id);
    builder_.setSensorPose(
        toEigen(tf_buffer_->lookupTransform(params_.base_frame, source, cloud.header.stamp).transform));
    return true;
  }
  catch (const tf2::TransformException& e)
  {
    reject("no_transform", e.what());
  }
  catch (const core::ParameterError& e)
  {
    reject("bad_transform", e.what());
  }
  return false;
}

void ScanGridWorker::noteDeskew(const DeskewResult& deskew)
{
  ++deskew_counts_[deskew.status];
  last_deskew_ = deskew.status;
  if (!deskew.skipped()) return;
  deskew_skipped_window_.add(core::steadySeconds());
  if (deskew_warned_.insert(deskew.status).second)
    ROS_WARN("scan_grid: a cloud on %s is not deskewed (%s): %s. Further clouds skipped for this reason are only "
             "counted (see diagnostics).",
             cloud_sub_.getTopic().c_str(), deskew.status.c_str(), deskew.detail.c_str());
}

void ScanGridWorker::publishGrid(const std_msgs::Header& header)
{
  if (grid_pub_.getNumSubscribers() > 0)
  {
    auto msg = boost::make_shared<EvidentialGrid>();
    GridConversions::toMessage(grid_, header, *msg);
    const core::ObstaclePoints obstacles = builder_.obstaclePoints();
    msg->obstacle_points.assign(obstacles.xy, obstacles.xy + 2 * obstacles.count);
    grid_pub_.publish(msg);
  }
  if (occupancy_pub_.getNumSubscribers() > 0)
  {
    auto occupancy = boost::make_shared<nav_msgs::OccupancyGrid>();
    GridConversions::scanToOccupancy(grid_, header, *occupancy);
    occupancy_pub_.publish(occupancy);
  }
}

void ScanGridWorker::recordPublished(const ros::WallTime& start, const ros::Time& stamp)
{
  ++counters_.clouds_published;
  last_published_wall_ = core::steadySeconds();
  published_window_.add(last_published_wall_);
  const double elapsed = (ros::WallTime::now() - start).toSec();
  window_processing_sum_ += elapsed;
  window_processing_max_ = std::max(window_processing_max_, elapsed);
  ++window_processed_;
  processing_samples_.add(last_published_wall_, kMillisecondsPerSecond * elapsed);
  cloud_to_published_.add(last_published_wall_, kMillisecondsPerSecond * (ros::Time::now() - stamp).toSec());
  if (gaps_.period() > 0.0 && elapsed > gaps_.period())
  {
    ++overruns_;
    overrun_window_.add(last_published_wall_);
  }
}

bool ScanGridWorker::blindCloud(const core::ScanGridStats& stats)
{
  const std::size_t valid = stats.points - stats.non_finite - stats.no_return;
  const core::BlindReason why = core::judgeReturns(stats.points, valid, params_.input);
  if (why == core::BlindReason::kNone)
  {
    if (blind_.active())
      ROS_INFO("scan_grid: %s sees again (%zu valid returns) after %zu blind clouds", cloud_sub_.getTopic().c_str(),
               valid, blind_.clouds());
    blind_.sighted();
    return false;
  }
  blind_.blind(core::steadySeconds());
  last_blind_reason_ = core::toString(why);
  reject(last_blind_reason_, std::to_string(valid) + " valid returns of " + std::to_string(stats.points) +
                                 " points (min_valid_returns " + std::to_string(params_.input.min_valid_returns) +
                                 "): the lidar is blind; not fused, the MapGrid keeps its evidence");
  return true;
}

void ScanGridWorker::onReconfigure(ScanGridConfig& config, std::uint32_t /*level*/)
{
  std::lock_guard<std::mutex> lock(mutex_);
  core::ScanGridParams m = params_.model;
  m.azimuth_resolution_deg = config.azimuth_resolution_deg;
  m.min_range = config.min_range;
  m.max_range = config.max_range;
  m.ground_height = config.ground_height;
  m.ground_tolerance = config.ground_tolerance;
  m.obstacle_min_height = config.obstacle_min_height;
  m.obstacle_max_height = config.obstacle_max_height;
  m.mu_free = config.mu_free;
  m.mu_occupied = config.mu_occupied;
  m.free_decay_length = config.free_decay_length;
  m.free_margin = config.free_margin;
  m.ambiguous_unknown = config.ambiguous_unknown;
  m.ground_cells_free = config.ground_cells_free;
  m.ground_consensus = config.ground_consensus;
  m.deskew = config.deskew;
  m.ground_model = config.ground_model;
  try
  {
    builder_.configure(m, builder_.sensorPose());
    params_.model = m;
    last_reconfigure_ = "accepted";
  }
  catch (const core::ParameterError& e)
  {
    ++reconfigure_refused_;
    last_reconfigure_ = std::string("refused: ") + e.what();
    ROS_ERROR("scan_grid: reconfigure refused, the previous values stay in force: %s", e.what());
  }
  toConfig(params_.model, config);
}

void ScanGridWorker::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status)
{
  std::lock_guard<std::mutex> lock(mutex_);
  const double now = core::steadySeconds();
  const core::InputFindings found = diagnoseSummary(status, now);
  diagnoseStream(status, now, found);
  diagnoseTotals(status, now);
  window_processed_ = 0;
  window_processing_sum_ = window_processing_max_ = 0.0;
}

core::InputFindings ScanGridWorker::diagnoseSummary(diagnostic_updater::DiagnosticStatusWrapper& status, double now)
{
  const std::size_t published = published_window_.count(now);
  const std::size_t rejected = rejected_window_.count(now);
  const bool ever = counters_.clouds_published > 0;
  core::InputFindings found;
  found.blind = blind_.active();
  found.blind_for = blind_.duration(now);
  found.blind_clouds = blind_.clouds();
  found.blind_reason = last_blind_reason_;
  found.lost = lost_window_.count(now);
  found.overruns = overrun_window_.count(now);
  core::HealthSummary h = core::inputHealth(
      core::streamHealth(params_.health, ever, ever ? now - last_published_wall_ : 0.0, published, rejected,
                         "clouds published"),
      params_.health, found);
  if (!ever)
  {
    // Say what is waited for: the topic when nothing came, the cause when everything that came was rejected.
    const double waited = now - start_wall_;
    if (counters_.clouds_received == 0)
      h.message = "no cloud received on " + cloud_sub_.getTopic() + " yet (" +
                  std::to_string(cloud_sub_.getNumPublishers()) + " publishers): is the lidar on that topic? "
                  "remap `points`";
    else if (counters_.clouds_rejected > 0)
    {
      h.message = "every cloud on " + cloud_sub_.getTopic() + " rejected, the last for " + last_rejection_;
      if (waited >= params_.health.stale_error) h.level = core::HealthLevel::kError;
    }
  }
  status.summary(static_cast<unsigned char>(h.level), h.message);
  return found;
}

void ScanGridWorker::diagnoseStream(diagnostic_updater::DiagnosticStatusWrapper& status, double now,
                                   const core::InputFindings& found)
{
  const std::size_t rejected = rejected_window_.count(now);
  const double mean_ms = window_processed_ > 0 ? kMillisecondsPerSecond * window_processing_sum_ /
                                                     static_cast<double>(window_processed_) :
                                                 0.0;
  status.add("input rate (Hz)", received_window_.rate(now, start_wall_));
  status.add("output rate (Hz)", published_window_.rate(now, start_wall_));
  status.add("clouds rejected in window", rejected);
  status.add("last rejection", last_rejection_.empty() ? std::string("none") : last_rejection_);
  status.add("lidar blind for (s)", found.blind_for);
  status.add("clouds lost in the input queue in window", found.lost);
  status.add("clouds lost in the input queue", clouds_lost_);
  status.add("clouds processed slower than they come in window", found.overruns);
  status.add("clouds processed slower than they come", overruns_);
  status.add("clouds missing from the stream in window", stream_gap_window_.count(now));
  status.add("clouds missing from the stream", stream_gaps_);
  status.add("input period (s)", gaps_.period());
  status.add("window (s)", params_.health.diagnostic_window);
  status.add("processing time mean (ms)", mean_ms);
  status.add("processing time max (ms)", kMillisecondsPerSecond * window_processing_max_);
  for (const auto& [q, label] : { std::pair<double, const char*>{ 0.5, " median (ms)" }, { 0.9, " p90 (ms)" } })
  {
    const double build = processing_samples_.quantile(now, q), age = cloud_to_published_.quantile(now, q);
    if (std::isnan(build))
      status.add(std::string("processing time") + label, "none");
    else
      status.add(std::string("processing time") + label, build);
    if (std::isnan(age))
      status.add(std::string("latency cloud to grid published") + label, "none");
    else
      status.add(std::string("latency cloud to grid published") + label, age);
  }
  status.add("clouds stamped ahead of the clock in window", cloud_to_published_.aheadOfClock(now));
  if (const double lead = cloud_to_published_.largestLead(now); std::isnan(lead))
    status.add("largest lead of a stamp over the clock (ms)", "none");
  else
    status.add("largest lead of a stamp over the clock (ms)", lead);
}

void ScanGridWorker::diagnoseTotals(diagnostic_updater::DiagnosticStatusWrapper& status, double now)
{
  status.add("clouds received", counters_.clouds_received);
  status.add("clouds published", counters_.clouds_published);
  status.add("clouds rejected", counters_.clouds_rejected);
  status.add("clouds skipped (no subscriber)", counters_.clouds_skipped);
  for (const auto& r : counters_.rejections) status.add("clouds rejected: " + r.first, r.second);
  status.add("points rejected", counters_.points_rejected);
  status.add("tf buffer clears (time jump)", tf_clears_);
  status.add("deskew", !params_.model.deskew ? std::string("off (parameter deskew)") :
                       last_deskew_ == "no_time_field" ?
                                               std::string("off: the clouds carry no time field (") +
                                                   params_.deskew_time_field + ")" :
                                               "on, last cloud: " + last_deskew_);
  status.add("deskew skipped in window", deskew_skipped_window_.count(now));
  for (const auto& d : deskew_counts_) status.add("deskew: " + d.first, d.second);
  status.add("ground model", params_.model.ground_model);
  if (params_.model.groundModel() != core::GroundModel::kFlat)
  {
    const core::GroundFitStats& g = last_stats_.ground_fit;
    status.add("ground flat fallbacks in window", ground_fallback_window_.count(now));
    status.add("ground flat fallbacks", ground_flat_fallbacks_);
    status.add("last cloud: ground zones fitted / few points / too steep / discontinuous",
               std::to_string(g.fitted) + " / " + std::to_string(g.few_points) + " / " + std::to_string(g.too_steep) +
                   " / " + std::to_string(g.discontinuous) + " of " + std::to_string(g.zones));
  }
  status.add("reconfigure refused", reconfigure_refused_);
  status.add("last reconfigure", last_reconfigure_);
  status.add("last cloud: points", last_stats_.points);
  status.add("last cloud: non-finite", last_stats_.non_finite);
  status.add("last cloud: no return (0,0,0)", last_stats_.no_return);
  status.add("last cloud: out of range", last_stats_.below_min_range + last_stats_.beyond_max_range);
  status.add("last cloud: self returns", last_stats_.self_returns);
  status.add("last cloud: ground / obstacle", std::to_string(last_stats_.ground) + " / " +
                                                  std::to_string(last_stats_.obstacle));
  status.add("last cloud: occupied / free cells", std::to_string(last_stats_.occupied_cells) + " / " +
                                                      std::to_string(last_stats_.free_cells));
}

}  // namespace map_aided_fusion

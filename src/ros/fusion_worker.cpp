#include "map_aided_fusion/ros/fusion_worker.hpp"

#ifdef __GLIBC__
#include <malloc.h>
#endif

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <sstream>

#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <nav_msgs/OccupancyGrid.h>
#include <nav_msgs/Odometry.h>
#include <tf2/utils.h>
#include <visualization_msgs/MarkerArray.h>

#include "map_aided_fusion/ros/conversions.hpp"
#include "map_aided_fusion/ros/param_loading.hpp"
#include "map_aided_fusion/core/track_evidence.hpp"
#include "map_aided_fusion/ros/visualization.hpp"

namespace map_aided_fusion {

namespace {

constexpr int kMaxQueueSize = 1000;
constexpr double kMaxFutureTolerance = 3600.0;
constexpr double kMaxObjectBoxHeight = 100.0;
/// Wall period of the clock watch (backward /clock jumps, transforms ahead of the clock), s.
constexpr double kClockCheckPeriod = 0.1;
constexpr double kWarnThrottle = 1.0;
constexpr double kMillisecondsPerSecond = 1000.0;
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

void FusionNodeParams::validate() const
{
  if (map_frame.empty()) throw core::ParameterError("map_frame", "must not be empty");
  core::requireInRange("tf_queue_size", tf_queue_size, 1, kMaxQueueSize);
  core::requireInRange("future_tolerance", future_tolerance, 0.0, kMaxFutureTolerance);
  core::requireInRange("object_box_height", object_box_height, 1e-3, kMaxObjectBoxHeight);
  if (pose_covariance_type != "pose" && pose_covariance_type != "odometry")
    throw core::ParameterError("pose_covariance_type", "must be 'pose' or 'odometry', not '" + pose_covariance_type + "'");
  time.validate();
  health.validate();
}

FusionNodeParams FusionNodeParams::load(const ros::NodeHandle& pnh)
{
  FusionNodeParams p;
  forEachParam(p, parameterServerReader(pnh));
  p.validate();
  return p;
}

FusionWorker::FusionWorker(ros::NodeHandle nh, ros::NodeHandle pnh)
  : nh_(nh)
  , pnh_(pnh)
  , node_params_(FusionNodeParams::load(pnh))
  , grid_(loadMapGridParams(pnh))
  , stamp_guard_(node_params_.time)
  , clock_jump_(node_params_.time.time_jump_threshold)
  , started_refused_window_(node_params_.health.diagnostic_window)
  , fused_window_(node_params_.health.diagnostic_window)
  , lost_window_(node_params_.health.diagnostic_window)
  , covariance_rejected_window_(node_params_.health.diagnostic_window)
  , tracker_resets_window_(node_params_.health.diagnostic_window)
  , tracker_bounded_window_(node_params_.health.diagnostic_window)
  , tf_listener_(tf_buffer_, nh)
  , reconfigure_(pnh)
{
  start_wall_ = core::steadySeconds();
  latency_.setSpan(node_params_.health.diagnostic_window);
  map_grid_pub_ = nh_.advertise<EvidentialGrid>("map_grid", 1);
  for (int e = 0; e < core::FrameMG::kSize; ++e) betp_pub_[e] = nh_.advertise<nav_msgs::OccupancyGrid>(kBetpTopics[e], 1);
  decision_pub_ = nh_.advertise<nav_msgs::OccupancyGrid>("decision", 1);
  navigable_pub_ = nh_.advertise<nav_msgs::OccupancyGrid>("navigable", 1);
  cells_pub_ = nh_.advertise<visualization_msgs::MarkerArray>("cells", 1);
  objects_pub_ = nh_.advertise<visualization_msgs::MarkerArray>("objects", 1);
  if (const core::TrackerParams tp = loadTrackerParams(pnh); tp.enabled)
  {
    tracker_.emplace(tp);
    tracks_pub_ = nh_.advertise<TrackedObjectArray>("tracks", 1);
    tracks_markers_pub_ = nh_.advertise<visualization_msgs::MarkerArray>("tracks/markers", 1);
  }
  refuseUnknownParams(pnh_, reconfigureNames<FusionConfig>());

  const auto queue = static_cast<uint32_t>(node_params_.tf_queue_size);
  scan_filter_ =
      std::make_unique<tf2_ros::MessageFilter<EvidentialGrid>>(tf_buffer_, node_params_.map_frame, queue, nh_);
  scan_filter_->registerCallback(&FusionWorker::onScan, this);
  scan_filter_->registerFailureCallback(
      [this](const EvidentialGrid::ConstPtr& msg, tf2_ros::FilterFailureReason reason) { onScanDropped(msg, reason); });
  prior_sub_ = nh_.subscribe("prior_grid", 1, &FusionWorker::onPrior, this);
  scan_sub_ = nh_.subscribe("scan_grid", queue, &FusionWorker::onScanIn, this);
  if (node_params_.shift_ahead)
    started_sub_ = nh_.subscribe("scan_grid/started", 1, &FusionWorker::onScanStarted, this);
  if (node_params_.pose_covariance_topic.empty())
    ROS_INFO_STREAM("fusion: no pose_covariance_topic: the prior is softened by position_sigma = "
                    << grid_.params().position_sigma << " m");
  else if (node_params_.pose_covariance_type == "odometry")
    covariance_sub_ = nh_.subscribe<nav_msgs::Odometry>(
        node_params_.pose_covariance_topic, 1,
        [this](const nav_msgs::Odometry::ConstPtr& m) { onCovariance(m->pose.covariance); });
  else
    covariance_sub_ = nh_.subscribe<geometry_msgs::PoseWithCovarianceStamped>(
        node_params_.pose_covariance_topic, 1,
        [this](const geometry_msgs::PoseWithCovarianceStamped::ConstPtr& m) { onCovariance(m->pose.covariance); });

  reconfigure_.setCallback([this](FusionConfig& config, uint32_t level) { onReconfigure(config, level); });

  diagnostics_ = std::make_unique<diagnostic_updater::Updater>(nh_, pnh_, pnh_.getNamespace());
  diagnostics_->setHardwareID("map_aided_fusion");
  diagnostics_->add("fusion", this, &FusionWorker::diagnose);
  diagnostics_timer_ = nh_.createWallTimer(ros::WallDuration(node_params_.health.diagnostic_period),
                                           [this](const ros::WallTimerEvent&) { diagnostics_->force_update(); });
  clock_timer_ =
      nh_.createWallTimer(ros::WallDuration(kClockCheckPeriod), [this](const ros::WallTimerEvent&) { checkClock(); });
  ROS_INFO_STREAM("fusion: MapGrid " << grid_.geometry().width << "x" << grid_.geometry().height << " cells at "
                                     << grid_.geometry().resolution << " m ("
                                     << grid_.params().bytesNeeded() / (1024.0 * 1024.0) << " MiB), frames "
                                     << node_params_.map_frame << " <- " << node_params_.base_frame);
}

FusionWorker::~FusionWorker()
{
  clock_timer_.stop();
  diagnostics_timer_.stop();
  scan_sub_.shutdown();
}

namespace {

/// The reconfigurable fields of @p p, written into @p c (what the server then shows and replies).
void toConfig(const core::MapGridParams& p, FusionConfig& c)
{
  c.alpha_static = p.fusion.discount.alpha_static;
  c.alpha_dynamic = p.fusion.discount.alpha_dynamic;
  c.alpha_free = p.fusion.discount.alpha_free;
  c.alpha_per_second = p.rates_per_second;
  c.delta_inc = p.fusion.counter.delta_inc;
  c.delta_dec = p.fusion.counter.delta_dec;
  c.gamma_occupied = p.fusion.counter.gamma_occupied;
  c.gamma_conflict = p.fusion.counter.gamma_conflict;
  c.specialise_literal = p.fusion.counter.mode == core::SpecialisationMode::kLiteral;
  c.decision_threshold = p.decision_threshold;
  c.min_object_cells = p.min_object_cells;
}

}  // namespace

void FusionWorker::onReconfigure(FusionConfig& c, uint32_t)
{
  std::lock_guard<std::mutex> lock(mutex_);
  const core::MapGridParams in_force = pending_params_ ? *pending_params_ : grid_.params();
  core::MapGridParams p = in_force;
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
    last_reconfigure_ = "accepted";
    toConfig(p, c);
  }
  catch (const core::ParameterError& e)
  {
    ++counters_.reconfigure_refused;
    last_reconfigure_ = std::string("refused: ") + e.what();
    ROS_ERROR_STREAM("fusion: reconfigure refused, the previous values stay in force: " << e.what());
    toConfig(in_force, c);
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
  if (!msg->header.frame_id.empty() && msg->header.frame_id != node_params_.map_frame)
  {
    ROS_ERROR_STREAM("fusion: prior_grid is in frame '" << msg->header.frame_id << "', expected '"
                                                        << node_params_.map_frame << "'; ignored");
    return;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  softener_.setPrior(prior);
  // Softened here, for the σ in force, rather than in the next scan's callback (longer than a scan period for a large
  // map at 0.2 m); that scan recomputes only if σ changes before it.
  softenedPrior();
#ifdef __GLIBC__
  malloc_trim(0);  // the previous prior (possibly a huge map's) is freed: give its pages back
#endif
  ROS_INFO_STREAM("fusion: prior grid " << prior->geometry.width << "x" << prior->geometry.height << " cells at "
                                        << prior->geometry.resolution << " m");
}

const core::PriorWindow* FusionWorker::softenedPrior()
{
  const double sigma = std::isnan(covariance_sigma_) ? grid_.params().position_sigma : covariance_sigma_;
  bool softened = false;
  const core::PriorWindow* prior = softener_.softened(sigma, &softened);
  if (softened) ++counters_.prior_softenings;
  return prior;
}

void FusionWorker::onCovariance(const boost::array<double, 36>& covariance)
{
  std::array<double, 36> c;
  std::copy(covariance.begin(), covariance.end(), c.begin());
  double sigma = 0.0;
  const core::CovarianceFault fault = core::positionSigma(c, sigma);
  std::lock_guard<std::mutex> lock(mutex_);
  if (fault != core::CovarianceFault::kNone)
  {
    ++counters_.covariance_rejected;
    covariance_rejected_window_.add(core::steadySeconds());
    ROS_WARN_STREAM_THROTTLE(kWarnThrottle, "fusion: pose covariance on " << node_params_.pose_covariance_topic
                                                << " rejected (" << core::toString(fault) << "); keeping sigma = "
                                                << softener_.sigmaInForce() << " m");
    return;
  }
  if (sigma > core::kMaxPositionSigma)
  {
    ++counters_.sigma_clamped;
    ROS_WARN_STREAM_THROTTLE(kWarnThrottle, "fusion: position sigma " << sigma << " m from the covariance clamped to "
                                                                      << core::kMaxPositionSigma << " m");
    sigma = core::kMaxPositionSigma;
  }
  covariance_sigma_ = sigma;
  last_covariance_wall_ = core::steadySeconds();
}

void FusionWorker::countLost(std::size_t& counter)
{
  ++counter;
  lost_window_.add(core::steadySeconds());
}

void FusionWorker::onScanDropped(const EvidentialGrid::ConstPtr& msg, tf2_ros::FilterFailureReason reason)
{
  std::lock_guard<std::mutex> lock(mutex_);
  countLost(counters_.dropped_no_transform);
  dropped_frame_ = msg->header.frame_id;
  ROS_WARN_STREAM_THROTTLE(kWarnThrottle, "fusion: scan at " << msg->header.stamp << " dropped: " << reasonName(reason)
                                                             << " (" << node_params_.map_frame << " <- "
                                                             << msg->header.frame_id << "); "
                                                             << counters_.dropped_no_transform << " dropped so far");
}

void FusionWorker::onScanIn(const EvidentialGrid::ConstPtr& msg)
{
  checkClock();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const double stamp = msg->header.stamp.toSec();
    if (stamp <= 0.0)
    {
      countLost(counters_.zero_stamp);
      ROS_WARN_STREAM_THROTTLE(kWarnThrottle, "fusion: scan stamped 0 dropped (no pose can be looked up for it); "
                                                  << counters_.zero_stamp << " so far");
      return;
    }
    const AheadOfClock ahead = aheadOfClock(stamp);
    if (ahead.too_far)
    {
      countLost(counters_.future_stamp);
      ROS_WARN_STREAM_THROTTLE(kWarnThrottle, "fusion: scan stamped " << msg->header.stamp << ", " << ahead.seconds
                                                                     << " s ahead of the clock (future_tolerance "
                                                                     << node_params_.future_tolerance << " s"
                                                                     << (ahead.after_jump ? ", after a backward clock jump" : "")
                                                                     << "), dropped; " << counters_.future_stamp
                                                                     << " so far");
      return;
    }
    if (!msg->header.frame_id.empty() && !tf_buffer_._frameExists(msg->header.frame_id))
      ROS_WARN_STREAM_THROTTLE(kWarnThrottle, "fusion: frame '" << msg->header.frame_id
                                                                << "' of scan_grid is unknown to tf so far; the scan "
                                                                   "waits for a transform to "
                                                                << node_params_.map_frame);
  }
  scan_filter_->add(msg);
}

void FusionWorker::resetForTimeJump(const std::string& why)
{
  ROS_WARN_STREAM("fusion: " << why << "; resetting the MapGrid and clearing the tf buffer");
  grid_.reset();
  if (tracker_)
  {
    tracker_->reset();
    tracker_resets_seen_ = tracker_->counts().resets;
    tracker_resets_window_.add(core::steadySeconds());
  }
  stamp_guard_.reset();
  last_pose_.reset();
  shifted_stamp_.reset();
  tf_buffer_.clear();
  ++counters_.resets;
  ++counters_.tf_clears;
  last_jump_wall_ = core::steadySeconds();
}

void FusionWorker::checkClock()
{
  const ros::Time now = ros::Time::now();
  if (now.isZero()) return;
  std::string frame;
  bool jumped = false;
  double watch = node_params_.future_tolerance;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    jumped = clock_jump_.observe(now.toSec());
    if (jumped)
    {
      std::ostringstream why;
      why << "ROS time went back by more than time_jump_threshold (" << node_params_.time.time_jump_threshold
          << " s) to " << now;
      resetForTimeJump(why.str());
    }
    frame = last_scan_frame_;
    if (core::steadySeconds() - last_jump_wall_ < core::kAfterJumpWatch)
      watch = std::min(watch, node_params_.time.time_jump_threshold);
  }
  if (jumped)
  {
    scan_filter_->clear();  // scans of before the jump still waiting for their transform
    return;
  }
  if (frame.empty()) return;
  // After a jump, transforms of the previous loop may still arrive; tf2 would then ignore the new loop's
  // transforms as too old. Transforms ahead of the clock by more than time_jump_threshold soon after a jump, or by
  // more than future_tolerance at any time, are from the past loop; a clock that merely lags keeps its tf.
  ros::Time latest;
  try
  {
    latest = tf_buffer_.lookupTransform(node_params_.map_frame, frame, ros::Time(0)).header.stamp;
  }
  catch (const tf2::TransformException&)
  {
    return;
  }
  if ((latest - now).toSec() > watch)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ROS_WARN_STREAM("fusion: the tf buffer holds " << node_params_.map_frame << " <- " << frame << " at " << latest
                                                  << ", ahead of the clock (" << now
                                                  << "): transforms of before a time jump; cleared");
    tf_buffer_.clear();
    ++counters_.tf_clears;
  }
}

void FusionWorker::LatencyWindows::setSpan(double span)
{
  for (core::SlidingSamples* w : { &conversion, &shift, &shift_ahead, &project_scan, &prior_window, &fusion, &tracking,
                                   &outputs, &skipped, &changing })
    w->setSpan(span);
  cloud_to_callback.setSpan(span);
  cloud_to_decision.setSpan(span);
}

FusionWorker::AheadOfClock FusionWorker::aheadOfClock(double stamp) const
{
  const ros::Time now = ros::Time::now();
  AheadOfClock a;
  a.clock_started = !now.isZero();
  a.seconds = a.clock_started ? stamp - now.toSec() : 0.0;
  a.after_jump = core::steadySeconds() - last_jump_wall_ < core::kAfterJumpWatch;
  a.too_far = a.seconds > node_params_.future_tolerance ||
              (a.after_jump && a.seconds > node_params_.time.time_jump_threshold);
  return a;
}

void FusionWorker::onScanStarted(const std_msgs::Header::ConstPtr& header)
{
  const double stamp = header->stamp.toSec();
  double x = std::numeric_limits<double>::quiet_NaN(), y = x;
  if (stamp > 0.0 && tf_buffer_.canTransform(node_params_.map_frame, header->frame_id, header->stamp))
  {
    try
    {
      const geometry_msgs::Transform t =
          tf_buffer_.lookupTransform(node_params_.map_frame, header->frame_id, header->stamp).transform;
      x = t.translation.x;
      y = t.translation.y;
    }
    catch (const tf2::TransformException&)
    {
    }
  }
  std::lock_guard<std::mutex> lock(mutex_);
  // A scan with new parameters changes the window's geometry: its own update shifts it (not a refusal).
  if (pending_params_) return;
  core::StartedReference ref;
  if (last_pose_ && stamp_guard_.last())
  {
    ref.frame = fused_frame_;
    ref.fused_stamp = *stamp_guard_.last();
    ref.fused_x = last_pose_->x;
    ref.fused_y = last_pose_->y;
    ref.shifted_stamp = shifted_stamp_;
  }
  const AheadOfClock ahead = aheadOfClock(stamp);
  const core::StartedVerdict verdict = core::checkStarted(ref, header->frame_id, stamp, !ahead.too_far, x, y,
                                                          node_params_.time);
  if (verdict == core::StartedVerdict::kNoScanYet) return;
  if (verdict != core::StartedVerdict::kShift)
  {
    ++counters_.started_refused[static_cast<std::size_t>(verdict)];
    started_refused_window_.add(core::steadySeconds());
    ROS_WARN_STREAM_THROTTLE(kWarnThrottle, "fusion: scan_grid/started in '" << header->frame_id << "' at "
                                                                            << header->stamp << " refused ("
                                                                            << core::toString(verdict)
                                                                            << "): the window stays; fused scans are in '"
                                                                            << ref.frame << "'");
    return;
  }
  const auto t0 = std::chrono::steady_clock::now();
  shifted_stamp_ = stamp;
  if (grid_.follow(core::Point2{ x, y })) ++counters_.shifts_ahead;
  const std::chrono::duration<double> took = std::chrono::steady_clock::now() - t0;
  latency_.shift_ahead.add(core::steadySeconds(), kMillisecondsPerSecond * took.count());
}

void FusionWorker::onScan(const EvidentialGrid::ConstPtr& msg)
{
  ScanTimes times;
  times.start = std::chrono::steady_clock::now();
  times.cloud_age_ms = kMillisecondsPerSecond * (ros::Time::now() - msg->header.stamp).toSec();
  // Reused from scan to scan (one per callback thread): no 10 MB allocation, page faults and zeroing per scan.
  thread_local core::ScanMassGrid scan;
  if (!convertScan(*msg, scan)) return;
  const std::optional<core::Pose2> pose = scanPose(*msg);
  if (!pose) return;

  std::lock_guard<std::mutex> lock(mutex_);
  last_scan_frame_ = msg->header.frame_id;
  if (pending_params_)
  {
    grid_.setParams(*pending_params_);
    pending_params_.reset();
  }
  const double stamp = msg->header.stamp.toSec();
  if (!admitStamp(msg->header.stamp)) return;
  warnPoseJump(*pose, stamp);
  const core::PriorWindow* prior = softenedPrior();
  if (!prior && !warned_no_prior_)
  {
    ROS_INFO("fusion: no prior_grid received yet: fusing with a vacuous prior");
    warned_no_prior_ = true;
  }
  const core::ObstaclePoints obstacles{ msg->obstacle_points.data(), msg->obstacle_points.size() / 2 };
  times.update = std::chrono::steady_clock::now();
  const auto stats =
      grid_.update(scan, *pose, stamp, prior, &times.stages, msg->obstacle_points.empty() ? nullptr : &obstacles);
  stamp_guard_.accept(stamp);
  last_pose_ = *pose;
  fused_frame_ = msg->header.frame_id;
  shifted_stamp_.reset();
  ++counters_.fused;
  last_fused_wall_ = core::steadySeconds();
  fused_window_.add(last_fused_wall_);
  last_times_ = times.stages;
  last_mean_conflict_ = stats.meanConflict();

  std_msgs::Header header;
  header.stamp = msg->header.stamp;
  header.frame_id = node_params_.map_frame;
  times.tracking = std::chrono::steady_clock::now();
  if (tracker_) track(header, stamp, *pose, obstacles, scan, prior);
  times.outputs = std::chrono::steady_clock::now();
  publish(header, prior);
  recordLatency(times, msg->header.stamp);
}

bool FusionWorker::convertScan(const EvidentialGrid& msg, core::ScanMassGrid& scan)
{
  try
  {
    GridConversions::scanFromMessage(msg, scan);
    if (msg.obstacle_points.size() % 2 != 0)
      throw ConversionError("obstacle_points holds an odd number of coordinates");
    for (const float v : msg.obstacle_points)
      if (!std::isfinite(v)) throw ConversionError("obstacle_points holds a non-finite coordinate");
  }
  catch (const ConversionError& e)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    countLost(counters_.rejected);
    ROS_ERROR_STREAM_THROTTLE(kWarnThrottle, "fusion: scan_grid rejected (" << counters_.rejected
                                                                            << " so far): " << e.what());
    return false;
  }
  return true;
}

std::optional<core::Pose2> FusionWorker::scanPose(const EvidentialGrid& msg)
{
  geometry_msgs::TransformStamped tf;
  try
  {
    tf = tf_buffer_.lookupTransform(node_params_.map_frame, msg.header.frame_id, msg.header.stamp);
  }
  catch (const tf2::TransformException& e)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    countLost(counters_.dropped_no_transform);
    ROS_WARN_STREAM_THROTTLE(kWarnThrottle, "fusion: scan dropped: " << e.what());
    return std::nullopt;
  }
  core::Pose2 pose;
  pose.x = tf.transform.translation.x;
  pose.y = tf.transform.translation.y;
  pose.yaw = tf2::getYaw(tf.transform.rotation);
  if (!std::isfinite(pose.x) || !std::isfinite(pose.y) || !std::isfinite(pose.yaw))
  {
    std::lock_guard<std::mutex> lock(mutex_);
    countLost(counters_.rejected);
    ROS_ERROR_STREAM_THROTTLE(kWarnThrottle, "fusion: scan dropped: the transform " << node_params_.map_frame << " <- "
                                                                                    << msg.header.frame_id
                                                                                    << " is not finite");
    return std::nullopt;
  }
  return pose;
}

bool FusionWorker::admitStamp(const ros::Time& header_stamp)
{
  const double stamp = header_stamp.toSec();
  // checkClock() watches ROS time and resets the guard when it goes back; before the first clock value, stamps decide.
  switch (stamp_guard_.check(stamp, !ros::Time::now().isZero()))
  {
    case core::StampVerdict::kFuse:
      break;
    case core::StampVerdict::kZeroStamp:
      countLost(counters_.zero_stamp);
      return false;
    case core::StampVerdict::kDuplicate:
      countLost(counters_.duplicate);
      ROS_WARN_STREAM_THROTTLE(kWarnThrottle, "fusion: scan stamped " << header_stamp
                                                                     << " again (already fused), dropped; "
                                                                     << counters_.duplicate << " so far");
      return false;
    case core::StampVerdict::kOutOfOrder:
      countLost(counters_.out_of_order);
      ROS_WARN_STREAM_THROTTLE(kWarnThrottle, "fusion: scan stamped " << header_stamp << " is "
                                                                     << *stamp_guard_.last() - stamp
                                                                     << " s older than the last fused scan, dropped "
                                                                        "(out of order); "
                                                                     << counters_.out_of_order << " so far");
      return false;
    case core::StampVerdict::kLate:
      if (stamp_guard_.lateRun(core::steadySeconds()))
      {
        std::ostringstream why;
        why << "scans have stayed older than the last fused one (" << std::fixed << *stamp_guard_.last() << " s, now "
            << stamp << " s) for more than time_jump_threshold (" << node_params_.time.time_jump_threshold
            << " s) of wall time: the data's time went back without the clock";
        resetForTimeJump(why.str());
        break;
      }
      countLost(counters_.late);
      ROS_WARN_STREAM_THROTTLE(kWarnThrottle, "fusion: scan stamped " << header_stamp << " is "
                                                                     << *stamp_guard_.last() - stamp
                                                                     << " s older than the last fused scan while the "
                                                                        "clock did not go back: released late (after "
                                                                        "a tf gap), dropped; "
                                                                     << counters_.late << " so far");
      return false;
    case core::StampVerdict::kTimeJump: {
      std::ostringstream why;
      why << "scan time went back from " << std::fixed << *stamp_guard_.last() << " to " << stamp
          << " s, more than time_jump_threshold (" << node_params_.time.time_jump_threshold << " s)";
      resetForTimeJump(why.str());
      break;
    }
  }
  return true;
}

void FusionWorker::warnPoseJump(const core::Pose2& pose, double stamp)
{
  if (last_pose_)
  {
    const double last_stamp = *stamp_guard_.last();  // set with last_pose_, reset with it
    const core::PoseJump j = core::checkPoseJump(last_pose_->x, last_pose_->y, last_stamp, pose.x, pose.y, stamp,
                                                 node_params_.time.max_plausible_speed);
    if (j.jumped)
    {
      ++counters_.pose_jumps;
      ROS_WARN_STREAM("fusion: the vehicle moved " << j.distance << " m in " << stamp - last_stamp << " s ("
                                                   << j.speed << " m/s, max_plausible_speed "
                                                   << node_params_.time.max_plausible_speed
                                                   << "): a localisation jump? Evidence is kept where the window "
                                                      "still covers it");
    }
  }
}

void FusionWorker::recordLatency(const ScanTimes& times, const ros::Time& header_stamp)
{
  const auto end = std::chrono::steady_clock::now();
  last_total_seconds_ = std::chrono::duration<double>(end - times.start).count();
  const auto ms = [](auto a, auto b) { return kMillisecondsPerSecond * std::chrono::duration<double>(b - a).count(); };
  const double now = last_fused_wall_;
  latency_.cloud_to_callback.add(now, times.cloud_age_ms);
  latency_.cloud_to_decision.add(now, kMillisecondsPerSecond * (ros::Time::now() - header_stamp).toSec());
  latency_.conversion.add(now, ms(times.start, times.update));
  latency_.shift.add(now, kMillisecondsPerSecond * times.stages.shift);
  latency_.project_scan.add(now, kMillisecondsPerSecond * times.stages.project_scan);
  latency_.prior_window.add(now, kMillisecondsPerSecond * times.stages.prior_window);
  latency_.fusion.add(now, kMillisecondsPerSecond * times.stages.fusion);
  latency_.skipped.add(now, grid_.skippedShare());
  if (!std::isnan(grid_.changingShare())) latency_.changing.add(now, grid_.changingShare());
  latency_.tracking.add(now, ms(times.tracking, times.outputs));
  latency_.outputs.add(now, ms(times.outputs, end));
}

void FusionWorker::publish(const std_msgs::Header& header, const core::PriorWindow* prior)
{
  const auto& grid = grid_.masses();
  if (map_grid_pub_.getNumSubscribers() > 0)
  {
    auto out = boost::make_shared<EvidentialGrid>();
    GridConversions::toMessage(grid, header, *out, PlaneSelection::kNonZero, true);
    map_grid_pub_.publish(out);
  }
  bool need_betp = decision_pub_.getNumSubscribers() + navigable_pub_.getNumSubscribers() + cells_pub_.getNumSubscribers() + objects_pub_.getNumSubscribers() > 0;
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
  const std::vector<std::int8_t>& decision = grid_.decisions();
  const auto publishLayer = [&](ros::Publisher& pub, const std::vector<std::int8_t>& data) {
    auto occ = boost::make_shared<nav_msgs::OccupancyGrid>();
    occ->header = header;
    GridConversions::toMapMetaData(grid.geometry(), occ->info);
    occ->info.map_load_time = header.stamp;
    occ->data = data;
    pub.publish(occ);
  };
  if (decision_pub_.getNumSubscribers() > 0) publishLayer(decision_pub_, decision);
  if (navigable_pub_.getNumSubscribers() > 0)
  {
    std::vector<std::int8_t> navigable;
    core::PriorWindow prior_window;
    grid_.priorWindow(prior, prior_window);
    core::navigableLayer(decision, prior_window, navigable);
    publishLayer(navigable_pub_, navigable);
  }
  if (cells_pub_.getNumSubscribers() > 0)
  {
    auto cells = boost::make_shared<visualization_msgs::MarkerArray>();
    Visualization::decisionToCells(grid.geometry(), decision, header, node_params_.publish_free_cells, *cells);
    cells_pub_.publish(cells);
  }
  if (objects_pub_.getNumSubscribers() > 0)
  {
    auto markers = boost::make_shared<visualization_msgs::MarkerArray>();
    const auto objects = core::extractObjects(grid.geometry(), decision, betp, grid_.params());
    Visualization::objectsToMarkers(objects, header, node_params_.object_box_height, *markers);
    objects_pub_.publish(markers);
  }
}

void FusionWorker::track(const std_msgs::Header& header, double stamp, const core::Pose2& pose,
                          const core::ObstaclePoints& returns, const core::ScanMassGrid& scan,
                          const core::PriorWindow* prior)
{
  const core::TrackerCounts before = tracker_->counts();
  core::trackScan(*tracker_, grid_, stamp, pose, returns, background_, &scan, prior);
  const core::TrackerCounts& after = tracker_->counts();
  if (after.measurements_dropped > before.measurements_dropped || after.tracks_refused > before.tracks_refused)
  {
    tracker_bounded_window_.add(core::steadySeconds());
    ROS_WARN_STREAM_THROTTLE(kWarnThrottle, "fusion: clutter: the tracker dropped "
                                                << after.measurements_dropped - before.measurements_dropped
                                                << " measurements over tracker_max_measurements ("
                                                << tracker_->params().max_measurements << ") and left "
                                                << after.tracks_refused - before.tracks_refused
                                                << " clusters untracked over tracker_max_tracks ("
                                                << tracker_->params().max_tracks << ") in this scan");
  }
  if (tracker_->counts().resets > tracker_resets_seen_)
  {
    tracker_resets_seen_ = tracker_->counts().resets;
    tracker_resets_window_.add(core::steadySeconds());
    ROS_WARN("fusion: every track dropped (time went back or the vehicle pose jumped)");
  }
  last_tracks_ = last_moving_tracks_ = last_held_back_tracks_ = 0;
  for (const core::Track& t : tracker_->tracks())
  {
    last_tracks_ += t.published();
    last_moving_tracks_ += t.published() && t.motion == core::TrackMotion::kMoving;
    last_held_back_tracks_ += t.reported() && !t.published();
  }
  if (tracks_pub_.getNumSubscribers() + tracks_markers_pub_.getNumSubscribers() == 0) return;
  auto tracks = boost::make_shared<TrackedObjectArray>();
  Visualization::tracksToMessage(tracker_->tracks(), header, stamp, node_params_.object_box_height, *tracks,
                                 core::reportedBoxes(*tracker_));
  if (tracks_markers_pub_.getNumSubscribers() > 0)
  {
    auto markers = boost::make_shared<visualization_msgs::MarkerArray>();
    Visualization::tracksToMarkers(*tracks, *markers);
    tracks_markers_pub_.publish(markers);
  }
  tracks_pub_.publish(tracks);
}

void FusionWorker::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status)
{
  std::lock_guard<std::mutex> lock(mutex_);
  const double now = core::steadySeconds();
  const core::StreamHealthParams& h = node_params_.health;
  const std::size_t fused = fused_window_.count(now);
  const std::size_t lost = lost_window_.count(now);
  const double last = counters_.fused > 0 ? last_fused_wall_ : now;
  core::HealthSummary summary = core::streamHealth(h, counters_.fused > 0, now - last, fused, lost, "scans fused");
  if (counters_.fused == 0)
  {
    // Say what is waited for: the scan grid topic, or the transform of the scans that came.
    if (counters_.dropped_no_transform == 0)
      summary.message = "no scan fused yet: waiting for " + scan_sub_.getTopic() + " (" +
                        std::to_string(scan_sub_.getNumPublishers()) + " publishers)";
    else
      summary.message = "no scan fused yet: " + std::to_string(counters_.dropped_no_transform) +
                        " dropped for want of the transform " + node_params_.map_frame + " <- " +
                        (dropped_frame_.empty() ? std::string("the scans' frame") : dropped_frame_) +
                        " (is the localisation publishing tf?)";
    if (now - start_wall_ >= h.stale_error && counters_.dropped_no_transform > 0)
      summary.level = core::HealthLevel::kError;
  }
  // Inputs refused or bounded in the window warn, on top of the stream's own health.
  const auto warn = [&](std::size_t n, const std::string& what) {
    if (n == 0) return;
    if (summary.level == core::HealthLevel::kOk) summary.level = core::HealthLevel::kWarn;
    summary.message += "; " + std::to_string(n) + " " + what + " in the window";
  };
  warn(started_refused_window_.count(now), "scan_grid/started headers refused (see keys)");
  warn(tracker_bounded_window_.count(now), "scans over the tracker's bounds (clutter)");
  status.summary(static_cast<unsigned char>(summary.level), summary.message);
  diagnoseCounters(status, now);
  diagnoseLatency(status, now);
  diagnosePrior(status, now);
  if (tracker_) diagnoseTracker(status, now);
}

void FusionWorker::diagnoseCounters(diagnostic_updater::DiagnosticStatusWrapper& status, double now)
{
  const core::StreamHealthParams& h = node_params_.health;
  const std::size_t fused = fused_window_.count(now);
  const double last = counters_.fused > 0 ? last_fused_wall_ : now;
  status.add("scan rate [Hz]", fused_window_.rate(now, start_wall_));
  status.add("scans fused in window", fused);
  status.add("scans dropped or rejected in window", lost_window_.count(now));
  status.add("window [s]", h.diagnostic_window);
  status.add("seconds since last fused scan", counters_.fused > 0 ? now - last : -1.0);
  status.add("scans fused", counters_.fused);
  status.add("scans dropped (no transform)", counters_.dropped_no_transform);
  status.add("scans rejected (malformed)", counters_.rejected);
  status.add("scans dropped (zero stamp)", counters_.zero_stamp);
  status.add("scans dropped (future stamp)", counters_.future_stamp);
  status.add("scans dropped (out of order)", counters_.out_of_order);
  status.add("scans dropped (duplicate stamp)", counters_.duplicate);
  status.add("scans dropped (released late)", counters_.late);
  status.add("grid resets (time jump)", counters_.resets);
  status.add("tf buffer clears", counters_.tf_clears);
  status.add("pose jumps", counters_.pose_jumps);
  status.add("reconfigure refused", counters_.reconfigure_refused);
  status.add("last reconfigure", last_reconfigure_);
  status.add("time shift [ms]", 1e3 * last_times_.shift);
  status.add("time project scan [ms]", 1e3 * last_times_.project_scan);
  status.add("time prior window [ms]", 1e3 * last_times_.prior_window);
  status.add("time fusion [ms]", 1e3 * last_times_.fusion);
  status.add("time total with outputs [ms]", 1e3 * last_total_seconds_);
}

void FusionWorker::diagnoseLatency(diagnostic_updater::DiagnosticStatusWrapper& status, double now)
{
  // Over the window: where a scan's time goes, from the cloud's stamp to its decision.
  const auto quantiles = [&](const std::string& name, auto& w) {
    for (const auto& [q, label] : { std::pair<double, const char*>{ 0.5, " median [ms]" }, { 0.9, " p90 [ms]" } })
    {
      const double v = w.quantile(now, q);
      if (std::isnan(v))
        status.add(name + label, "none");
      else
        status.add(name + label, v);
    }
  };
  quantiles("latency cloud to fusion callback", latency_.cloud_to_callback);
  quantiles("latency cloud to decision", latency_.cloud_to_decision);
  // A stamp ahead of a lagging clock has no latency: counted here, not as a negative one.
  status.add("scans stamped ahead of the clock in window", latency_.cloud_to_decision.aheadOfClock(now));
  const double lead = latency_.cloud_to_decision.largestLead(now);
  if (std::isnan(lead))
    status.add("largest lead of a stamp over the clock [ms]", "none");
  else
    status.add("largest lead of a stamp over the clock [ms]", lead);
  quantiles("stage conversion", latency_.conversion);
  quantiles("stage shift", latency_.shift);
  quantiles("stage shift ahead", latency_.shift_ahead);
  quantiles("stage project scan", latency_.project_scan);
  quantiles("stage prior window", latency_.prior_window);
  quantiles("stage fusion step", latency_.fusion);
  quantiles("stage tracking", latency_.tracking);
  quantiles("stage outputs", latency_.outputs);
  for (const auto& [key, samples] : { std::pair{ "cells skipped (skip_unchanged) median [share]", &latency_.skipped },
                                      std::pair{ "cells changing unobserved (skip_unchanged) median [share]",
                                                 &latency_.changing } })
  {
    const double share = samples->quantile(now, 0.5);
    if (std::isnan(share))
      status.add(key, "none");
    else
      status.add(key, share);
  }
}

void FusionWorker::diagnosePrior(diagnostic_updater::DiagnosticStatusWrapper& status, double now)
{
  status.add("mean conflict", last_mean_conflict_);
  status.add("memory [MiB]", grid_.params().bytesNeeded() / (1024.0 * 1024.0));
  status.add("prior", softener_.raw() ? "received" : "none (vacuous)");
  const bool covariance_fresh =
      !std::isnan(covariance_sigma_) && now - last_covariance_wall_ <= node_params_.health.diagnostic_window;
  status.add("position sigma in force [m]", softener_.sigmaInForce());
  status.add("position sigma source",
             node_params_.pose_covariance_topic.empty() ? std::string("position_sigma parameter")
             : std::isnan(covariance_sigma_)            ? "position_sigma parameter (no covariance received yet)"
             : covariance_fresh ? "covariance on " + node_params_.pose_covariance_topic
                                : "last covariance on " + node_params_.pose_covariance_topic + " (stale)");
  status.add("covariances rejected in window", covariance_rejected_window_.count(now));
  status.add("covariances rejected", counters_.covariance_rejected);
  status.add("sigma clamped (over the bound)", counters_.sigma_clamped);
  status.add("prior softenings", counters_.prior_softenings);
  status.add("window shifts ahead (shift_ahead)", counters_.shifts_ahead);
  status.add("started headers refused in window", started_refused_window_.count(now));
  for (std::size_t v = 0; v < kStartedVerdicts; ++v)
  {
    const auto verdict = static_cast<core::StartedVerdict>(v);
    if (verdict == core::StartedVerdict::kShift || verdict == core::StartedVerdict::kNoScanYet) continue;
    status.add(std::string("started headers refused (") + core::toString(verdict) + ")", counters_.started_refused[v]);
  }
  status.add("tracker", tracker_ ? "on" : "off");
}

void FusionWorker::diagnoseTracker(diagnostic_updater::DiagnosticStatusWrapper& status, double now)
{
  {
    const core::TrackerCounts& c = tracker_->counts();
    status.add("tracks (last scan)", last_tracks_);
    status.add("moving tracks (last scan)", last_moving_tracks_);
    status.add("tracks held back (last scan; born before the counter could mark static background)",
               last_held_back_tracks_);
    status.add("tracker resets in window", tracker_resets_window_.count(now));
    status.add("tracker resets", c.resets);
    status.add("tracks deleted (non-finite or too fast)", c.rejected_tracks);
    status.add("clusters not tracked (fragments of a moving track)", c.fragments);
    status.add("tracks deleted (duplicates of a moving track)", c.duplicates);
    if (tracker_->hasCommonMotion())
    {
      std::ostringstream v;
      v << std::fixed << std::setprecision(2) << tracker_->commonMotion().x << ", " << tracker_->commonMotion().y;
      status.add("common motion (last scan) [m/s]", v.str());
    }
    else
      status.add("common motion (last scan) [m/s]", "none");
    status.add("scans with a common motion", c.common_motion_scans);
    {
      std::ostringstream w;
      w << std::fixed << std::setprecision(2) << tracker_->commonTurnRate() * 180.0 / M_PI;
      status.add("common motion's turn rate (last scan) [deg/s]", w.str());
    }
    status.add("scans whose common motion turns", c.common_turn_scans);
    status.add("tracks whose motion was seen by the distance they walked", c.walked);
    status.add("new tracks whose box took their second cluster's axes", c.second_axes);
    status.add("boxes turned to a long cluster's axis", c.long_box);
    status.add("associations with a cluster whose ends were hidden (track not yet moving)", c.hidden_ends);
    status.add("measurements whose fitted box turned off their principal axes", c.box_fit);
    status.add("associations with a cluster placed by its open end", c.open_anchor);
    status.add("associations placed by an open end whose growth at the other end left their sigma", c.far_growth);
    status.add("measurements split off static background", c.split_measurements);
    status.add("tracker inputs skipped (non-finite)", c.non_finite_inputs);
    status.add("scans over the tracker's bounds in window", tracker_bounded_window_.count(now));
    status.add("measurements dropped (over tracker_max_measurements)", c.measurements_dropped);
    status.add("clusters not tracked (over tracker_max_tracks)", c.tracks_refused);
    status.add("most measurements in one scan", c.peak_measurements);
    status.add("most tracks after one scan", c.peak_tracks);
  }
}

}  // namespace map_aided_fusion

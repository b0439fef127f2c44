/**
 * @file scan_grid_worker.hpp
 * @brief The ScanGrid node's worker, shared by ScanGridNodelet and the plain scan_grid_node.
 *
 * Subscribes `points` (sensor_msgs/PointCloud2 with float32 x, y, z in any layout), waits with a
 * tf2_ros::MessageFilter until base_frame ← cloud frame is known at the cloud's stamp, builds the
 * ScanGrid (core::ScanGridBuilder) and publishes `scan_grid` (map_aided_fusion/EvidentialGrid, classes
 * [F, O], frame base_frame, stamp = cloud stamp; zero-copy inside a nodelet manager) and
 * `scan_grid/occupancy` (nav_msgs/OccupancyGrid, round(100·BetP(O)), −1 where vacuous).
 * Unreadable clouds are rejected with one error per reason, then counted; diagnostic_updater reports
 * the input rate, the processing time and the rejected clouds and points.
 */
#pragma once

#include <cstddef>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>

#include <diagnostic_updater/diagnostic_updater.h>
#include <dynamic_reconfigure/server.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_msgs/Header.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/message_filter.h>
#include <tf2_ros/transform_listener.h>

#include "map_aided_fusion/ScanGridConfig.h"
#include "map_aided_fusion/core/input_health.hpp"
#include "map_aided_fusion/core/scan_grid.hpp"
#include "map_aided_fusion/core/sliding_window.hpp"
#include "map_aided_fusion/core/stamp_guard.hpp"
#include "map_aided_fusion/ros/cloud_deskew.hpp"
#include "map_aided_fusion/ros/startup_failure.hpp"

namespace map_aided_fusion {

/// Everything the node reads from its private namespace (config/scan_grid.yaml).
struct ScanGridNodeParams
{
  std::string base_frame = "base_link";  ///< frame of the published grids
  int input_queue_size = 2;              ///< clouds waiting to be built: older ones are dropped and counted (≥ 1)
  int tf_queue_size = 10;                ///< clouds waiting for their transform (≥ 1)
  /// s a cloud may be stamped ahead of the clock (a late /clock is waited for), [0, 3600]
  double future_tolerance = 10.0;
  double time_jump_threshold = 1.0;      ///< s ROS time must go back by to count as a jump (tf buffer cleared)
  core::StreamHealthParams health;       ///< diagnostic period, window and staleness
  core::InputHealthParams input;         ///< blind clouds and lost inputs
  core::ScanGridParams model;            ///< sensor model and grid, see core::ScanGridParams
  std::string deskew_fixed_frame = "map";  ///< frame the vehicle moves in, for the sweep's motion (odom on a vehicle)
  std::string deskew_time_field = "auto";  ///< per-point time field, or auto (see knownTimeFields())

  /// @throws core::ParameterError naming the first bad parameter.
  void validate() const;
  /**
   * @brief Reads every parameter from @p pnh, keeping the defaults above for absent ones.
   * @throws core::ParameterError for a parameter of the wrong type or out of range.
   */
  static ScanGridNodeParams load(const ros::NodeHandle& pnh);
};

/// Calls get(name, field, doc) for every parameter of @p p, with the names of config/scan_grid.yaml.
template <class Get>
void forEachParam(ScanGridNodeParams& p, Get&& get)
{
  get("base_frame", p.base_frame, { "", "vehicle frame of the published grids" });
  get("input_queue_size", p.input_queue_size, { "clouds", "clouds waiting to be built; older ones are dropped and counted" });
  get("tf_queue_size", p.tf_queue_size, { "clouds", "clouds waiting for their transform" });
  get("future_tolerance", p.future_tolerance, { "s", "a cloud may be stamped this far ahead of a lagging clock" });
  get("time_jump_threshold", p.time_jump_threshold, { "s", "ROS time going back by more than this is a jump (tf buffer cleared)" });
  get("deskew_fixed_frame", p.deskew_fixed_frame, { "", "frame the vehicle moves in, for a sweep's motion (odom on a vehicle)" });
  get("deskew_time_field", p.deskew_time_field, { "", "per-point time field, or auto" });
  core::forEachParam(p.health, get);
  core::forEachParam(p.input, get);
  core::forEachParam(p.model, get);
}

/// Counters since start, reported by the diagnostics.
struct ScanGridNodeCounters
{
  std::size_t clouds_received = 0;
  std::size_t clouds_published = 0;
  std::size_t clouds_rejected = 0;    ///< unreadable, no transform, bad transform, or blind
  std::size_t clouds_skipped = 0;     ///< nobody subscribed
  std::size_t points_rejected = 0;    ///< invalid returns in processed clouds (see core::ScanGridStats)
  std::map<std::string, std::size_t> rejections;  ///< clouds rejected, by reason
};

/// The ScanGrid node. Construct it with the node's public and private handles; it runs until destroyed.
class ScanGridWorker
{
public:
  ScanGridWorker(ros::NodeHandle nh, ros::NodeHandle pnh);
  ~ScanGridWorker();
  ScanGridWorker(const ScanGridWorker&) = delete;
  ScanGridWorker& operator=(const ScanGridWorker&) = delete;

  /// False when the parameters were rejected: the worker then subscribes and publishes nothing.
  bool active() const { return active_; }

private:
  void onCloud(const sensor_msgs::PointCloud2ConstPtr& cloud);
  void onCloudWithTransform(const sensor_msgs::PointCloud2ConstPtr& cloud);
  /// Takes @p cloud off the backlog; false (counted as lost in the input queue) when input_queue_size newer clouds
  /// wait behind it, so that an overloaded node drops its oldest clouds instead of falling ever further behind.
  bool takePendingBuild(const sensor_msgs::PointCloud2& cloud);
  void onTransformFailure(const sensor_msgs::PointCloud2ConstPtr& cloud,
                          tf2_ros::filter_failure_reasons::FilterFailureReason reason);
  void onReconfigure(ScanGridConfig& config, std::uint32_t level);
  void checkClock();
  void reject(const std::string& reason, const std::string& detail);
  /// True (counted, not fused) when the cloud has too few valid returns. Caller holds mutex_.
  bool blindCloud(const core::ScanGridStats& stats);
  /// A view of the cloud's x, y, z; false (rejected and counted) when the cloud cannot be read. Caller holds mutex_.
  bool viewOf(const sensor_msgs::PointCloud2& cloud, core::PointCloudView& view);
  /// The sensor's pose in base_frame at the cloud's stamp given to the builder; false (rejected and counted) when tf
  /// has none or it is no rigid transform. Caller holds mutex_.
  bool setSensorPose(const sensor_msgs::PointCloud2& cloud);
  /// Counts a cloud's deskew outcome; the first cloud skipped for a reason is WARNed. Caller holds mutex_.
  void noteDeskew(const DeskewResult& deskew);
  /// The ScanGrid (with its obstacle returns) and its occupancy view, to their subscribers. Caller holds mutex_.
  void publishGrid(const std_msgs::Header& header);
  /// Counts a published cloud: rates, processing time since @p start, latency from @p stamp, overruns.
  void recordPublished(const ros::WallTime& start, const ros::Time& stamp);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);
  /// diagnose()'s parts, caller holds mutex_: the level and message (returns what the input checks found), the
  /// stream's rates, losses and latencies in the window, and the totals with the last cloud's figures.
  core::InputFindings diagnoseSummary(diagnostic_updater::DiagnosticStatusWrapper& status, double now);
  void diagnoseStream(diagnostic_updater::DiagnosticStatusWrapper& status, double now, const core::InputFindings& found);
  void diagnoseTotals(diagnostic_updater::DiagnosticStatusWrapper& status, double now);

  ros::NodeHandle nh_, pnh_;
  ScanGridNodeParams params_;
  bool active_ = false;

  std::mutex mutex_;
  core::ScanGridBuilder builder_;
  core::ScanMassGrid grid_;
  ScanGridNodeCounters counters_;
  std::set<std::string> reported_;  // rejection reasons already logged as errors
  std::string last_rejection_;      // "reason: detail" of the last rejected cloud
  CloudDeskewer deskewer_;
  std::map<std::string, std::size_t> deskew_counts_;  // clouds by deskew status, since start
  std::set<std::string> deskew_warned_;               // skip reasons already warned about
  std::string last_deskew_ = "none";
  std::size_t ground_flat_fallbacks_ = 0;             // scans whose ground model fell back to flat

  // Diagnostics over the last health.diagnostic_window seconds (wall time).
  core::SlidingCounter received_window_, published_window_, rejected_window_, deskew_skipped_window_,
      ground_fallback_window_;
  /// ms over the window: building a cloud's grid, and the cloud's age when its grid is published.
  core::SlidingSamples processing_samples_;
  core::LatencyWindow cloud_to_published_;  ///< latencies; clouds stamped ahead of the clock counted apart
  double window_processing_sum_ = 0.0;
  double window_processing_max_ = 0.0;
  std::size_t window_processed_ = 0;
  double start_wall_ = 0.0;
  double last_published_wall_ = 0.0;
  core::ScanGridStats last_stats_;
  core::ClockJumpDetector clock_jump_;
  /// Steady time of the last backward clock jump (clouds ahead of the clock soon after it are of before it).
  double last_jump_wall_ = -1e9;
  std::size_t tf_clears_ = 0;
  core::BlindSpell blind_;
  std::string last_blind_reason_;
  core::InputGapCounter gaps_;
  core::SlidingCounter lost_window_, overrun_window_, stream_gap_window_;
  std::size_t clouds_lost_ = 0, overruns_ = 0;
  /// Clouds missing from the stream (a gap in its stamps): the source, the network, or the intake's own queue
  /// should it ever fall kIntakeQueue clouds behind. Clouds this node discards are clouds_lost_, counted one by one.
  std::size_t stream_gaps_ = 0;
  /// Clouds handed to the tf filter and not yet built, dropped or cleared: the backlog input_queue_size bounds.
  std::size_t pending_builds_ = 0;
  std::size_t reconfigure_refused_ = 0;
  std::string last_reconfigure_ = "none";

  std::unique_ptr<tf2_ros::Buffer> tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  std::unique_ptr<tf2_ros::MessageFilter<sensor_msgs::PointCloud2>> tf_filter_;
  std::unique_ptr<dynamic_reconfigure::Server<ScanGridConfig>> reconfigure_;
  std::unique_ptr<StartupFailure> failure_;  ///< ERROR diagnostics when the parameters were refused
  std::unique_ptr<diagnostic_updater::Updater> updater_;
  /// The intake: `points` is received on its own thread (intake_queue_), whose callback (onCloud) only checks a
  /// cloud and hands it to the tf filter, so that it never waits behind a build and no cloud is lost unseen in
  /// roscpp's queue; the builds run on the node's callback queue, where takePendingBuild() bounds and counts them.
  ros::CallbackQueue intake_queue_;
  std::unique_ptr<ros::AsyncSpinner> intake_spinner_;
  ros::Subscriber cloud_sub_;
  ros::Publisher grid_pub_;
  ros::Publisher occupancy_pub_;
  ros::Publisher started_pub_;  ///< `scan_grid/started`: the header of each ScanGrid as its build starts
  ros::WallTimer diagnostic_timer_, clock_timer_;
};

}  // namespace map_aided_fusion

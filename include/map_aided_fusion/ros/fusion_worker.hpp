/**
 * @file fusion_worker.hpp
 * @brief The fusion nodelet's worker: keeps the MapGrid, follows the vehicle through tf and publishes the
 *        class layers, decisions, cells and objects. Built from (nh, pnh) by FusionNodelet::onInit() or by
 *        the plain fusion_node.
 */
#pragma once

#include <array>
#include <chrono>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include <diagnostic_updater/diagnostic_updater.h>
#include <dynamic_reconfigure/server.h>
#include <ros/ros.h>
#include <std_msgs/Header.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/message_filter.h>
#include <tf2_ros/transform_listener.h>

#include "map_aided_fusion/EvidentialGrid.h"
#include "map_aided_fusion/FusionConfig.h"
#include "map_aided_fusion/core/map_grid.hpp"
#include "map_aided_fusion/core/prior_uncertainty.hpp"
#include "map_aided_fusion/core/sliding_window.hpp"
#include "map_aided_fusion/core/stamp_guard.hpp"
#include "map_aided_fusion/core/tracker.hpp"

namespace map_aided_fusion {

/// How many core::StartedVerdict values there are.
constexpr std::size_t kStartedVerdicts = static_cast<std::size_t>(core::StartedVerdict::kNoTransform) + 1;

/// Counters since start, reported on /diagnostics.
struct FusionCounters
{
  std::size_t fused = 0;                ///< scans fused
  std::size_t dropped_no_transform = 0; ///< scans dropped by the tf message filter
  std::size_t rejected = 0;             ///< malformed scan grids
  std::size_t zero_stamp = 0;           ///< scans stamped 0
  std::size_t future_stamp = 0;         ///< scans stamped further ahead of the clock than future_tolerance
  std::size_t out_of_order = 0;         ///< scans older than the last fused one (within time_jump_threshold)
  std::size_t duplicate = 0;            ///< scans with the stamp of the last fused one
  std::size_t late = 0;                 ///< scans older by more than time_jump_threshold, the clock not gone back
  std::size_t resets = 0;               ///< grid resets (genuine time jumps only)
  std::size_t tf_clears = 0;            ///< tf buffer cleared (time jump, or transforms ahead of the clock)
  std::size_t pose_jumps = 0;           ///< vehicle moved faster than max_plausible_speed between two scans
  std::size_t reconfigure_refused = 0;  ///< dynamic_reconfigure requests refused
  std::size_t covariance_rejected = 0;  ///< pose covariances refused (NaN, negative variance, asymmetric)
  std::size_t sigma_clamped = 0;        ///< covariances whose σ exceeded core::kMaxPositionSigma (clamped)
  std::size_t prior_softenings = 0;     ///< times the prior was softened anew (new prior or σ changed)
  std::size_t shifts_ahead = 0;         ///< window shifts made on `scan_grid/started`, before their scan (shift_ahead)
  /// `scan_grid/started` headers refused, by core::StartedVerdict (kShift and kNoScanYet stay 0).
  std::array<std::size_t, kStartedVerdicts> started_refused{};
};

/// The fusion node's own parameters besides the MapGrid's (config/fusion.yaml).
struct FusionNodeParams
{
  std::string map_frame = "map";        ///< fixed frame of the MapGrid and the PriorGrid
  std::string base_frame = "base_link"; ///< vehicle frame (informational)
  int tf_queue_size = 5;                ///< scans waiting for their transform, [1, 1000]
  double future_tolerance = 10.0;       ///< s a scan may be stamped ahead of a lagging clock, [0, 3600]
  bool publish_free_cells = false;      ///< also draw free cells in `cells`
  double object_box_height = 1.5;       ///< m, height of the object boxes, (0, 100]
  /// Move the window when `scan_grid/started` announces a scan, while its ScanGrid is built, rather than when the
  /// ScanGrid arrives: the same shift (core::MapGrid::follow()), off the cloud-to-decision path.
  bool shift_ahead = true;
  /// Topic of the vehicle's pose covariance ("" : none, the MapGrid's position_sigma is used).
  std::string pose_covariance_topic;
  /// Its type: "pose" (geometry_msgs/PoseWithCovarianceStamped) or "odometry" (nav_msgs/Odometry).
  std::string pose_covariance_type = "pose";
  core::TimeGuardParams time;           ///< out-of-order, time-jump and pose-jump thresholds
  core::StreamHealthParams health;      ///< diagnostics period, window and staleness
  /// @throws core::ParameterError naming the first bad parameter.
  void validate() const;
  /// Reads every parameter from @p pnh, keeping defaults for absent ones, and validates.
  static FusionNodeParams load(const ros::NodeHandle& pnh);
};

/// Calls get(name, field, doc) for every parameter of @p p, with the names of config/fusion.yaml.
template <class Get>
void forEachParam(FusionNodeParams& p, Get&& get)
{
  get("map_frame", p.map_frame, { "", "fixed frame of the MapGrid and of the PriorGrid" });
  get("base_frame", p.base_frame, { "", "vehicle frame" });
  get("tf_queue_size", p.tf_queue_size, { "scans", "scans waiting for their transform" });
  get("future_tolerance", p.future_tolerance, { "s", "a scan may be stamped this far ahead of a lagging clock" });
  get("publish_free_cells", p.publish_free_cells, { "", "also draw free cells in the cells markers" });
  get("object_box_height", p.object_box_height, { "m", "height of the object boxes" });
  get("shift_ahead", p.shift_ahead,
      { "", "move the window when scan_grid/started announces a scan, while its ScanGrid is built" });
  get("pose_covariance_topic", p.pose_covariance_topic, { "", "topic of the vehicle pose covariance (\"\": position_sigma is used)" });
  get("pose_covariance_type", p.pose_covariance_type, { "", "pose (PoseWithCovarianceStamped) or odometry (nav_msgs/Odometry)" });
  core::forEachParam(p.time, get);
  core::forEachParam(p.health, get);
}

/**
 * Topics: in `scan_grid`, `scan_grid/started` (shift_ahead), `prior_grid`, and the pose covariance when configured;
 * out `map_grid`, `betp/<class>`, `decision`, `navigable`, `cells`, `objects`.
 *
 * Time: scans are fused in stamp order. A scan stamped 0, further ahead of the clock than
 * future_tolerance, with the stamp of the last fused one, or older than it (released late after a tf gap) is
 * dropped and counted; only a genuine time jump (ROS time going back by more than time_jump_threshold, as when
 * a bag loops, or late scans that keep coming for longer than that, none fused) resets the MapGrid, once, and
 * clears the tf buffer. A clock that lags behind the data is not a
 * jump: the scans wait for their transforms and are fused. Diagnostics
 * are published on a wall timer and describe the last diagnostic_window seconds.
 */
class FusionWorker
{
public:
  /**
   * @param nh   node handle for topics
   * @param pnh  private node handle for parameters (config/fusion.yaml)
   * @throws core::ParameterError when a parameter is out of range (the caller logs it).
   */
  FusionWorker(ros::NodeHandle nh, ros::NodeHandle pnh);
  ~FusionWorker();

private:
  void onScanIn(const EvidentialGrid::ConstPtr& msg);
  void onScan(const EvidentialGrid::ConstPtr& msg);
  /// When a scan's callback reached each stage (steady clock), and the cloud's age at its start (ms).
  struct ScanTimes
  {
    std::chrono::steady_clock::time_point start, update, tracking, outputs;
    double cloud_age_ms = 0.0;
    core::StageTimes stages;  ///< the MapGrid update's own stages
  };
  /// Parts of onScan(): the ScanGrid message into @p scan (false: rejected, counted); the vehicle pose at its stamp
  /// (none: dropped, counted); the stamp's verdict under mutex_ (false: dropped, counted; a genuine jump resets and
  /// admits); a warning on a pose jump; the latencies of the scan fused.
  bool convertScan(const EvidentialGrid& msg, core::ScanMassGrid& scan);
  std::optional<core::Pose2> scanPose(const EvidentialGrid& msg);
  bool admitStamp(const ros::Time& stamp);
  void warnPoseJump(const core::Pose2& pose, double stamp);
  void recordLatency(const ScanTimes& times, const ros::Time& stamp);
  /// shift_ahead: a ScanGrid stamped @p header is being built; the window moves now as its update would move it,
  /// when the header describes a scan that will be fused (core::checkStarted(): the frame of the fused scans, a
  /// newer stamp within the clock's tolerances, a pose in tf reachable at max_plausible_speed, no pending
  /// parameters); any other header is refused and counted by cause.
  void onScanStarted(const std_msgs::Header::ConstPtr& header);
  /// How far a stamp is ahead of ROS time, and whether a scan so stamped is dropped for it (further than
  /// future_tolerance, or than time_jump_threshold soon after a backward jump). Under mutex_.
  struct AheadOfClock
  {
    double seconds = 0.0;  ///< 0 before the clock's first value
    bool clock_started = false;  ///< ROS time has a value
    bool after_jump = false;
    bool too_far = false;
  };
  AheadOfClock aheadOfClock(double stamp) const;
  /// Clock watch on a wall timer: a backward jump resets once; transforms ahead of the clock are cleared.
  void checkClock();
  /// Resets the grid and the time state after a genuine jump; caller holds mutex_.
  void resetForTimeJump(const std::string& why);
  /// Counts a scan that will not be fused; caller holds mutex_.
  void countLost(std::size_t& counter);
  void onScanDropped(const EvidentialGrid::ConstPtr& msg, tf2_ros::FilterFailureReason reason);
  void onPrior(const EvidentialGrid::ConstPtr& msg);
  /// A pose covariance (6 × 6 row-major): a new σ, or a counted, throttled rejection keeping the last good σ.
  void onCovariance(const boost::array<double, 36>& covariance);
  /// The prior softened by the σ in force (the last good covariance's, else position_sigma), recomputed and counted
  /// only when the prior or σ changed (core::PriorSoftener); nullptr without a prior. Under mutex_.
  const core::PriorWindow* softenedPrior();
  void onReconfigure(FusionConfig& config, uint32_t level);
  /// Publishes the layers of the last update, whose prior was @p prior (nullptr: none).
  void publish(const std_msgs::Header& header, const core::PriorWindow* prior);
  /// Updates the tracker with the scan's obstacle returns, applies its motion evidence to the MapGrid (step "track
  /// evidence") and publishes `tracks` and `tracks/markers`.
  void track(const std_msgs::Header& header, double stamp, const core::Pose2& pose, const core::ObstaclePoints& returns,
             const core::ScanMassGrid& scan, const core::PriorWindow* prior);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);
  /// Parts of diagnose(), under mutex_, at steady time @p now: the scans' counters and the last scan's stage times;
  /// the latency quantiles over the window; the prior, pose covariance and shifts ahead; the tracker.
  void diagnoseCounters(diagnostic_updater::DiagnosticStatusWrapper& status, double now);
  void diagnoseLatency(diagnostic_updater::DiagnosticStatusWrapper& status, double now);
  void diagnosePrior(diagnostic_updater::DiagnosticStatusWrapper& status, double now);
  void diagnoseTracker(diagnostic_updater::DiagnosticStatusWrapper& status, double now);

  ros::NodeHandle nh_, pnh_;
  FusionNodeParams node_params_;

  std::mutex mutex_;
  core::MapGrid grid_;
  std::optional<core::MapGridParams> pending_params_;
  core::PriorSoftener softener_;
  bool warned_no_prior_ = false;
  double covariance_sigma_ = std::numeric_limits<double>::quiet_NaN();  ///< σ of the last good covariance, m
  double last_covariance_wall_ = 0.0;
  core::StampGuard stamp_guard_;
  core::ClockJumpDetector clock_jump_;
  std::optional<core::Pose2> last_pose_;
  double last_jump_wall_ = -1e9;  ///< steady time of the last reset for a time jump
  std::string last_scan_frame_;
  std::string fused_frame_;  ///< frame of the last fused scan: a `started` header must be in it
  std::optional<double> shifted_stamp_;  ///< stamp of the last `started` header honoured since the last fused scan
  core::SlidingCounter started_refused_window_;
  std::string dropped_frame_;  ///< frame of the last scan dropped for want of its transform
  FusionCounters counters_;
  core::SlidingCounter fused_window_, lost_window_;
  core::SlidingCounter covariance_rejected_window_;
  std::optional<core::Tracker> tracker_;  ///< when `tracker` is true (config/fusion.yaml)
  std::vector<std::uint8_t> background_;   ///< per obstacle return of the scan: on static background
  std::uint64_t tracker_resets_seen_ = 0;  ///< the tracker's resets already counted in the window
  core::SlidingCounter tracker_resets_window_;
  core::SlidingCounter tracker_bounded_window_;  ///< scans in which the tracker dropped measurements or tracks
  std::size_t last_tracks_ = 0, last_moving_tracks_ = 0, last_held_back_tracks_ = 0;
  double start_wall_ = 0.0;
  double last_fused_wall_ = 0.0;
  core::StageTimes last_times_;
  double last_total_seconds_ = 0.0;
  /// Where a scan's time goes, ms, over the diagnostics window (issue: latency you can see): the cloud's age when
  /// the callback starts (ScanGrid build, hand-over, tf wait) and when its decision is out, and each stage.
  struct LatencyWindows
  {
    /// The cloud's age: latencies, and stamps ahead of a lagging clock counted apart (never a negative latency).
    core::LatencyWindow cloud_to_callback, cloud_to_decision;
    core::SlidingSamples conversion, shift, project_scan, prior_window, fusion, tracking, outputs;
    core::SlidingSamples shift_ahead;  ///< the shifts made on `scan_grid/started`, before the scan's callback
    core::SlidingSamples skipped;  ///< share of the window's cells the step skipped (MapGridParams::skip_unchanged)
    core::SlidingSamples changing;  ///< share the step computed under a vacuous scan (neither skipped nor observed)
    void setSpan(double span);
  };
  LatencyWindows latency_;
  double last_mean_conflict_ = 0.0;
  std::string last_reconfigure_ = "none";

  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  std::unique_ptr<tf2_ros::MessageFilter<EvidentialGrid>> scan_filter_;
  ros::Subscriber scan_sub_, started_sub_, prior_sub_, covariance_sub_;
  ros::Publisher map_grid_pub_, decision_pub_, navigable_pub_, cells_pub_, objects_pub_;
  ros::Publisher tracks_pub_, tracks_markers_pub_;
  ros::Publisher betp_pub_[core::FrameMG::kSize];
  dynamic_reconfigure::Server<FusionConfig> reconfigure_;
  std::unique_ptr<diagnostic_updater::Updater> diagnostics_;
  ros::WallTimer diagnostics_timer_, clock_timer_;
};

}  // namespace map_aided_fusion

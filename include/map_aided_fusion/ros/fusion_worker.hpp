/**
 * @file fusion_worker.hpp
 * @brief The fusion nodelet's worker: keeps the MapGrid, follows the vehicle through tf and publishes the
 *        class layers, decisions, cells and objects. Built from (nh, pnh) by FusionNodelet::onInit() or by
 *        the plain fusion_node.
 */
#pragma once

#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include <diagnostic_updater/diagnostic_updater.h>
#include <dynamic_reconfigure/server.h>
#include <message_filters/subscriber.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/message_filter.h>
#include <tf2_ros/transform_listener.h>

#include "map_aided_fusion/EvidentialGrid.h"
#include "map_aided_fusion/FusionConfig.h"
#include "map_aided_fusion/core/map_grid.hpp"

namespace map_aided_fusion {

/// Counters reported on /diagnostics.
struct FusionCounters
{
  std::size_t fused = 0;                ///< scans fused
  std::size_t dropped_no_transform = 0; ///< scans dropped by the tf message filter
  std::size_t rejected = 0;             ///< malformed scan grids
  std::size_t resets = 0;               ///< grid resets (time going backwards)
};

/// Topics: in `scan_grid`, `prior_grid`; out `map_grid`, `betp/*`, `decision`, `cells`, `objects`.
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
  void onScan(const EvidentialGrid::ConstPtr& msg);
  void onScanDropped(const EvidentialGrid::ConstPtr& msg, tf2_ros::FilterFailureReason reason);
  void onPrior(const EvidentialGrid::ConstPtr& msg);
  void onReconfigure(FusionConfig& config, uint32_t level);
  void publish(const std_msgs::Header& header);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);

  ros::NodeHandle nh_, pnh_;
  std::string map_frame_, base_frame_;
  bool publish_free_cells_ = false;
  double object_box_height_ = 1.5;

  std::mutex mutex_;
  core::MapGrid grid_;
  std::optional<core::MapGridParams> pending_params_;
  std::shared_ptr<core::PriorWindow> prior_;
  bool warned_no_prior_ = false;
  std::optional<ros::Time> last_stamp_;
  FusionCounters counters_;
  core::StageTimes last_times_;
  double last_total_seconds_ = 0.0;
  double last_mean_conflict_ = 0.0;
  ros::WallTime last_scan_wall_;
  double scan_rate_ = 0.0;

  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  message_filters::Subscriber<EvidentialGrid> scan_sub_;
  std::unique_ptr<tf2_ros::MessageFilter<EvidentialGrid>> scan_filter_;
  ros::Subscriber prior_sub_;
  ros::Publisher map_grid_pub_, decision_pub_, cells_pub_, objects_pub_;
  ros::Publisher betp_pub_[core::FrameMG::kSize];
  dynamic_reconfigure::Server<FusionConfig> reconfigure_;
  diagnostic_updater::Updater diagnostics_;
  ros::Timer diagnostics_timer_;
};

}  // namespace map_aided_fusion

#include "map_aided_fusion/ros/startup_failure.hpp"

#include <utility>

namespace map_aided_fusion {

namespace {
constexpr double kPeriod = 1.0;  // s, wall time
}  // namespace

StartupFailure::StartupFailure(ros::NodeHandle nh, ros::NodeHandle pnh, const std::string& task, std::string reason)
  : reason_(std::move(reason))
{
  updater_ = std::make_unique<diagnostic_updater::Updater>(nh, pnh, pnh.getNamespace());
  updater_->setHardwareID(task);
  updater_->add(task, [this](diagnostic_updater::DiagnosticStatusWrapper& s) {
    s.summary(diagnostic_msgs::DiagnosticStatus::ERROR, "not started: " + reason_);
    s.add("reason", reason_);
  });
  updater_->force_update();
  timer_ = nh.createWallTimer(ros::WallDuration(kPeriod), [this](const ros::WallTimerEvent&) { updater_->force_update(); });
}

}  // namespace map_aided_fusion

/**
 * @file startup_failure.hpp
 * @brief The diagnostics of a component that could not start (a parameter out of range, an unknown key, a window
 *        over the memory budget): an ERROR status with the reason, under the task name the running component
 *        would use, once a second, so that /diagnostics (rqt_robot_monitor) tells why nothing comes.
 */
#pragma once

#include <memory>
#include <string>

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>

namespace map_aided_fusion {

class StartupFailure
{
public:
  /**
   * @param nh, pnh  the component's handles (the status is named after pnh's namespace, as the component's own)
   * @param task     the task name of the component's diagnostics ("fusion", "ScanGrid")
   * @param reason   what stopped it (the ParameterError's text)
   */
  StartupFailure(ros::NodeHandle nh, ros::NodeHandle pnh, const std::string& task, std::string reason);

private:
  std::string reason_;
  std::unique_ptr<diagnostic_updater::Updater> updater_;
  ros::WallTimer timer_;
};

}  // namespace map_aided_fusion

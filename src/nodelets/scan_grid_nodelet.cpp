#include <memory>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include "map_aided_fusion/ros/scan_grid_worker.hpp"

namespace map_aided_fusion {

/// Nodelet wrapper of ScanGridWorker (see scan_grid_worker.hpp for topics and parameters).
class ScanGridNodelet : public nodelet::Nodelet
{
private:
  void onInit() override { worker_ = std::make_unique<ScanGridWorker>(getNodeHandle(), getPrivateNodeHandle()); }

  std::unique_ptr<ScanGridWorker> worker_;
};

}  // namespace map_aided_fusion

PLUGINLIB_EXPORT_CLASS(map_aided_fusion::ScanGridNodelet, nodelet::Nodelet)

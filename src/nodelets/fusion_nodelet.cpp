#include <memory>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include "map_aided_fusion/ros/fusion_worker.hpp"
#include "map_aided_fusion/ros/startup_failure.hpp"

namespace map_aided_fusion {

/// Keeps the MapGrid and fuses each ScanGrid with the PriorGrid (see FusionWorker).
class FusionNodelet : public nodelet::Nodelet
{
private:
  void onInit() override
  {
    try
    {
      worker_ = std::make_unique<FusionWorker>(getNodeHandle(), getPrivateNodeHandle());
    }
    catch (const std::exception& e)
    {
      NODELET_ERROR_STREAM("fusion: not started: " << e.what());
      failure_ = std::make_unique<StartupFailure>(getNodeHandle(), getPrivateNodeHandle(), "fusion", e.what());
    }
  }
  std::unique_ptr<FusionWorker> worker_;
  std::unique_ptr<StartupFailure> failure_;  ///< ERROR diagnostics with the reason when the worker could not start
};

}  // namespace map_aided_fusion

PLUGINLIB_EXPORT_CLASS(map_aided_fusion::FusionNodelet, nodelet::Nodelet)

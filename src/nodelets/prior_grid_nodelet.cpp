#include <memory>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include "map_aided_fusion/ros/prior_grid_worker.hpp"

namespace map_aided_fusion {

/// Loads a geographic map and publishes the PriorGrid (latched); see PriorGridWorker.
class PriorGridNodelet : public nodelet::Nodelet
{
private:
  void onInit() override { worker_ = std::make_unique<PriorGridWorker>(getNodeHandle(), getPrivateNodeHandle()); }

  std::unique_ptr<PriorGridWorker> worker_;
};

}  // namespace map_aided_fusion

PLUGINLIB_EXPORT_CLASS(map_aided_fusion::PriorGridNodelet, nodelet::Nodelet)

// Plain-node version of the PriorGridNodelet (same worker).
#include <ros/ros.h>

#include "map_aided_fusion/ros/prior_grid_worker.hpp"

int main(int argc, char** argv)
{
  ros::init(argc, argv, "prior_grid");
  map_aided_fusion::PriorGridWorker node(ros::NodeHandle(), ros::NodeHandle("~"));
  ros::spin();
  return 0;
}

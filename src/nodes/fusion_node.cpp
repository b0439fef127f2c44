// The fusion as a plain node: the same worker as FusionNodelet.
#include <ros/ros.h>

#include "map_aided_fusion/ros/fusion_worker.hpp"

int main(int argc, char** argv)
{
  ros::init(argc, argv, "fusion");
  try
  {
    map_aided_fusion::FusionWorker worker(ros::NodeHandle(), ros::NodeHandle("~"));
    ros::spin();
  }
  catch (const std::exception& e)
  {
    ROS_FATAL_STREAM("fusion: " << e.what());
    return 1;
  }
  return 0;
}

// The fusion as a plain node: the same worker as FusionNodelet.
#include <iostream>

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
    // On stderr as well as rosout: rosconsole may not be flushed before exit.
    std::cerr << "fusion: not started: " << e.what() << std::endl;
    ROS_FATAL_STREAM("fusion: not started: " << e.what());
    return 1;
  }
  return 0;
}

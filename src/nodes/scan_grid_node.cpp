// The ScanGrid as a plain node: the same worker as ScanGridNodelet.
#include <ros/ros.h>

#include "map_aided_fusion/ros/scan_grid_worker.hpp"

int main(int argc, char** argv)
{
  ros::init(argc, argv, "scan_grid");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  map_aided_fusion::ScanGridWorker worker(nh, pnh);
  ros::spin();
  return 0;
}

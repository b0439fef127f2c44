#include "map_aided_fusion/ros/param_loading.hpp"

namespace map_aided_fusion {

void readParam(const ros::NodeHandle& nh, const std::string& name, double& value)
{
  if (!nh.hasParam(name)) return;
  XmlRpc::XmlRpcValue v;
  nh.getParam(name, v);
  if (v.getType() == XmlRpc::XmlRpcValue::TypeDouble)
    value = static_cast<double>(v);
  else if (v.getType() == XmlRpc::XmlRpcValue::TypeInt)
    value = static_cast<int>(v);
  else
    throw core::ParameterError(name, "must be a number (" + nh.resolveName(name) + ")");
}

core::MapGridParams loadMapGridParams(const ros::NodeHandle& nh)
{
  core::MapGridParams p;
  core::forEachParam(p, parameterServerReader(nh));
  p.validate();
  return p;
}

core::TrackerParams loadTrackerParams(const ros::NodeHandle& nh)
{
  core::TrackerParams p;
  core::forEachParam(p, parameterServerReader(nh));
  p.validate();
  return p;
}

}  // namespace map_aided_fusion

/**
 * @file param_loading.hpp
 * @brief Reading typed parameter structs from the ROS parameter server (values from the config folder's YAML files).
 */
#pragma once

#include <string>
#include <vector>

#include <ros/node_handle.h>

#include "map_aided_fusion/core/map_grid.hpp"
#include "map_aided_fusion/core/tracker.hpp"
#include "map_aided_fusion/core/parameters.hpp"

namespace map_aided_fusion {

/// Records that the component under namespace @p ns knows the parameter @p name (every readParam() does), process-wide.
void recordKnownParam(const std::string& ns, const std::string& name);

/// @p value keeps its default when @p name is not set; a value of the wrong type is a ParameterError.
template <typename T>
void readParam(const ros::NodeHandle& nh, const std::string& name, T& value)
{
  recordKnownParam(nh.getNamespace(), name);
  if (!nh.hasParam(name)) return;
  if (!nh.getParam(name, value))
    throw core::ParameterError(name, "has the wrong type (" + nh.resolveName(name) + ")");
}

/// double parameters may be written as integers in YAML.
void readParam(const ros::NodeHandle& nh, const std::string& name, double& value);

/// A getter for core::forEachParam() that reads from @p nh (absent parameters keep their defaults).
inline auto parameterServerReader(const ros::NodeHandle& nh)
{
  return [&nh](const std::string& name, auto& value, const core::ParamDoc&) { readParam(nh, name, value); };
}

/**
 * @brief The keys set under @p pnh's namespace that no readParam() on it asked for and that are not in
 *        @p also_known (a misspelt `decision_treshold`, a key of another component's file), sorted.
 */
std::vector<std::string> unknownParams(const ros::NodeHandle& pnh, const std::vector<std::string>& also_known = {});

/**
 * @brief Refuses unknown keys (see unknownParams()), as the simulator refuses unknown scenario keys: a key that is
 *        silently ignored leaves its default in force without anybody knowing.
 * @throws core::ParameterError naming the first unknown key and the nearest known one.
 */
void refuseUnknownParams(const ros::NodeHandle& pnh, const std::vector<std::string>& also_known = {});

/// The parameter names of a dynamic_reconfigure config type (its server writes them into the private namespace).
template <class Config>
std::vector<std::string> reconfigureNames()
{
  std::vector<std::string> names;
  for (const auto& d : Config::__getParamDescriptions__()) names.push_back(d->name);
  return names;
}

/**
 * @brief The MapGrid parameters from @p nh (the fusion nodelet's private namespace; see config/fusion.yaml).
 * @throws core::ParameterError naming the parameter that is missing its type or out of range.
 */
core::MapGridParams loadMapGridParams(const ros::NodeHandle& nh);

/**
 * @brief The tracker's parameters from @p nh (the fusion nodelet's private namespace, `tracker*` keys).
 * @throws core::ParameterError naming the parameter that has the wrong type or is out of range.
 */
core::TrackerParams loadTrackerParams(const ros::NodeHandle& nh);

}  // namespace map_aided_fusion

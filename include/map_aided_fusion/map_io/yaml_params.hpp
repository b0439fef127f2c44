/**
 * @file yaml_params.hpp
 * @brief Reading parameter structs from the package's YAML files without a ROS master (offline tools), through
 *        the same forEachParam() lists as the nodelets.
 */
#pragma once

#include <string>
#include <type_traits>

#include <yaml-cpp/yaml.h>

#include "map_aided_fusion/core/parameters.hpp"

namespace map_aided_fusion {
namespace map_io {

/// The YAML file at @p path (an empty node for an empty path). @throws std::runtime_error naming the file.
inline YAML::Node loadYamlFile(const std::string& path)
{
  if (path.empty()) return YAML::Node();
  try
  {
    return YAML::LoadFile(path);
  }
  catch (const YAML::Exception& e)
  {
    throw std::runtime_error("config '" + path + "': " + e.what());
  }
}

/// A getter for forEachParam(): absent keys keep their defaults; a value of the wrong type is a ParameterError.
inline auto yamlReader(const YAML::Node& root)
{
  return [root](const std::string& name, auto& value, const core::ParamDoc&) {
    if (!root || !root.IsMap()) return;
    const YAML::Node n = root[name];
    if (!n) return;
    try
    {
      value = n.as<std::remove_reference_t<decltype(value)>>();
    }
    catch (const YAML::Exception&)
    {
      throw core::ParameterError(name, "has the wrong type");
    }
  };
}

}  // namespace map_io
}  // namespace map_aided_fusion

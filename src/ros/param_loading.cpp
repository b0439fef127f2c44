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
  readParam(nh, "size_x", p.size_x);
  readParam(nh, "size_y", p.size_y);
  readParam(nh, "resolution", p.resolution);
  readParam(nh, "alpha_static", p.fusion.discount.alpha_static);
  readParam(nh, "alpha_dynamic", p.fusion.discount.alpha_dynamic);
  readParam(nh, "alpha_free", p.fusion.discount.alpha_free);
  readParam(nh, "alpha_per_second", p.rates_per_second);
  readParam(nh, "delta_inc", p.fusion.counter.delta_inc);
  readParam(nh, "delta_dec", p.fusion.counter.delta_dec);
  readParam(nh, "gamma_occupied", p.fusion.counter.gamma_occupied);
  readParam(nh, "gamma_conflict", p.fusion.counter.gamma_conflict);
  bool literal = p.fusion.counter.mode == core::SpecialisationMode::kLiteral;
  readParam(nh, "specialise_literal", literal);
  p.fusion.counter.mode = literal ? core::SpecialisationMode::kLiteral : core::SpecialisationMode::kMovingToStopped;
  readParam(nh, "decision_threshold", p.decision_threshold);
  readParam(nh, "min_object_cells", p.min_object_cells);
  p.validate();
  return p;
}

}  // namespace map_aided_fusion

#include "map_aided_fusion/ros/param_loading.hpp"

#include <algorithm>
#include <map>
#include <mutex>
#include <set>

namespace map_aided_fusion {

namespace {

std::mutex& knownMutex()
{
  static std::mutex m;
  return m;
}

std::map<std::string, std::set<std::string>>& knownKeys()
{
  static std::map<std::string, std::set<std::string>> k;
  return k;
}

std::size_t editDistance(const std::string& a, const std::string& b)
{
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i)
  {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j)
    {
      const std::size_t up = row[j];
      row[j] = std::min({ row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1) });
      diagonal = up;
    }
  }
  return row[b.size()];
}

/// The keys the component under @p pnh asked for, and @p also_known.
std::set<std::string> knownFor(const ros::NodeHandle& pnh, const std::vector<std::string>& also_known)
{
  std::set<std::string> known(also_known.begin(), also_known.end());
  std::lock_guard<std::mutex> lock(knownMutex());
  const auto& k = knownKeys()[pnh.getNamespace()];
  known.insert(k.begin(), k.end());
  return known;
}

}  // namespace

void recordKnownParam(const std::string& ns, const std::string& name)
{
  std::lock_guard<std::mutex> lock(knownMutex());
  knownKeys()[ns].insert(name);
}

std::vector<std::string> unknownParams(const ros::NodeHandle& pnh, const std::vector<std::string>& also_known)
{
  const std::set<std::string> known = knownFor(pnh, also_known);
  std::vector<std::string> names;
  if (!pnh.getParamNames(names)) return {};
  const std::string prefix = pnh.getNamespace() + "/";
  std::set<std::string> unknown;
  for (const std::string& n : names)
  {
    if (n.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string key = n.substr(prefix.size(), n.find('/', prefix.size()) - prefix.size());
    if (!key.empty() && !known.count(key)) unknown.insert(key);
  }
  return { unknown.begin(), unknown.end() };
}

void refuseUnknownParams(const ros::NodeHandle& pnh, const std::vector<std::string>& also_known)
{
  const std::vector<std::string> unknown = unknownParams(pnh, also_known);
  if (unknown.empty()) return;
  std::string hint;
  std::size_t best = std::string::npos;
  for (const std::string& k : knownFor(pnh, also_known))
    if (const std::size_t d = editDistance(unknown.front(), k); d < best)
    {
      best = d;
      hint = k;
    }
  std::string others;
  for (std::size_t i = 1; i < unknown.size(); ++i) others += (others.empty() ? "" : ", ") + unknown[i];
  throw core::ParameterError(unknown.front(), "is not a parameter of " + pnh.getNamespace() +
                                                  (hint.empty() || best > 3 ? std::string() : " (did you mean '" + hint + "'?)") +
                                                  (others.empty() ? std::string() : "; unknown too: " + others));
}

void readParam(const ros::NodeHandle& nh, const std::string& name, double& value)
{
  recordKnownParam(nh.getNamespace(), name);
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

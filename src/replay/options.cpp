#include "map_aided_fusion/replay/options.hpp"

#include <sstream>
#include <stdexcept>

namespace map_aided_fusion {
namespace replay {

namespace {

constexpr double kMaxMatchRadius = 10.0;  ///< m

double argDouble(const std::string& name, const std::string& v)
{
  try
  {
    std::size_t used = 0;
    const double d = std::stod(v, &used);
    if (used != v.size()) throw std::invalid_argument(v);
    return d;
  }
  catch (const std::exception&)
  {
    throw std::runtime_error(name + ": not a number: " + v);
  }
}

}  // namespace

ReplayOptions parseReplayOptions(const std::vector<std::string>& args)
{
  ReplayOptions o;
  for (std::size_t i = 0; i < args.size(); ++i)
  {
    const std::string& a = args[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= args.size()) throw std::runtime_error(a + " needs a value");
      return args[++i];
    };
    if (a == "--bag") o.bag = value();
    else if (a == "--output-bag")
    {
      const std::string v = value();
      const auto eq = v.find('=');
      if (eq != std::string::npos && eq > 0 && v.find('/') > eq)
        o.output_bags.emplace_back(v.substr(0, eq), v.substr(eq + 1));
      else
        o.output_bags.emplace_back("live", v);
    }
    else if (a == "--live-topic") o.live_topic = value();
    else if (a == "--out") o.out = value();
    else if (a == "--fusion-config") o.fusion_config = value();
    else if (a == "--scan-grid-config") o.scan_grid_config = value();
    else if (a == "--prior-config") o.prior_config = value();
    else if (a == "--map") o.map = value();
    else if (a == "--origin")
    {
      std::stringstream ss(value());
      std::array<double, 3> v{ 0, 0, 0 };
      std::string part;
      int k = 0;
      while (std::getline(ss, part, ',') && k < 3) v[k++] = argDouble("--origin", part);
      if (k < 2) throw std::runtime_error("--origin needs LAT,LON[,ALT]");
      o.origin = v;
    }
    else if (a == "--snapshot-time") o.snapshot_time = argDouble(a, value());
    else if (a == "--sheet-period") o.sheet_period = argDouble(a, value());
    else if (a == "--match-radius") o.match_radius = argDouble(a, value());
    else if (a == "--pose-covariance-topic") o.pose_covariance_topic = value();
    else if (a == "--no-ablations") o.ablations = false;
    else if (a == "--check-config") o.check_config = true;
    else if (a == "--only")
    {
      std::stringstream ss(value());
      std::string name;
      while (std::getline(ss, name, ','))
        if (!name.empty()) o.only.insert(name);
      if (o.only.empty()) throw std::runtime_error("--only needs at least one variant name");
    }
    else if (a == "--quiet") o.quiet = true;
    else if (a == "-h" || a == "--help")
    {
      o.help = true;
      return o;
    }
    else
      throw std::runtime_error("unknown argument " + a);
  }
  if (o.bag.empty() && !o.check_config) throw std::runtime_error("--bag is required");
  if (!(o.match_radius >= 0.0 && o.match_radius <= kMaxMatchRadius))
    throw std::runtime_error("--match-radius must be in [0, 10] m");
  return o;
}

const char* replayUsage()
{
  return "usage: evaluate --bag SCENARIO.bag [--output-bag [NAME=]LIVE.bag ...] [--out DIR]\n"
               "                [--fusion-config F.yaml] [--scan-grid-config S.yaml] [--prior-config P.yaml]\n"
               "                [--pose-covariance-topic T] (softens the prior by the sigma of T)\n"
               "                [--map FILE] [--origin LAT,LON[,ALT]] [--snapshot-time S] [--sheet-period S]\n"
               "                [--match-radius M] [--no-ablations] [--only VARIANT[,VARIANT...]] [--quiet]\n"
               "       evaluate --check-config [--fusion-config F.yaml] [--scan-grid-config S.yaml] [--prior-config P.yaml]\n"
               "  Runs the pipeline offline on the bag with the configured method (variant `default`), the\n"
               "  paper's exact method (`paper`) and their ablations, scores bags recorded from the live\n"
               "  nodelets (topic /map_aided_fusion/decision) when given (row `live`, or NAME), and writes DIR/metrics.json,\n"
               "  DIR/metrics.md, DIR/scores.csv and DIR/snapshots/.\n"
               "  A simulator bag (/ground_truth/classes, /ground_truth/objects) is scored per cell and per object;\n"
               "  a labelled real bag (/ground_truth/points, from kitti_to_bag) per labelled point: false V (V cells\n"
               "  farther than --match-radius, 1 m, from every moving point), moving objects' cells decided V,\n"
               "  decisions of static obstacle cells; a bag of labelled boxes (/ground_truth/objects without\n"
               "  /ground_truth/classes: KITTI tracking, from kitti_to_bag) per object: first seen, first V, delay,\n"
               "  V and S shares, false V where /ground_truth/valid says the labels are valid. Without --map (or a map_file in the prior config) the\n"
               "  pipeline runs without prior. --only runs just the named variants (e.g. `default`, as the tuner does).\n"
               "  --check-config loads and validates the three files and exits: 0, or 1 with the parameter's name.\n";
}

}  // namespace replay
}  // namespace map_aided_fusion

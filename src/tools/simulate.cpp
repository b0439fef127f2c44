// rosrun map_aided_fusion simulate --scenario scenarios/default.yaml --out x.bag
//   [--duration S] [--preset ibeo4|vlp32|hdl32|hdl64] [--seed N] [--quiet]
// Loads the scenario and its map, simulates every scan and writes the bag (see ros/sim_bag.hpp).
#include <unistd.h>

#include <cstdlib>
#include <iostream>
#include <string>

#include <rosbag/exceptions.h>
#include <ros/time.h>

#include "map_aided_fusion/core/parameters.hpp"
#include "map_aided_fusion/map_io/map_loader.hpp"
#include "map_aided_fusion/ros/sim_bag.hpp"

using namespace map_aided_fusion;

namespace {

constexpr int kUsageError = 2;
constexpr int kRunError = 1;

void usage(std::ostream& out)
{
  out << "usage: simulate --scenario FILE.yaml --out FILE.bag [--duration S] [--preset ibeo4|vlp32|hdl32|hdl64]"
         " [--seed N] [--quiet]\n"
         "Simulates an urban scenario (lidar, ego pose, ground truth) and writes a rosbag with /points, /tf,\n"
         "/tf_static, /ground_truth/classes and /ground_truth/objects.\n";
}

}  // namespace

int main(int argc, char** argv)
{
  std::string scenario_file, out_file, preset;
  double duration = -1.0;
  long long seed = -1;
  bool quiet = false;
  for (int i = 1; i < argc; ++i)
  {
    const std::string a = argv[i];
    auto value = [&](const char* name) -> std::string {
      if (i + 1 >= argc)
      {
        std::cerr << "simulate: " << name << " needs a value\n";
        usage(std::cerr);
        std::exit(kUsageError);
      }
      return argv[++i];
    };
    try
    {
      if (a == "--scenario") scenario_file = value("--scenario");
      else if (a == "--out") out_file = value("--out");
      else if (a == "--duration") duration = std::stod(value("--duration"));
      else if (a == "--preset") preset = value("--preset");
      else if (a == "--seed") seed = std::stoll(value("--seed"));
      else if (a == "--quiet") quiet = true;
      else if (a == "--help" || a == "-h")
      {
        usage(std::cout);
        return 0;
      }
      else
      {
        std::cerr << "simulate: unknown argument '" << a << "'\n";
        usage(std::cerr);
        return kUsageError;
      }
    }
    catch (const std::exception&)
    {
      std::cerr << "simulate: bad number for " << a << "\n";
      return kUsageError;
    }
  }
  if (scenario_file.empty() || out_file.empty())
  {
    usage(std::cerr);
    return kUsageError;
  }

  try
  {
    sim::Scenario sc = sim::loadScenario(scenario_file);
    if (duration >= 0.0) sc.duration = duration;
    if (seed >= 0) sc.seed = static_cast<std::uint64_t>(seed);
    if (!preset.empty()) sc.lidar = sim::LidarParams::fromPreset(preset);
    sc.validate();
    if (sc.map_file.empty()) throw core::ParameterError("map", "the scenario names no map file");

    map_io::MapLoadParams mp;
    mp.file = sc.map_file;
    mp.origin_latitude = sc.map_origin_latitude;
    mp.origin_longitude = sc.map_origin_longitude;
    mp.origin_altitude = sc.map_origin_altitude;
    map_io::MapLoadReport report;
    const core::VectorMap map = map_io::loadVectorMap(mp, &report);
    if (!quiet) std::cerr << "[simulate] " << map_io::summary(report) << "\n";

    ros::Time::init();
    sim::Simulator simulator(sc, map);
    const sim::WorldSummary& w = simulator.summary();
    if (!quiet)
      std::cerr << "[simulate] scenario '" << sc.name << "': " << sc.duration << " s, lidar " << sc.lidar.preset
                << ", seed " << sc.seed << ", " << sc.objects.size() << " objects; world: " << w.mapped_buildings
                << " mapped buildings, " << w.unmapped_buildings << " missing from the map, " << w.absent_buildings
                << " mapped but absent\n";
    SimBagOptions options;
    options.path = out_file;
    // A progress line rewritten in place only on a terminal (logs get no carriage returns).
    options.progress = quiet || !::isatty(STDERR_FILENO) ? nullptr : &std::cerr;
    const SimBagStats stats = writeSimulationBag(simulator, options);
    std::cerr << "[simulate] wrote " << out_file << ": " << stats.scans << " scans, " << stats.points << " points, "
              << stats.tf_messages << " tf in " << stats.wall_seconds << " s\n";
  }
  catch (const core::ParameterError& e)
  {
    std::cerr << "simulate: invalid scenario parameter " << e.what() << "\n";
    return kRunError;
  }
  catch (const map_io::MapLoadError& e)
  {
    std::cerr << "simulate: cannot load the map: " << e.what() << "\n";
    return kRunError;
  }
  catch (const rosbag::BagException& e)
  {
    std::cerr << "simulate: cannot write the bag: " << e.what() << "\n";
    return kRunError;
  }
  catch (const std::exception& e)
  {
    std::cerr << "simulate: " << e.what() << "\n";
    return kRunError;
  }
  return 0;
}

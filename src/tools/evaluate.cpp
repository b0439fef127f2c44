// evaluate: the offline replay of a bag through the core (replay/offline_replay.hpp) from the command line.
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "map_aided_fusion/replay/offline_replay.hpp"

namespace replay = map_aided_fusion::replay;

int main(int argc, char** argv)
{
  replay::ReplayOptions options;
  try
  {
    options = replay::parseReplayOptions(std::vector<std::string>(argv + 1, argv + argc));
  }
  catch (const std::exception& e)
  {
    std::cerr << "evaluate: " << e.what() << "\n" << replay::replayUsage();
    return 2;
  }
  if (options.help)
  {
    std::cerr << replay::replayUsage();
    return 0;
  }
  try
  {
    if (options.check_config)
    {
      replay::loadReplayConfiguration(options);
      std::cout << "configuration valid\n";
      return 0;
    }
    const replay::ReplayReport report = replay::runOfflineReplay(options);
    std::cout << report.markdown << "wrote " << (std::filesystem::path(options.out) / "metrics.json").string()
              << ", metrics.md, scores.csv, snapshots/\n";
    return 0;
  }
  catch (const std::exception& e)
  {
    std::cerr << "\nevaluate: " << e.what() << "\n";
    return 1;
  }
}

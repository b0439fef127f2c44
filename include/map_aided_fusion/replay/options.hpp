/**
 * @file options.hpp
 * @brief What `evaluate` is asked to do: the options of the offline replay, parsed from its command line.
 */
#pragma once

#include <array>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace map_aided_fusion {
namespace replay {

/// The options of an offline replay (see replayUsage()).
struct ReplayOptions
{
  std::string bag;
  std::vector<std::pair<std::string, std::string>> output_bags;  ///< (row name, live recording)
  std::string live_topic = "/map_aided_fusion/decision";
  std::string live_tracks_topic = "/map_aided_fusion/tracks";
  std::string out = "out";
  std::string fusion_config;
  std::string scan_grid_config;
  std::string prior_config;
  std::optional<std::string> pose_covariance_topic;  ///< replaces the fusion config's
  std::string map;
  std::optional<std::array<double, 3>> origin;  ///< latitude, longitude (degrees), altitude (m)
  std::string base_frame = "base_link";
  std::string map_frame = "map";
  double snapshot_time = -1.0;  ///< s after the first scan; < 0: 70 % of the run
  double sheet_period = 5.0;    ///< s between contact-sheet frames
  double match_radius = 1.0;    ///< m: a V cell farther from every moving labelled point is a false V, in [0, 10]
  bool ablations = true;
  bool quiet = false;
  bool check_config = false;    ///< only load and validate the configuration files
  bool help = false;            ///< -h, --help
  std::set<std::string> only;   ///< run only these variants (empty: all)
};

/**
 * @brief The options of @p args (the command line without the program's name).
 * @throws std::runtime_error naming the argument: unknown, missing its value, not a number, --bag missing.
 */
ReplayOptions parseReplayOptions(const std::vector<std::string>& args);

/// The usage text of `evaluate`.
const char* replayUsage();

}  // namespace replay
}  // namespace map_aided_fusion

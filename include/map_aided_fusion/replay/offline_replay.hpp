/**
 * @file offline_replay.hpp
 * @brief The offline replay behind `evaluate`: a bag through the ROS-free core with every variant, scored against
 *        the bag's ground truth (simulator cells, labelled points or labelled boxes), recordings of the live nodelets
 *        scored the same way, and the report written: metrics.json, metrics.md, scores.csv, snapshots/.
 *        No ROS master is needed.
 */
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "map_aided_fusion/core/profiles.hpp"
#include "map_aided_fusion/map_io/prior_grid_params.hpp"
#include "map_aided_fusion/replay/options.hpp"

namespace map_aided_fusion {
namespace replay {

/// The nodelets' configuration files, read without a master and validated.
struct ReplayConfiguration
{
  core::Profile configured;               ///< the MapGrid, ScanGrid and tracker parameters (the prior's: see prior)
  map_io::PriorGridParams prior;          ///< the map loader's file (β, cell test and accuracies validated)
  std::string covariance_topic;           ///< the fusion config's pose_covariance_topic, or the option's
  std::string covariance_type = "pose";   ///< pose or odometry
};

/**
 * @brief Reads and validates --fusion-config, --scan-grid-config and --prior-config (an empty path: the defaults).
 * @throws core::ParameterError naming the parameter; std::runtime_error for a file that cannot be read
 */
ReplayConfiguration loadReplayConfiguration(const ReplayOptions& options);

/// What a replay produced.
struct ReplayReport
{
  std::string markdown;               ///< metrics.md without its title
  std::size_t scans = 0;              ///< clouds replayed
  std::vector<std::string> variants;  ///< the rows scored, offline variants then live recordings
  std::string ground_truth;           ///< "simulator cells", "labelled points" or "labelled boxes"
};

/**
 * @brief Replays options.bag and writes the report into options.out.
 * @throws std::runtime_error for a bag without clouds or ground truth, an unreadable cloud, no variant left by
 *         --only; core::ParameterError for a bad configuration
 */
ReplayReport runOfflineReplay(const ReplayOptions& options);

}  // namespace replay
}  // namespace map_aided_fusion

/**
 * @file report.hpp
 * @brief Pieces of the offline replay's report (metrics.md and metrics.json's meta).
 */
#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "map_aided_fusion/eval/metrics.hpp"

namespace map_aided_fusion {
namespace replay {

/// The deskewing outcomes of a replay, by status: "applied 600", "applied 580, time_out_of_sweep 20"; "none".
std::string deskewSummary(const std::map<std::string, std::size_t>& status);

/**
 * @brief The movers tables of metrics.md: per kind for `default`, `paper` and the live rows, all kinds for every
 *        variant when there are more, and one table per mover for the main rows. "" when no variant scored movers.
 * @param objects_only  no section title (a bag of labelled boxes scores nothing else)
 */
std::string moversSection(const std::vector<eval::VariantScores>& scores, bool objects_only);

/// CLEAR-MOT of the moving tracks against the movers, with its title; "" when no variant tracked.
std::string tracksSection(const std::vector<eval::VariantScores>& scores);

}  // namespace replay
}  // namespace map_aided_fusion

/**
 * @file variants.hpp
 * @brief The variants an offline replay runs: the configured method, the paper's, the paper's ablations and the
 *        configured method without each added step (core::addedSteps()).
 */
#pragma once

#include <set>
#include <string>
#include <vector>

#include "map_aided_fusion/core/profiles.hpp"

namespace map_aided_fusion {
namespace replay {

/// One pipeline to run on the bag.
struct VariantSpec
{
  std::string name;         ///< its row in metrics.md and key in metrics.json
  std::string description;  ///< one line
  core::Profile profile;
  bool use_prior = false;   ///< with the map's PriorGrid (false: a vacuous prior)
};

/**
 * @brief In order: `default` (@p configured), `paper` (core::paperProfile()), with a prior also
 *        `default_no_prior` and `paper_no_prior`; with @p ablations `dempster`, `yager`, `single_rate`,
 *        `no_counter` (the paper with one part changed) and `default_without_<step>` for every added step
 *        @p configured enables. Only the names in @p only when it is not empty.
 */
std::vector<VariantSpec> variantSpecs(const core::Profile& configured, bool have_prior, bool ablations,
                                      const std::set<std::string>& only = {});

}  // namespace replay
}  // namespace map_aided_fusion

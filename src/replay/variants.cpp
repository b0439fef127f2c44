#include "map_aided_fusion/replay/variants.hpp"

namespace map_aided_fusion {
namespace replay {

std::vector<VariantSpec> variantSpecs(const core::Profile& configured, bool have_prior, bool ablations,
                                      const std::set<std::string>& only)
{
  std::vector<VariantSpec> specs;
  auto add = [&](const std::string& name, const std::string& description, const core::Profile& profile,
                 bool use_prior) {
    if (!only.empty() && !only.count(name)) return;
    specs.push_back(VariantSpec{ name, description, profile, use_prior });
  };
  const core::Profile paper = core::paperProfile();
  add("default", "the configured method (config/*.yaml: the paper's pipeline and the steps this package adds)",
      configured, have_prior);
  add("paper", "the paper's exact method (config/paper/*.yaml: prior, contextual discounting, modified Yager rule, "
               "counter and specialisation)",
      paper, have_prior);
  if (have_prior)
  {
    add("default_no_prior", "as default, with a vacuous PriorGrid", configured, false);
    add("paper_no_prior", "as paper, with a vacuous PriorGrid", paper, false);
  }
  if (!ablations) return specs;
  auto paperWith = [&](auto&& change) {
    core::Profile p = paper;
    change(p.map_grid.fusion);
    return p;
  };
  add("dempster", "paper, with Dempster's rule instead of the modified Yager rule",
      paperWith([](core::FusionParams& f) { f.rule = core::CombinationRule::kDempster; }), have_prior);
  add("yager", "paper, with Yager's rule (all conflict to Omega) instead of the modified Yager rule",
      paperWith([](core::FusionParams& f) { f.rule = core::CombinationRule::kYager; }), have_prior);
  add("single_rate", "paper, with classical discounting at one rate (alpha_free) instead of contextual discounting",
      paperWith([](core::FusionParams& f) {
        f.contextual_discounting = false;
        f.alpha_single = f.discount.alpha_free;
      }),
      have_prior);
  add("no_counter", "paper, without the counter zeta and the specialisation",
      paperWith([](core::FusionParams& f) { f.use_counter = false; }), have_prior);
  for (const core::AddedStep& step : core::addedSteps())
  {
    core::Profile p = configured;
    if (!step.enabled(p)) continue;
    step.disable(p);
    add("default_without_" + std::string(step.name),
        "default, without the step " + std::string(step.name) + ": " + std::string(step.summary), p, have_prior);
  }
  // Step motion spreading, off by default since it lost on the labelled real sequences: its measurement beside the
  // default's (doc/steps.md).
  if (!(configured.map_grid.motion_share > 0.0))
  {
    core::Profile p = configured;
    p.map_grid.motion_share = core::kMotionSpreadingShare;
    add("default_with_motion_spreading",
        "default, with the step motion_spreading (off by default): a small occupied region with enough V cells is one "
        "moving object: its open motion goes to {V}",
        p, have_prior);
  }
  // Step ground cells free, off by default since it lost on the labelled real sequences (doc/steps.md).
  if (!configured.scan_grid.ground_cells_free)
  {
    core::Profile p = configured;
    p.scan_grid.ground_cells_free = true;
    add("default_with_ground_cells_free",
        "default, with the step ground_cells_free (off by default): a ScanGrid cell holding a ground return is free, "
        "also beyond its sector's nearest obstacle",
        p, have_prior);
  }
  // The ground model that is not the default's: its measurement beside the default's (doc/steps.md).
  if (configured.scan_grid.groundModel() == core::GroundModel::kPlanes)
  {
    core::Profile p = configured;
    p.scan_grid.ground_model = core::toString(core::GroundModel::kZones);
    add("default_with_ground_zones",
        "default, with the ground model `zones` (a least-squares plane per zone of a concentric zone model, from its "
        "lowest returns) instead of `planes`",
        p, have_prior);
  }
  return specs;
}

}  // namespace replay
}  // namespace map_aided_fusion

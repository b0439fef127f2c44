#include "map_aided_fusion/core/tracking/tracker_params.hpp"

#include <algorithm>

namespace map_aided_fusion {
namespace core {

namespace {

constexpr double kMinCellSize = 0.01;  // m
constexpr double kMaxCellSize = 10.0;  // m
constexpr double kMinStep = 1e-6;      // s between two scans
constexpr int kMaxBound = 1000000;     // max_measurements, max_tracks: beyond any scan, and memory
constexpr double kMaxManoeuvreSigma = 100.0;  // m/s³: the manoeuvring model's jerk noise, at most
constexpr double kMinShare = 1e-3;          // free_space_share: 0 would call everything seen
constexpr double kMaxFreeSpaceTime = 10.0;  // s of ScanGrids kept (memory)

}  // namespace

const std::vector<TrackerStepSwitch>& trackerStepSwitches()
{
  static const std::vector<TrackerStepSwitch> switches{
    { "building_background", &TrackerSteps::building_background },
    { "background_split", &TrackerSteps::background_split },
    { "fragments", &TrackerSteps::fragments },
    { "duplicates", &TrackerSteps::duplicates },
    { "free_space_check", &TrackerSteps::free_space_check },
    { "small_free_space", &TrackerSteps::small_free_space },
    { "walked", &TrackerSteps::walked },
    { "heading_box", &TrackerSteps::heading_box },
    { "long_box", &TrackerSteps::long_box },
    { "second_axes", &TrackerSteps::second_axes },
    { "box_fit", &TrackerSteps::box_fit },
    { "open_ends", &TrackerSteps::open_ends },
    { "hidden_ends", &TrackerSteps::hidden_ends },
    { "open_anchor", &TrackerSteps::open_anchor },
    { "far_growth", &TrackerSteps::far_growth },
    { "manoeuvres", &TrackerSteps::manoeuvres },
    { "common_motion", &TrackerSteps::common_motion },
    { "common_turn", &TrackerSteps::common_turn },
    { "track_evidence", &TrackerSteps::track_evidence },
    { "track_box", &TrackerSteps::track_box },
    { "hidden_length", &TrackerSteps::hidden_length },
    { "hidden_centre", &TrackerSteps::hidden_centre },
    { "box_margin", &TrackerSteps::box_margin },
    { "box_hidden", &TrackerSteps::box_hidden },
    { "small_movers", &TrackerSteps::small_movers },
    { "small_box", &TrackerSteps::small_box },
    { "small_specialised", &TrackerSteps::small_specialised },
    { "movers_without_map", &TrackerSteps::movers_without_map },
  };
  return switches;
}

std::vector<std::string> stepsOff(const TrackerSteps& s)
{
  std::vector<std::string> off;
  for (const TrackerStepSwitch& w : trackerStepSwitches())
    if (!(s.*w.on)) off.emplace_back(w.name);
  return off;
}

TrackerSteps stepsWithOff(const std::vector<std::string>& names)
{
  TrackerSteps s;
  for (const std::string& name : names)
  {
    const auto& all = trackerStepSwitches();
    const auto w = std::find_if(all.begin(), all.end(), [&](const TrackerStepSwitch& x) { return name == x.name; });
    if (w == all.end()) throw ParameterError("tracker_steps_off", "names no tracker step: '" + name + "' (doc/steps.md)");
    s.*(w->on) = false;
  }
  return s;
}

void TrackerParams::validate() const
{
  requireInRange("tracker_cluster_distance", cluster_distance, 2.0 * kMinCellSize, 2.0 * kMaxCellSize);
  requireInRange("tracker_min_cluster_points", min_cluster_points, 1, 1e6);
  requireInRange("tracker_max_measurements", max_measurements, 1, kMaxBound);
  requireInRange("tracker_max_tracks", max_tracks, 1, kMaxBound);
  requirePositive("tracker_max_object_length", max_object_length);
  requirePositive("tracker_max_object_width", max_object_width);
  requirePositive("tracker_pedestrian_size", pedestrian_size);
  requireInRange("tracker_pedestrian_size", pedestrian_size, 0.0, max_object_width);
  requirePositive("tracker_vehicle_length", vehicle_length);
  requireInRange("tracker_vehicle_length", vehicle_length, 0.0, max_object_length);
  requireUnit("tracker_background_zeta", background_zeta);
  requireUnit("tracker_background_share", background_share);
  requirePositive("tracker_measurement_sigma", measurement_sigma);
  requireInRange("tracker_extent_sigma", extent_sigma, 0.0, 10.0);
  requirePositive("tracker_acceleration_sigma", acceleration_sigma);
  requirePositive("tracker_manoeuvre_jerk_sigma", manoeuvre_jerk_sigma);
  requireInRange("tracker_manoeuvre_jerk_sigma", manoeuvre_jerk_sigma, 0.0, kMaxManoeuvreSigma);
  requirePositive("tracker_gate", gate);
  requirePositive("tracker_max_gate_distance", max_gate_distance);
  requireInRange("tracker_confirm_hits", confirm_hits, 1, 1000);
  requireInRange("tracker_max_coast_time", max_coast_time, 0.0, 60.0);
  requireInRange("tracker_moving_speed", moving_speed, 0.0, 100.0);
  requireInRange("tracker_motion_sigmas", motion_sigmas, 0.0, 10.0);
  requireInRange("tracker_stopped_speed", stopped_speed, 0.0, 100.0);
  requireInRange("tracker_stopped_time", stopped_time, 0.0, 600.0);
  requirePositive("tracker_max_speed", max_speed);
  requirePositive("tracker_max_ego_speed", max_ego_speed);
  requireUnit("tracker_evidence_weight", evidence_weight);
  requireInRange("tracker_free_space_share", free_space_share, kMinShare, 1.0);
  requireInRange("tracker_free_space_margin", free_space_margin, 0.0, kMaxCellSize);
  requireInRange("tracker_free_space_time", free_space_time, kMinStep, kMaxFreeSpaceTime);
}

}  // namespace core
}  // namespace map_aided_fusion

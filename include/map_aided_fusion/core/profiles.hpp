/**
 * @file profiles.hpp
 * @brief Named parameter sets of the whole pipeline: the paper's exact method and this package's default.
 *
 * The `paper` profile is the method of Kurdej et al. bit for bit (every step this package adds is off); it is
 * what the files of `config/paper/` holds and what `evaluate` runs as the `paper` variant. The `default` profile is
 * the parameter structs' defaults, what the files of `config/` hold. Tests check both files against these functions.
 */
#pragma once

#include <vector>

#include "map_aided_fusion/core/map_grid.hpp"
#include "map_aided_fusion/core/prior_grid.hpp"
#include "map_aided_fusion/core/scan_grid.hpp"
#include "map_aided_fusion/core/tracker.hpp"

namespace map_aided_fusion {
namespace core {

/// The parameters of the ScanGrid, of the MapGrid and how the PriorGrid is made (its β are the same in both).
struct Profile
{
  ScanGridParams scan_grid;
  MapGridParams map_grid;
  PriorGridOptions prior;
  TrackerParams tracker;  ///< tracked objects (config/fusion.yaml, tracker_*); off in the paper's method
};

/**
 * @brief A step this package adds to the paper's pipeline: a name (its entry in doc/steps.md), what it does,
 *        and how to tell and switch it in a profile. Each is off in the paper profile.
 */
struct AddedStep
{
  const char* name;
  const char* summary;
  bool (*enabled)(const Profile&);
  void (*disable)(Profile&);
};

/// Every added step, in pipeline order.
const std::vector<AddedStep>& addedSteps();

/// The paper's method: every added step off, the paper's α, β, δ, γ, μ.
Profile paperProfile();

/// This package's default (the files of config/): the structs' defaults, the self box of a passenger car with
/// its lidar on the roof (carSelfBox()) and a ScanGrid that covers the MapGrid's window (scanGridCoveringWindow()).
Profile defaultProfile();

/// Side of a square ScanGrid (vehicle frame, m) that covers a MapGrid window of @p window_x × @p window_y (map
/// frame, centred on the vehicle) whatever the heading: its diagonal, rounded up to a metre (142 m for 100 m).
/// The paper's 100 m ScanGrid leaves the window's corners unseen when the heading is not along an axis.
double scanGridCoveringWindow(double window_x, double window_y);

/// Sets @p p's self box to a passenger car's with its lidar on the roof, base_link on the ground under the lidar:
/// x in [−2.7, 2.7] m, y in [−1.7, 1.7] m (KITTI's car returns its own roof edges and mirrors up to 1.6 m beside
/// the lidar, and its bonnet 2.5 m ahead of it). The paper's profile has none.
void carSelfBox(ScanGridParams& p);

/// @p p with every step this package adds to the paper switched off (the rest unchanged).
Profile withoutAddedSteps(Profile p);

}  // namespace core
}  // namespace map_aided_fusion

#include "map_aided_fusion/core/profiles.hpp"

#include <cmath>

namespace map_aided_fusion {
namespace core {

const std::vector<AddedStep>& addedSteps()
{
  static const std::vector<AddedStep> steps{
    { "cell_coverage", "the prior from the share of each cell covered by buildings and roads; outline cells are {F, C}",
      [](const Profile& p) { return p.prior.cell_test == PriorCellTest::kCoverage; },
      [](Profile& p) { p.prior.cell_test = PriorCellTest::kCentre; } },
    { "map_accuracy", "the prior softened by the map's positional accuracy (building_accuracy, road_accuracy)",
      [](const Profile& p) { return p.prior.building_accuracy > 0.0 || p.prior.road_accuracy > 0.0; },
      [](Profile& p) { p.prior.building_accuracy = p.prior.road_accuracy = 0.0; } },
    { "map_conflict", "a per-cell doubt about the map, grown where the scan sees through a mapped building, discounts the prior",
      [](const Profile& p) { return p.map_grid.map_conflict_gain > 0.0; },
      [](Profile& p) { p.map_grid.map_conflict_gain = 0.0; } },
    { "deskew", "each point of a sweep moved to the sensor's pose at the cloud's stamp (clouds with a time field)",
      [](const Profile& p) { return p.scan_grid.deskew; },
      [](Profile& p) { p.scan_grid.deskew = false; } },
    { "ground_model", "heights measured from ground planes fitted per zone and scan (planes or zones), not from a flat ground",
      [](const Profile& p) { return p.scan_grid.groundModel() != GroundModel::kFlat; },
      [](Profile& p) { p.scan_grid.ground_model = toString(GroundModel::kFlat); } },
    { "relative_height", "a low obstacle return must stand obstacle_min_height above the lowest return around it",
      [](const Profile& p) { return p.scan_grid.relative_height_limit > 0.0; },
      [](Profile& p) { p.scan_grid.relative_height_limit = 0.0; } },
    { "ambiguous_unknown", "a ScanGrid cell holding a return neither ground nor obstacle gets no free mass",
      [](const Profile& p) { return p.scan_grid.ambiguous_unknown; },
      [](Profile& p) { p.scan_grid.ambiguous_unknown = false; } },
    { "ground_cells_free", "a ScanGrid cell holding a ground return is free, also beyond its sector's nearest obstacle",
      [](const Profile& p) { return p.scan_grid.ground_cells_free; },
      [](Profile& p) { p.scan_grid.ground_cells_free = false; } },
    { "ground_consensus", "a return one fitted ground model calls ground and the other obstacle bounds free space, no mass "
                          "(inert with the flat model)",
      [](const Profile& p) { return p.scan_grid.ground_consensus; },
      [](Profile& p) { p.scan_grid.ground_consensus = false; } },
    { "point_occupancy", "occupied evidence in the window cell under each obstacle return, not resampled scan cells",
      [](const Profile& p) { return p.map_grid.point_occupancy; },
      [](Profile& p) { p.map_grid.point_occupancy = false; } },
    { "obstacle_clearance", "no free evidence within obstacle_clearance of an obstacle return",
      [](const Profile& p) { return p.map_grid.obstacle_clearance > 0.0; },
      [](Profile& p) { p.map_grid.obstacle_clearance = 0.0; } },
    { "building_conflict", "the conflict between {F} and evidence that can only be the mapped building goes to Omega, not V",
      [](const Profile& p) { return p.map_grid.fusion.building_conflict; },
      [](Profile& p) { p.map_grid.fusion.building_conflict = false; } },
    { "moving_expiry", "m({V}) goes to Omega where the scan holds no occupied mass",
      [](const Profile& p) { return p.map_grid.fusion.moving_expiry; },
      [](Profile& p) { p.map_grid.fusion.moving_expiry = false; } },
    { "motion_spreading", "a small occupied region with enough V cells is one moving object: its open motion goes to {V}",
      [](const Profile& p) { return p.map_grid.motion_share > 0.0; },
      [](Profile& p) { p.map_grid.motion_share = 0.0; } },
    { "motion_margin", "S or V within motion_margin of each other is decided 'occupied, motion not yet known'",
      [](const Profile& p) { return p.map_grid.motion_margin > 0.0; },
      [](Profile& p) { p.map_grid.motion_margin = 0.0; } },
    { "building_background", "a return on a cell decided mapped building lies on static background, as one on a high counter",
      [](const Profile& p) { return p.tracker.enabled && p.tracker.steps.building_background; },
      [](Profile& p) { p.tracker.steps.building_background = false; } },
    { "fragments", "a cluster in the box of a moving track (grown by 1 m) starts no track of its own",
      [](const Profile& p) { return p.tracker.enabled && p.tracker.steps.fragments; },
      [](Profile& p) { p.tracker.steps.fragments = false; } },
    { "duplicates", "a moving track inside the object box of a moving track with more hits is deleted; its cluster and the fragments take that track's motion",
      [](const Profile& p) { return p.tracker.enabled && p.tracker.steps.duplicates; },
      [](Profile& p) { p.tracker.steps.duplicates = false; } },
    { "free_space_check", "a track is moving only once free space shows that it left a place or came into one",
      [](const Profile& p) { return p.tracker.enabled && p.tracker.steps.free_space_check; },
      [](Profile& p) { p.tracker.steps.free_space_check = false; } },
    { "small_free_space", "a pedestrian-sized track walking beside obstacles is checked for free space with a tighter margin",
      [](const Profile& p) { return p.tracker.enabled && p.tracker.steps.small_free_space; },
      [](Profile& p) { p.tracker.steps.small_free_space = false; } },
    { "heading_box", "the box of a short moving track turns to its heading once askew (an object that turns)",
      [](const Profile& p) { return p.tracker.enabled && p.tracker.steps.heading_box; },
      [](Profile& p) { p.tracker.steps.heading_box = false; } },
    { "track_evidence", "a moving track supports {V} in its cells, a stopped one {S}; one not yet known makes them neither",
      [](const Profile& p) { return p.tracker.enabled && p.tracker.steps.track_evidence; },
      [](Profile& p) { p.tracker.steps.track_evidence = false; } },
    { "track_box", "track evidence also in the cells of a track's box that hold none of its returns",
      [](const Profile& p) { return p.tracker.enabled && p.tracker.steps.track_box; },
      [](Profile& p) { p.tracker.steps.track_box = false; } },
    { "hidden_length", "a moving vehicle seen end-on: its track box extends away from the sensor to a vehicle's length",
      [](const Profile& p) { return p.tracker.enabled && p.tracker.steps.hidden_length; },
      [](Profile& p) { p.tracker.steps.hidden_length = false; } },
    { "box_margin", "a moving track's box grows across its axis by a margin: the cells its sides half cover",
      [](const Profile& p) { return p.tracker.enabled && p.tracker.steps.box_margin; },
      [](Profile& p) { p.tracker.steps.box_margin = false; } },
    { "box_hidden", "the box cells of a moving track that the scan did not see free also move their free mass to V",
      [](const Profile& p) { return p.tracker.enabled && p.tracker.steps.box_hidden; },
      [](Profile& p) { p.tracker.steps.box_hidden = false; } },
    { "small_movers", "a pedestrian-sized moving track also moves to V the sets holding N (a pavement's prior {N, S, V})",
      [](const Profile& p) { return p.tracker.enabled && p.tracker.steps.small_movers; },
      [](Profile& p) { p.tracker.steps.small_movers = false; } },
    { "small_box", "a pedestrian-sized moving track's box grows to a pedestrian's size behind its returns and across",
      [](const Profile& p) { return p.tracker.enabled && p.tracker.steps.small_box; },
      [](Profile& p) { p.tracker.steps.small_box = false; } },
    { "small_specialised", "a pedestrian-sized moving track also moves to V its cells' mass on {N}, {S} and {N, S}",
      [](const Profile& p) { return p.tracker.enabled && p.tracker.steps.small_specialised; },
      [](Profile& p) { p.tracker.steps.small_specialised = false; } },
    { "movers_without_map", "without a prior, a moving track's return cells (a small mover's box too) also move to V the sets holding C or N",
      [](const Profile& p) { return p.tracker.enabled && p.tracker.steps.movers_without_map; },
      [](Profile& p) { p.tracker.steps.movers_without_map = false; } },
    { "open_ends", "a partly seen cluster whose end nearest the sensor is occluded, and the other open, is anchored on the other",
      [](const Profile& p) { return p.tracker.enabled && p.tracker.steps.open_ends; },
      [](Profile& p) { p.tracker.steps.open_ends = false; } },
    { "hidden_centre", "a moving vehicle seen end-on is reported at the centre of the box of step hidden_length, not of its face",
      [](const Profile& p) { return p.tracker.enabled && p.tracker.steps.hidden_centre; },
      [](Profile& p) { p.tracker.steps.hidden_centre = false; } },
    { "common_motion", "when many confirmed tracks agree on one slow velocity (a drifting pose), motion is decided relative to it",
      [](const Profile& p) { return p.tracker.enabled && p.tracker.steps.common_motion; },
      [](Profile& p) { p.tracker.steps.common_motion = false; } },
    { "background_split", "the returns of a cluster too long or wide that are not on static background are clustered again: a pedestrian beside a wall",
      [](const Profile& p) { return p.tracker.enabled && p.tracker.steps.background_split; },
      [](Profile& p) { p.tracker.steps.background_split = false; } },
    { "walked", "a small walker seen in each of its last scans that moved far enough has shown its motion as free space would",
      [](const Profile& p) { return p.tracker.enabled && p.tracker.steps.walked; },
      [](Profile& p) { p.tracker.steps.walked = false; } },
    { "second_axes", "a new track whose first cluster was nearly as wide as long takes the axes of its elongated, longer second cluster",
      [](const Profile& p) { return p.tracker.enabled && p.tracker.steps.second_axes; },
      [](Profile& p) { p.tracker.steps.second_axes = false; } },
    { "hidden_ends", "a cluster whose two ends are hidden and neither open (a car seen through a gap) tells a track not yet moving nothing along its axis",
      [](const Profile& p) { return p.tracker.enabled && p.tracker.steps.hidden_ends; },
      [](Profile& p) { p.tracker.steps.hidden_ends = false; } },
    { "box_fit", "a cluster's axes are those of the rectangle that fits its returns best, not its principal axes (a vehicle's L of rear and side)",
      [](const Profile& p) { return p.tracker.enabled && p.tracker.steps.box_fit; },
      [](Profile& p) { p.tracker.steps.box_fit = false; } },
    { "open_anchor", "a cluster placed by its end nearest the sensor, with free space beyond it, has a compact cluster's sigma along its axis",
      [](const Profile& p) { return p.tracker.enabled && p.tracker.steps.open_anchor; },
      [](Profile& p) { p.tracker.steps.open_anchor = false; } },
    { "far_growth", "a cluster placed by its open end along the box's axes grew at its other end (a car coming out from behind an occluder): its growth leaves its sigma as it was",
      [](const Profile& p) { return p.tracker.enabled && p.tracker.steps.far_growth; },
      [](Profile& p) { p.tracker.steps.far_growth = false; } },
    { "manoeuvres", "the motion model is an interacting multiple model of constant velocity and constant acceleration (braking, turning)",
      [](const Profile& p) { return p.tracker.enabled && p.tracker.steps.manoeuvres; },
      [](Profile& p) { p.tracker.steps.manoeuvres = false; } },
    { "long_box", "a moving track's box turns to the axis of its long cluster (a bus pulling in), within 20° of its heading",
      [](const Profile& p) { return p.tracker.enabled && p.tracker.steps.long_box; },
      [](Profile& p) { p.tracker.steps.long_box = false; } },
    { "common_turn", "the common motion may turn about the sensor (a drifting heading): static objects far away are no faster than near ones",
      [](const Profile& p) { return p.tracker.enabled && p.tracker.steps.common_turn; },
      [](Profile& p) { p.tracker.steps.common_turn = false; } },
  };
  return steps;
}

Profile withoutAddedSteps(Profile p)
{
  for (const AddedStep& s : addedSteps()) s.disable(p);
  return p;
}

namespace {

constexpr double kCarSelfBoxRear = -2.7;   // m, x of the car's rear from the lidar
constexpr double kCarSelfBoxFront = 2.7;   // m, x of its front (the bonnet, which KITTI's lidar sees at 2.5 m)
constexpr double kCarSelfBoxHalfWidth = 1.7;  // m, half its width with the mirrors, and a margin

}  // namespace

void carSelfBox(ScanGridParams& p)
{
  p.self_box_min_x = kCarSelfBoxRear;
  p.self_box_max_x = kCarSelfBoxFront;
  p.self_box_min_y = -kCarSelfBoxHalfWidth;
  p.self_box_max_y = kCarSelfBoxHalfWidth;
}

double scanGridCoveringWindow(double window_x, double window_y)
{
  return std::ceil(std::hypot(window_x, window_y));
}

Profile defaultProfile()
{
  Profile p;
  carSelfBox(p.scan_grid);
  p.scan_grid.grid_size_x = p.scan_grid.grid_size_y = scanGridCoveringWindow(p.map_grid.size_x, p.map_grid.size_y);
  return p;
}

Profile paperProfile()
{
  Profile p = withoutAddedSteps(Profile{});
  p.tracker.enabled = false;
  return p;
}

}  // namespace core
}  // namespace map_aided_fusion

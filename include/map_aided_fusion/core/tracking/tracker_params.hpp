/**
 * @file tracker_params.hpp
 * @brief The tracker's parameters (config/fusion.yaml, `tracker_*`): what a user sets, the added steps that
 *        `tracker_steps_off` switches off by name, and the fixed numbers of those steps.
 */
#pragma once

#include <string>
#include <vector>

#include "map_aided_fusion/core/parameters.hpp"

namespace map_aided_fusion {
namespace core {

/// Default TrackerParams::max_measurements and max_tracks: about six times the most seen in one scan of any dataset
/// (KITTI tracking 0000: 170 measurements, 185 tracks; SemanticKITTI 06: 140 and 158; doc/reliability.md).
constexpr int kDefaultMaxMeasurements = 1000;
constexpr int kDefaultMaxTracks = 1000;

/// @name Fixed numbers of the tracker's steps
/// Each belongs to one step (TrackerSteps) and is not a parameter: a maintainer changes it in the code, with the
/// step's measurements (doc/steps.md). The numbers of the parts' own models are their parameter structs' defaults
/// (BoxFitParams, CommonMotionParams, MeasurementModelParams, MotionDecisionParams).
/// @{
/// m: step fragments: how far beyond a moving track's box a cluster is a piece of it (and step duplicates' margin).
constexpr double kFragmentMargin = 1.0;
/// BetP(C) above which a return lies on a mapped building (step building background): the cell is decided building.
constexpr double kBuildingBackgroundBetP = 0.5;
/// deg: step heading box turns a box whose axes are this far from the heading; step long box takes an axis within it.
constexpr double kHeadingBoxAngleDeg = 20.0;
/// m: step heading box turns only boxes no longer than this (cyclists, pedestrians).
constexpr double kHeadingBoxMaxLength = 2.5;
/// m: step long box takes the axis of clusters at least this long (a bus, a lorry), not a car's L seen end-on.
constexpr double kLongBoxMinLength = 6.0;
/// m: how far beyond a cluster's end step open ends looks for free space and for an occluder's shadow.
constexpr double kOpenEndDistance = 1.0;
/// Step walked: consecutive associations of a small walker, and how far (m) it moved since its oldest sighting.
constexpr int kWalkMinHits = 10;
constexpr double kWalkDistance = 0.5;
/// Step small free space: the free-space margin (m) of a pedestrian-sized track, its least extent on both axes (m;
/// a sliver of a wall seen edge-on is thinner) and its greatest speed (m/s; a walk).
constexpr double kSmallFreeSpaceMargin = 0.0;
constexpr double kSmallMinExtent = 0.1;
constexpr double kWalkingMaxSpeed = 2.0;
/// Step second axes: a first cluster at least this wide for its length has no axis; a second cluster at most
/// kSecondAxesElongation wide for its length has one, and turns the box when longer than kSecondAxesGrowth times the
/// first.
constexpr double kSecondAxesRound = 0.4;
constexpr double kSecondAxesElongation = 0.5;
constexpr double kSecondAxesGrowth = 1.5;
/// m: the narrowest face that is a vehicle's end (steps hidden length, hidden centre); a cyclist's is narrower.
constexpr double kVehicleMinEndWidth = 1.4;
/// m: step box margin: a moving track's box grows by this on each side across its axis (about a beam step at 20 m).
constexpr double kBoxMargin = 0.1;
/// m/s: velocity standard deviation of a new track (about the speed of a city's traffic).
constexpr double kInitialSpeedSigma = 5.0;
/// @}

/**
 * @brief The tracker's added steps (doc/steps.md), each on by default; `tracker_steps_off` lists those switched
 *        off by name (core::addedSteps() holds the same names; the paper profile has them all off).
 */
struct TrackerSteps
{
  /// "building background": a return on a MapGrid cell whose BetP(C) (a mapped building: the PriorGrid's B, kept by
  /// the fusion) is above kBuildingBackgroundBetP lies on static background too. A facade first seen far away, before
  /// its counter has grown, slides along its visible part while the vehicle drives and made false moving tracks.
  /// Without a prior BetP(C) is 0 and the step does nothing.
  bool building_background = true;
  /// "background split": a pedestrian walking beside a wall, a hedge or a row of parked cars touches them, and its
  /// returns join their cluster, longer than max_object_length or wider than max_object_width, which is no
  /// measurement. The returns of such a cluster that do not lie on static background are clustered again, and those
  /// pieces at most pedestrian_size long and wide are measurements (Measurement::split). A piece is associated only
  /// with a track whose box is at most that size: a vehicle's track does not jump to a piece of it.
  bool background_split = true;
  /// "fragments": an object seen in several clusters (a bus's side behind its face, a van past an occluder, the
  /// sparse returns of a far car) gets one track per cluster, and every track but one is a false moving object. A
  /// cluster no track takes whose centroid lies in the box of a moving track seen this scan, grown by
  /// kFragmentMargin on every side, starts no track (and is counted).
  bool fragments = true;
  /// "duplicates": one object can still hold several moving tracks: clusters that started their track before the
  /// object's own track moved, the returns of a lidar ring that slides along a car's roof at a fixed range from the
  /// sensor, a van's side sampled column by column at a grazing angle. A moving track seen this scan whose object box
  /// (objectBox()) has its centre in the object box of a moving track with more hits seen this scan, grown by
  /// kFragmentMargin, and that moves within 60° of its heading (two objects passing each other do not), is a
  /// duplicate of it: it is deleted (and counted). Its cluster, and with this step every fragment, is then a piece of
  /// the other's object: step fragments tests the object box, and the pieces' returns take the track's motion
  /// (Track::fragments, step track evidence).
  bool duplicates = true;
  /// "free-space check": a track is moving only once free space shows the motion, i.e. free_space_share of its
  /// returns of an earlier scan lies where the last scan saw free space (it left), or of its returns of the last scan
  /// where an earlier scan saw free space (it came). A velocity alone does not tell an object from a fragment of a
  /// wall or a hedge whose visible part slides as the vehicle drives by. While the check runs, the speed need clear
  /// moving_speed by MotionDecisionParams::free_space_motion_sigmas only.
  bool free_space_check = true;
  /// "small free space": a pedestrian walks beside facades, parked cars and poles, whose cells lie within
  /// free_space_margin of it, so that free space never shows where it left or came. A track at most pedestrian_size
  /// long and wide, at least kSmallMinExtent on both axes and no faster than kWalkingMaxSpeed is checked with
  /// kSmallFreeSpaceMargin instead.
  bool small_free_space = true;
  /// "walked" (with the free-space check): a pedestrian on a pavement behind parked cars is hidden from the ground
  /// around it, so free space never shows where it left or came. A track checked as a small walker (step small free
  /// space) that was associated in each of its last kWalkMinHits scans and whose position moved at least
  /// kWalkDistance, relative to the common motion, since its oldest sighting the check keeps (free_space_time ago)
  /// has shown its motion as the free-space check would.
  bool walked = true;
  /// "heading box": a track's box keeps the axes of its first cluster, so an object that turns is seen askew in them:
  /// its box grows (a cyclist's to 1.7 × 1.6 m) and the point followed slides off the object until the gate loses it.
  /// A moving track's box no longer than kHeadingBoxMaxLength turns to its heading, from the cluster of that scan,
  /// once it is askew by more than kHeadingBoxAngleDeg. A longer object is seldom seen whole (a van behind a car):
  /// the middle of its cluster is not its box's, so its box keeps its axes.
  bool heading_box = true;
  /// "long box": a long vehicle keeps the axes of its first cluster too (the front face of a bus seen from 70 m), and
  /// when it turns (a bus pulling in to a stop at 16°) its box, grown to hold every cluster in those axes, swells (6 ×
  /// 12 m for a 2.5 × 12 m bus), and the point the track follows slides across it. A moving track whose cluster is at
  /// least kLongBoxMinLength long, at most half as wide, and whose major axis lies within kHeadingBoxAngleDeg of the
  /// track's heading, turns its box to that axis once the box is more than 6° from it, extents and middle from that
  /// cluster. Shorter clusters (a car's L seen end-on) do not give an axis this reliable.
  bool long_box = true;
  /// "second axes": a new track's box takes the axes of its first cluster, which has none when it is nearly as wide
  /// as long: the corner of a car coming out of a shadow, whose axes can be 20° off the car's, so that the point the
  /// track follows (referencePoint()) moves across the car as its side grows. When the track's second cluster is
  /// elongated and much longer than the first (kSecondAxesRound, kSecondAxesElongation, kSecondAxesGrowth), the box
  /// turns to the second cluster's axes (unless within 6° of them) before that cluster corrects the track; its
  /// extents become those of the old box seen along the new axes (the rectangle around it).
  bool second_axes = true;
  /// "box fit": a cluster's axes are those of the rectangle that fits its returns best, not its principal axes
  /// (BoxFitParams: the closeness criterion of L-shape fitting, Zhang et al. 2017). A vehicle seen on its rear and one
  /// side gives an L of returns whose principal axes lie between the two faces: its box was askew by up to 45°, grew
  /// as more of the side came into view, and the point its track follows slid across the vehicle.
  bool box_fit = true;
  /// "open ends": which end of a partly seen cluster is the object's end. The box of a cluster shorter than the
  /// track's is anchored on the cluster's end nearest the sensor, but an occluder nearer the sensor can cut exactly
  /// that end (a car coming out of the shadow of a parked car on the sensor's side). Along each axis of the box within
  /// 20° of the cluster's, when the sensor's line of sight to the point kOpenEndDistance beyond the near end is
  /// blocked by an obstacle at least 1 m nearer, and the scan saw free space (SeenFree at free_space_margin) at that
  /// distance beyond the other end, the other end anchors the box (referencePoint(), the box's growth). Needs a
  /// ScanGrid.
  bool open_ends = true;
  /// "hidden ends" (with step open ends, which finds the hidden ends): a cluster whose two ends along its major axis
  /// are both hidden from the sensor by nearer obstacles, neither with free space beyond it, is the part of an object
  /// seen through a gap. For a track not yet moving, the measurement's σ along that axis grows by
  /// MeasurementModelParams::hidden_ends_sigma, so that such views do not make it moving with the gap's motion.
  bool hidden_ends = true;
  /// "open anchor" (with step open ends): when the anchoring end of a cluster along its major axis has free space
  /// seen beyond it, it is the object's own end, placed as well as a compact cluster's centroid: the measurement's σ
  /// along that axis is measurement_sigma, without the extent_sigma share of the cluster's length. That share kept the
  /// gain of a long vehicle's track low, and its velocity lagged by up to 2 m/s as it braked.
  bool open_anchor = true;
  /// "far growth" (with step open anchor): a cluster placed by its open anchoring end, whose major axis is that of the
  /// track's box, grew or shrank at its other end: its change of length since the track's last cluster does not enter
  /// the measurement's σ along that axis (the first velocity reported for a car coming out from behind an occluder at
  /// 12 m/s was 7.9 m/s).
  bool far_growth = true;
  /// "manoeuvres" (core/tracking/motion_model.hpp, ImmState): the motion model is an interacting multiple model of
  /// the constant-velocity model and a constant-acceleration one (white-noise jerk manoeuvre_jerk_sigma), which
  /// follows braking, pulling away and turning; off: the constant-velocity model alone. Per class, as the field's
  /// trackers choose their motion models: a track whose first cluster is at most pedestrian_size long and wide (a
  /// walker) keeps the constant-velocity model alone.
  bool manoeuvres = true;
  /// "common motion": a pose that drifts (a localisation's slow error) moves the whole static world in the map
  /// frame, and the track of every static object takes that drift as its velocity (KITTI 00's first sweeps: 1.0 to
  /// 1.6 m/s, all one way). The scan's common motion (Tracker::commonMotion(), core/tracking/common_motion.hpp) is the
  /// median velocity of the confirmed tracks seen in the scan when enough of them agree with it and it is slow (a
  /// drift, not traffic). The motion decision and P(motion) of track evidence then take each track's speed relative
  /// to it; the velocities reported stay the tracks'.
  bool common_motion = true;
  /// "common turn" (with common motion): a heading that drifts turns the whole static world about the sensor, so its
  /// objects move at speeds that grow with their distance (KITTI 00's last sweeps: 0.4 m/s ahead, 1.6 m/s 40 m
  /// behind). The common motion is then a rigid motion about the sensor, v(p) = v₀ + ω × (p − sensor), when it agrees
  /// with more tracks than the median does (fitCommonMotion()).
  bool common_turn = true;
  /// "track evidence" (core/track_evidence.hpp): a moving track supports {V} in its cells, a stopped one {S}, with
  /// weight β = evidence_weight · P(motion).
  bool track_evidence = true;
  /// "track box": track evidence also in the cells of the measurement's box that hold none of its returns (seen over
  /// or hidden behind the object's near side), from the sets that already hold the track's class only.
  bool track_box = true;
  /// "hidden length": a moving track seen end-on (its cluster at least kVehicleMinEndWidth wide across its heading
  /// and shallower than vehicle_length along it: a car's rear or front face) has its box, for the track box, extended
  /// away from the sensor along its heading to vehicle_length. The body behind the face holds no return (the rays end
  /// on the face or pass over the roof) and otherwise keeps the prior.
  bool hidden_length = true;
  /// "hidden centre": a moving track seen end-on (as for step hidden length) reports (reportedBox(): the tracks topic,
  /// the scoring) the box of step hidden length and its centre, half a vehicle's length behind the face seen. A scan
  /// that misses it (the track coasts) keeps that box where its last sighting put it, relative to the track's
  /// position and heading (Track::seen_box).
  bool hidden_centre = true;
  /// "box margin": a moving track's box (of step track box; not a small mover's) grows by kBoxMargin on each side
  /// across its axis. A side's outermost returns lie up to a beam step inside the object's outline, so the cells that
  /// its sides half cover have their centres just outside the cluster's box.
  bool box_margin = true;
  /// "box hidden": the cells of a moving track's box that the scan did not see free (behind its near side, under the
  /// rays over its roof) also move their free sets, {F} and {F, S}, to V, as a cell of its returns does: their free
  /// evidence is older than the object that drove in. Cells the scan sees free stay free.
  bool box_hidden = true;
  /// "small movers": a moving track at most pedestrian_size long and wide also moves to V the sets that hold N, which
  /// track evidence otherwise leaves to the prior and the counter: a pavement's prior is {N, S, V}.
  bool small_movers = true;
  /// "small box": such a small mover's box, for the track box, is grown to pedestrian_size along the line of sight
  /// (away from the sensor: the rays end on its near side) and across it, so that it covers the body behind the
  /// returns.
  bool small_box = true;
  /// "small specialised": a small mover's cells also move to V their mass on {N}, {S} and {N, S} (and, in its
  /// returns' cells, on the sets within {F, N, S}): a walker stays in a cell for several scans, and the counter
  /// specialises the pavement's {N, S, V} to {N, S} before its track is moving.
  bool small_specialised = true;
  /// "movers without map": without a prior the grid never tells C and N from S and V (the scan's O is {C, N, S, V}),
  /// so the cells of a moving track's returns, and the box cells of a small mover, also move to V the sets holding C
  /// or N. With a prior, C and N are the map's and the counter's and stay.
  bool movers_without_map = true;
};

/// Every step of TrackerSteps: its name (doc/steps.md, `tracker_steps_off`) and its switch.
struct TrackerStepSwitch
{
  const char* name;
  bool TrackerSteps::*on;
};
const std::vector<TrackerStepSwitch>& trackerStepSwitches();

/// The names of the steps of @p s that are off, in trackerStepSwitches()' order.
std::vector<std::string> stepsOff(const TrackerSteps& s);

/// The steps with exactly those of @p names off. @throws ParameterError naming `tracker_steps_off` for a name that
/// is no tracker step.
TrackerSteps stepsWithOff(const std::vector<std::string>& names);

/// The tracker's parameters (config/fusion.yaml, `tracker_*`): what a user sets for a vehicle, a lidar and its
/// traffic, with units in the comments. The steps' own numbers are the named constants above.
struct TrackerParams
{
  bool enabled = true;               ///< run the tracker (false in the paper profile)
  double cluster_distance = 0.6;     ///< m: returns in cells of half this size that touch are one cluster
  int min_cluster_points = 12;       ///< a cluster with fewer returns is no measurement
  double max_object_length = 18.0;   ///< m: a longer cluster (a wall, a fence, a hedge) is no object; an articulated bus is shorter
  double max_object_width = 4.0;     ///< m: a wider cluster is no object
  /// m: a pedestrian's size, the longest and widest track taken for one (steps background split, small free space,
  /// small movers, small box).
  double pedestrian_size = 1.0;
  /// m: a vehicle's length, to which the box of a vehicle seen end-on extends (steps hidden length, hidden centre).
  double vehicle_length = 4.0;
  /// A return on a MapGrid cell whose counter ζ is above this lies on static background (occupied scan after scan:
  /// a facade, a parked car); ζ grows by delta_inc per consistent occupied scan …
  double background_zeta = 0.4;
  /// … and a cluster with more than this share of its returns on background is no moving-object candidate, not
  /// tracked; 1: off.
  double background_share = 0.5;
  double measurement_sigma = 0.15;   ///< m, standard deviation of a compact cluster's centroid
  double extent_sigma = 0.1;         ///< m of standard deviation per metre of the cluster's extent on that axis
  double acceleration_sigma = 2.0;   ///< m/s², white-noise acceleration of the constant-velocity model
  double manoeuvre_jerk_sigma = 5.0;  ///< m/s³, white-noise jerk of the constant-acceleration model (step manoeuvres)
  double gate = 13.8;                ///< Mahalanobis² of an association (χ² with 2 dof: 13.8 is 99.9 %)
  double max_gate_distance = 3.0;    ///< m: no association farther than this, whatever the covariance
  int confirm_hits = 3;              ///< consecutive associations that confirm a tentative track
  double max_coast_time = 0.5;       ///< s without an association before a confirmed track is deleted
  /// The bounds of a scan's cost (rain, a flock of birds, a street lined with hedges): at most max_measurements
  /// measurements a scan, the nearest to the sensor (the others are dropped and counted), and at most max_tracks
  /// tracks (clusters that would start one beyond are counted, not tracked; the nearest start first).
  int max_measurements = kDefaultMaxMeasurements;
  int max_tracks = kDefaultMaxTracks;
  double moving_speed = 0.5;         ///< m/s: moving when speed − motion_sigmas · σ(speed) is above this
  double motion_sigmas = 1.5;        ///< how many standard deviations the speed must clear
  double stopped_speed = 0.8;        ///< m/s: stopped when speed + motion_sigmas · σ(speed) stays below this …
  double stopped_time = 1.0;         ///< s … for this long
  double max_speed = 50.0;           ///< m/s: a track estimated faster is deleted (a wrong association)
  double max_ego_speed = 70.0;       ///< m/s: a vehicle pose moving faster between two scans resets every track
  double free_space_share = 0.3;     ///< share of a sighting's returns that must lie in free space, (0, 1] (free-space check)
  double free_space_margin = 0.5;    ///< m: a point is in free space when every ScanGrid cell this near was seen free
  double free_space_time = 1.0;      ///< s: how far back sightings and scans are compared (free-space check)
  /// Weight w of a track's motion in its cells' masses, β = w · P(motion) (step track evidence).
  double evidence_weight = 0.8;
  TrackerSteps steps;                ///< the added steps (`tracker_steps_off`: those off)

  /// @throws ParameterError naming the first parameter out of range.
  void validate() const;
};

/// Calls get(name, field) for every parameter, with the names of config/fusion.yaml.
template <class Get>
void forEachParam(TrackerParams& p, Get&& get)
{
  get("tracker", p.enabled, { "", "run the tracker (tracks topic, track evidence)" });
  get("tracker_cluster_distance", p.cluster_distance, { "m", "returns in touching cells of half this size are one cluster" });
  get("tracker_min_cluster_points", p.min_cluster_points, { "returns", "a cluster with fewer returns is no measurement" });
  get("tracker_max_object_length", p.max_object_length, { "m", "a longer cluster (wall, fence, hedge) is no object" });
  get("tracker_max_object_width", p.max_object_width, { "m", "a wider cluster is no object" });
  get("tracker_pedestrian_size", p.pedestrian_size, { "m", "a pedestrian's size: the longest and widest track taken for one (steps background split, small free space, small movers, small box)" });
  get("tracker_vehicle_length", p.vehicle_length, { "m", "a vehicle's length: the box of a moving vehicle seen end-on extends to it (steps hidden length, hidden centre)" });
  get("tracker_background_zeta", p.background_zeta, { "", "a return on a cell whose counter ζ is above this lies on static background" });
  get("tracker_background_share", p.background_share, { "", "a cluster with more than this share of background returns is not tracked; 1: off" });
  get("tracker_measurement_sigma", p.measurement_sigma, { "m", "standard deviation of a compact cluster's centroid" });
  get("tracker_extent_sigma", p.extent_sigma, { "m/m", "added standard deviation per metre of the cluster's extent on that axis" });
  get("tracker_acceleration_sigma", p.acceleration_sigma, { "m/s²", "white-noise acceleration of the constant-velocity model" });
  get("tracker_manoeuvre_jerk_sigma", p.manoeuvre_jerk_sigma, { "m/s³", "white-noise jerk of the constant-acceleration model that an interacting multiple model mixes with the constant-velocity one (step manoeuvres: braking, turning)" });
  get("tracker_gate", p.gate, { "", "Mahalanobis² gate of an association (χ², 2 dof: 13.8 is 99.9 %)" });
  get("tracker_max_gate_distance", p.max_gate_distance, { "m", "no association farther than this, whatever the covariance" });
  get("tracker_confirm_hits", p.confirm_hits, { "scans", "consecutive associations that confirm a tentative track" });
  get("tracker_max_coast_time", p.max_coast_time, { "s", "time without an association before a confirmed track is deleted" });
  get("tracker_max_measurements", p.max_measurements, { "measurements", "a scan's measurements beyond this, the farthest from the sensor, are dropped and counted" });
  get("tracker_max_tracks", p.max_tracks, { "tracks", "clusters that would start a track beyond this many tracks are counted, not tracked" });
  get("tracker_moving_speed", p.moving_speed, { "m/s", "moving when speed − motion_sigmas·σ(speed) is above this" });
  get("tracker_motion_sigmas", p.motion_sigmas, { "", "standard deviations the speed must clear to call a motion state" });
  get("tracker_stopped_speed", p.stopped_speed, { "m/s", "stopped when speed + motion_sigmas·σ(speed) stays below this for stopped_time" });
  get("tracker_stopped_time", p.stopped_time, { "s", "see tracker_stopped_speed" });
  get("tracker_max_speed", p.max_speed, { "m/s", "a track estimated faster is deleted (a wrong association)" });
  get("tracker_max_ego_speed", p.max_ego_speed, { "m/s", "a vehicle pose moving faster between two scans resets every track" });
  get("tracker_free_space_share", p.free_space_share, { "", "share of a sighting's returns that must lie in free space (step free-space check)" });
  get("tracker_free_space_margin", p.free_space_margin, { "m", "a point is in free space when every ScanGrid cell this near (whole cells) was seen free" });
  get("tracker_free_space_time", p.free_space_time, { "s", "how far back the free-space check compares sightings and scans" });
  get("tracker_evidence_weight", p.evidence_weight, { "", "weight w of a track's motion in its cells (β = w·P(motion), step track evidence)" });
  std::vector<std::string> off = stepsOff(p.steps);
  get("tracker_steps_off", off, { "", "the tracker's added steps switched off, by name (doc/steps.md): building_background, background_split, fragments, duplicates, free_space_check, small_free_space, walked, heading_box, long_box, second_axes, box_fit, open_ends, hidden_ends, open_anchor, far_growth, manoeuvres, common_motion, common_turn, track_evidence, track_box, hidden_length, hidden_centre, box_margin, box_hidden, small_movers, small_box, small_specialised, movers_without_map" });
  p.steps = stepsWithOff(off);
}

}  // namespace core
}  // namespace map_aided_fusion

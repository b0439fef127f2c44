/**
 * @file tracker.hpp
 * @brief Tracked objects (ROS-free): per scan, measurements from clusters of the scan's obstacle returns; tracks with
 *        a constant-velocity Kalman filter, associated to the measurements by a gated global assignment
 *        (core/assignment.hpp; candidates found through a grid, each gated component solved apart), with a lifecycle
 *        (tentative → confirmed → coasting → deleted) and a motion decision from the velocity and its covariance
 *        (moving, stopped or not yet known). A scan's cost is bounded: at most max_measurements measurements and
 *        max_tracks tracks, the nearest to the sensor first.
 *
 * Not in the paper: it gives each object an id and a velocity, and the motion evidence the grid's classes lack
 * (doc/evaluation.md scores it with CLEAR-MOT). The `paper` profile does not use it.
 */
#pragma once

#include <cmath>
#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "map_aided_fusion/core/assignment.hpp"
#include "map_aided_fusion/core/parameters.hpp"
#include "map_aided_fusion/core/grid_geometry.hpp"
#include "map_aided_fusion/core/mass_grid.hpp"
#include "map_aided_fusion/core/seen_free.hpp"
#include "map_aided_fusion/core/tracking/common_motion.hpp"
#include "map_aided_fusion/core/tracking/lifecycle.hpp"
#include "map_aided_fusion/core/tracking/measurement_model.hpp"
#include "map_aided_fusion/core/tracking/motion_decision.hpp"
#include "map_aided_fusion/core/tracking/motion_model.hpp"

namespace map_aided_fusion {
namespace core {

/// Default TrackerParams::max_measurements and max_tracks: about six times the most seen in one scan of any dataset
/// (KITTI tracking 0000: 170 measurements, 185 tracks; SemanticKITTI 06: 140 and 158; doc/reliability.md).
constexpr int kDefaultMaxMeasurements = 1000;
constexpr int kDefaultMaxTracks = 1000;

/// The tracker's parameters (config/fusion.yaml, `tracker_*`); units in the comments.
struct TrackerParams
{
  bool enabled = true;               ///< run the tracker (false in the paper profile)
  double cluster_distance = 0.6;     ///< m: returns in cells of half this size that touch are one cluster
  int min_cluster_points = 12;       ///< a cluster with fewer returns is no measurement
  /// A return on a MapGrid cell whose counter ζ is above this lies on static background (occupied scan after scan:
  /// a facade, a parked car); ζ grows by delta_inc per consistent occupied scan …
  double background_zeta = 0.4;
  /// … and a cluster with more than this share of its returns on background is no moving-object candidate, not
  /// tracked; 1: off.
  double background_share = 0.5;
  /// Step "building background": a return on a MapGrid cell whose BetP(C) (a mapped building: the PriorGrid's B,
  /// kept by the fusion) is above background_building lies on static background too. A facade first seen far away,
  /// before its counter has grown, slides along its visible part while the vehicle drives and made false moving
  /// tracks. Without a prior BetP(C) is 0 and the step does nothing.
  bool building_background = true;
  double background_building = 0.5;  ///< BetP(C) in [0, 1] above which a return lies on a mapped building
  /// Step "background split": a pedestrian walking beside a wall, a hedge or a row of parked cars touches them, and
  /// its returns join their cluster, longer than max_object_length or wider than max_object_width, which is no
  /// measurement. The returns of such a cluster that do not lie on static background (background_zeta, step building
  /// background) are clustered again, and those pieces at most background_split_size long and wide are measurements
  /// (Measurement::split). A piece is associated only with a track whose box is at most that size: a vehicle's
  /// track does not jump to a piece of it.
  bool background_split = true;
  double background_split_size = 1.0;  ///< m in (0, max_object_width]: a pedestrian's size
  double max_object_length = 18.0;   ///< m: a longer cluster (a wall, a fence, a hedge) is no object; an articulated bus is shorter
  double max_object_width = 4.0;     ///< m: a wider cluster is no object
  double measurement_sigma = 0.15;   ///< m, standard deviation of a compact cluster's centroid
  double extent_sigma = 0.1;         ///< m of standard deviation per metre of the cluster's extent on that axis
  double acceleration_sigma = 2.0;   ///< m/s², white-noise acceleration of the constant-velocity model
  /// Step "manoeuvres" (core/tracking/motion_model.hpp, ImmState): the motion model is an interacting multiple model
  /// of the constant-velocity model above and a constant-acceleration one with this white-noise jerk (m/s³), which
  /// follows braking, pulling away and turning; 0: off, the constant-velocity model alone.
  double manoeuvre_jerk_sigma = 5.0;
  double initial_speed_sigma = 5.0;  ///< m/s, velocity standard deviation of a new track
  double gate = 13.8;                ///< Mahalanobis² of an association (χ² with 2 dof: 13.8 is 99.9 %)
  double max_gate_distance = 3.0;    ///< m: no association farther than this, whatever the covariance
  int confirm_hits = 3;              ///< consecutive associations that confirm a tentative track
  /// Step "fragments": an object seen in several clusters (a bus's side behind its face, a van past an occluder, the
  /// sparse returns of a far car) gets one track per cluster, and every track but one is a false moving object. A
  /// cluster no track takes whose centroid lies in the box of a moving track seen this scan, grown by
  /// fragment_margin on every side, starts no track (and is counted).
  bool fragments = true;
  double fragment_margin = 1.0;      ///< m
  /// Step "duplicates": one object can still hold several moving tracks: clusters that started their track before
  /// the object's own track moved, the returns of a lidar ring that slides along a car's roof at a fixed range from
  /// the sensor (at the vehicle's speed), a van's side sampled column by column at a grazing angle. A moving track
  /// seen this scan whose object box (objectBox()) has its centre in the object box of a moving track with more hits
  /// seen this scan, grown by fragment_margin, and that moves within 60° of its heading (two objects passing each
  /// other do not), is a duplicate of it: it is deleted (and counted). Its cluster, and
  /// with this step every fragment, is then a piece of the other's object: step fragments tests the object box, and
  /// the pieces' returns take the track's motion (Track::fragments, step track evidence).
  bool duplicates = true;
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
  /// Step "free-space check": a track is moving only once free space shows the motion, i.e. this share of its returns
  /// of an earlier scan lies where the last scan saw free space (it left), or of its returns of the last scan where an
  /// earlier scan saw free space (it came). A velocity alone does not tell an object from a fragment of a wall or a
  /// hedge whose visible part slides as the vehicle drives by.
  bool free_space_check = true;
  double free_space_share = 0.3;     ///< share of a sighting's returns that must lie in free space, (0, 1]
  double free_space_margin = 0.5;    ///< m: a point is in free space when every ScanGrid cell this near was seen free
  double free_space_time = 1.0;      ///< s: how far back sightings and scans are compared
  /// While the check runs, free space has shown the motion too, so the speed need clear moving_speed by this many
  /// standard deviations only, instead of motion_sigmas (which still decides without a ScanGrid).
  double free_space_motion_sigmas = 0.5;
  /// Step "small free space": a pedestrian walks beside facades, parked cars and poles, whose cells lie within
  /// free_space_margin of it, so that free space never shows where it left or came. A track at most
  /// free_space_small_size long and wide (0: off), at least free_space_small_min_extent on both axes (a sliver of a
  /// wall seen edge-on is thinner) and no faster than free_space_small_max_speed (a walk) is checked with
  /// free_space_small_margin instead.
  double free_space_small_size = 1.0;        ///< m
  double free_space_small_margin = 0.0;      ///< m, [0, free_space_margin]
  double free_space_small_min_extent = 0.1;  ///< m
  double free_space_small_max_speed = 2.0;   ///< m/s
  /// Step "heading box": a track's box keeps the axes of its first cluster, so an object that turns is seen askew in
  /// them: its box grows (a cyclist's to 1.7 × 1.6 m) and the point followed slides off the object until the gate
  /// loses it. A moving track's box no longer than heading_box_max_length turns to its heading, from the cluster of
  /// that scan, once it is askew by more than heading_box_angle. A longer object is seldom seen whole (a van behind
  /// a car): the middle of its cluster is not its box's, so its box keeps its axes.
  bool heading_box = true;
  double heading_box_angle = 20.0;      ///< deg in [0, 45]: the box turns when its axes are this far from the heading
  double heading_box_max_length = 2.5;  ///< m: only boxes no longer than this turn (cyclists, pedestrians)
  /// Step "long box": a long vehicle keeps the axes of its first cluster too (the front face of a bus seen from 70 m),
  /// and when it turns (a bus pulling in to a stop at 16°) its box, grown to hold every cluster in those axes, swells
  /// (6 × 12 m for a 2.5 × 12 m bus), and the point the track follows slides across it. A moving track whose cluster
  /// is at least long_box_min_length long, at most half as wide, and whose major axis lies within heading_box_angle of
  /// the track's heading, turns its box to that axis once the box is more than 6° from it, extents and middle from
  /// that cluster. Shorter clusters (a car's L seen end-on) do not give an axis this reliable.
  bool long_box = true;
  double long_box_min_length = 6.0;  ///< m in [0, 100]: shortest cluster whose axis the box takes
  /// Step "track evidence" (core/track_evidence.hpp): the weight w of a track's motion in its cells' masses,
  /// β = w · P(motion); 0: off.
  double evidence_weight = 0.8;
  /// … given also to the cells of its measurement's box that hold none of its returns (seen over or hidden behind
  /// the object's near side), from the sets that already hold the track's class only.
  bool evidence_box = true;
  /// Step "hidden length": a moving track seen end-on (its cluster at least evidence_end_width wide across its
  /// heading and shallower than evidence_hidden_length along it: a car's rear or front face) has its box, for the
  /// track box, extended away from the sensor along its heading to evidence_hidden_length m; 0: off. The body behind
  /// the face holds no return (the rays end on the face or pass over the roof) and otherwise keeps the prior.
  double evidence_hidden_length = 4.0;
  bool hidden_length = true;  ///< step "hidden length" on (it also needs evidence_hidden_length > 0)
  /// Step "box hidden": the cells of a moving track's box that the scan did not see free (behind its near side, under
  /// the rays over its roof) also move their free sets, {F} and {F, S}, to V, as a cell of its returns does: their
  /// free evidence is older than the object that drove in. Cells the scan sees free stay free.
  bool evidence_box_hidden = true;
  double evidence_end_width = 1.4;  ///< m: the narrowest face that is a vehicle's end (a cyclist's is narrower)
  /// Step "box margin": a moving track's box (of step track box; not a small mover's) grows by this on each side
  /// across its axis (m; 0: off). A side's outermost returns lie up to a beam step inside the object's outline, so
  /// the cells that its sides half cover have their centres just outside the cluster's box.
  double evidence_box_margin = 0.1;
  /// Step "small movers": a moving track whose box is at most this long and wide (m; a pedestrian's) also moves to
  /// V the sets that hold N, which track evidence otherwise leaves to the prior and the counter: a pavement's prior
  /// is {N, S, V}. 0: off.
  double evidence_small_size = 1.0;
  /// Step "small box": such a small mover's box, for the track box, is grown to evidence_small_size along the line
  /// of sight (away from the sensor: the rays end on its near side) and across it, so that it covers the body behind
  /// the returns.
  bool evidence_small_box = true;
  /// Step "small specialised": a small mover's cells (step small movers) also move to V their mass on {N}, {S} and
  /// {N, S} (and, in its returns' cells, on the sets within {F, N, S}): a walker stays in a cell for several scans, and
  /// the counter specialises the pavement's {N, S, V} to {N, S} before its track is moving.
  bool evidence_small_specialised = true;
  /// Step "hidden centre": a moving track seen end-on (as for step hidden length, with evidence_hidden_length > 0)
  /// reports (reportedBox(): the tracks topic, the scoring) the box of step hidden length and its centre, half a
  /// vehicle's length behind the face seen, instead of the face's. A scan that misses it (the track coasts) keeps
  /// that box where its last sighting put it, relative to the track's position and heading (Track::seen_box).
  bool hidden_centre = true;
  /// Step "open ends": which end of a partly seen cluster is the object's end. The box of a cluster shorter than the
  /// track's is anchored on the cluster's end nearest the sensor, but an occluder nearer the sensor can cut exactly
  /// that end (a car coming out of the shadow of a parked car on the sensor's side). Along each axis of the box
  /// within 20° of the cluster's, when the sensor's line of sight to the point open_end_distance beyond the near end
  /// is blocked by an obstacle at least 1 m nearer, and the scan saw free space (SeenFree at free_space_margin) at
  /// that distance beyond the other end, the other end anchors the box (referencePoint(), the box's growth).
  /// Needs a ScanGrid.
  bool open_ends = true;
  double open_end_distance = 1.0;  ///< m in [0, 10]: how far beyond a cluster's end both tests look
  /// Step "common motion": a pose that drifts (a localisation's slow error) moves the whole static world in the map
  /// frame, and the track of every static object takes that drift as its velocity (KITTI 00's first sweeps: 1.0 to
  /// 1.6 m/s, all one way). The scan's common motion (Tracker::commonMotion()) is the median velocity, per axis, of
  /// the confirmed tracks seen in the scan when there are at least common_motion_min_tracks of them, that median is
  /// no faster than common_motion_max_speed (a drift, not traffic) and more than common_motion_share of them lie
  /// within common_motion_sigmas σ(speed) of it (one motion, not a mix). The motion decision (moving, stopped, the
  /// free-space check's speed test) and P(motion) of track evidence then take each track's speed relative to it;
  /// the velocities reported stay the tracks'.
  bool common_motion = true;
  int common_motion_min_tracks = 20;
  double common_motion_share = 0.5;      ///< in (0, 1]
  double common_motion_sigmas = 2.0;     ///< σ(speed) of a track from the median that still agrees with it
  double common_motion_max_speed = 2.0;  ///< m/s
  /// Step "common turn" (with common_motion): a heading that drifts turns the whole static world about the sensor,
  /// so its objects move at speeds that grow with their distance, and no one velocity is shared (KITTI 00's last
  /// sweeps: 0.4 m/s ahead, 1.6 m/s 40 m behind). The common motion is then a rigid motion about the sensor,
  /// v(p) = v₀ + ω × (p − sensor), fitted to the velocities of the tracks seen in the scan by least squares weighted
  /// by 1/σ(speed)², from the median with ω = 0, Huber-weighted beyond common_motion_sigmas σ. It replaces the median
  /// when more of those tracks agree with it, ω is more than common_motion_sigmas of its standard error from 0 and at
  /// most common_motion_max_turn_rate, and |v₀| is at most common_motion_max_speed. Needs the sensor position
  /// (Measurement::has_sensor).
  bool common_turn = true;
  double common_motion_max_turn_rate = 0.05;  ///< rad/s in [0, 1]: a faster turn is not a drift
  /// Step "movers without a map": without a prior the grid never tells C and N from S and V (the scan's O is
  /// {C, N, S, V}), so the cells of a moving track's returns, and the box cells of a small mover (step small movers),
  /// also move to V the sets holding C or N. With a prior, C and N are the map's and the counter's and stay.
  bool evidence_without_map = true;
  /// Step "walked" (free-space check): a pedestrian on a pavement behind parked cars is hidden from the ground around
  /// it, so free space never shows where it left or came. A track checked as a small walker (step small free space)
  /// that was associated in each of its last walk_min_hits scans and whose position moved at least walk_distance,
  /// relative to the common motion, since its oldest sighting the check keeps (free_space_time ago) has shown its
  /// motion as the free-space check would.
  bool walked = true;
  int walk_min_hits = 10;      ///< consecutive associations
  double walk_distance = 0.5;  ///< m in (0, 10]
  /// Step "second axes": a new track's box takes the axes of its first cluster, which has none when it is nearly as
  /// wide as long: the corner of a car coming out of a shadow, whose axes can be 20° off the car's, so that the point
  /// the track follows (referencePoint()) moves across the car as its side grows. When the track's second cluster is
  /// elongated and much longer than the first, the box turns to the second cluster's axes (unless within 6° of them)
  /// before that cluster corrects the track; its extents become those of the old box seen along the new axes (the
  /// rectangle around it).
  bool second_axes = true;
  double second_axes_round = 0.4;       ///< [0, 1]: a first cluster at least this wide for its length has no axis
  double second_axes_elongation = 0.5;  ///< (0, 1]: a second cluster at most this wide for its length has one
  double second_axes_growth = 1.5;      ///< [1, 100]: and is longer than this many times the first's length
  /// Step "hidden ends" (with step open ends, which finds the hidden ends): a cluster whose two ends along its major
  /// axis are both hidden from the sensor by nearer obstacles, neither with free space beyond it, is the part of an
  /// object seen through a gap: its extent along that axis is the gap's, and its centroid moves with neither end of the
  /// object (a car passing behind two parked cars). For a track not yet moving, the measurement's σ along that axis
  /// grows by hidden_ends_sigma, so that such views do not make it moving with the gap's motion. A moving track keeps
  /// the usual σ (its velocity is known; measured, the larger σ made a turning van lag).
  bool hidden_ends = true;
  double hidden_ends_sigma = 5.0;  ///< m in (0, 100]
  /// Step "box fit": a cluster's axes are those of the rectangle that fits its returns best, not its principal axes.
  /// A vehicle seen on its rear and one side gives an L of returns whose principal axes lie between the two faces:
  /// its box was askew by up to 45°, grew as more of the side came into view, and the point its track follows slid
  /// across the vehicle. Rectangles are tried every box_fit_step degrees in [0°, 90°) and scored by the closeness
  /// criterion of L-shape fitting (Zhang et al. 2017): each return adds 1 / max(d, box_fit_closeness), d its distance
  /// to the rectangle's nearest edge. A cluster whose principal extent is shorter than box_fit_min_length keeps its
  /// principal axes: a pedestrian's returns have no edges to fit.
  bool box_fit = true;
  double box_fit_step = 3.0;          ///< deg in [0.1, 45]
  double box_fit_closeness = 0.05;    ///< m in (0, 1]: a return this near an edge scores as if on it
  double box_fit_min_length = 1.5;    ///< m in [0, max_object_length]
  /// Step "open anchor" (with step open ends, which finds the open faces): a track follows the end of its cluster
  /// nearest the sensor (referencePoint()). When that end along the cluster's major axis has free space seen beyond
  /// it, it is the object's own end, placed as well as a compact cluster's centroid: the measurement's σ along that
  /// axis is measurement_sigma, without the extent_sigma share of the cluster's length. That share kept the gain of
  /// a long vehicle's track low, and its velocity lagged by up to 2 m/s as it braked.
  bool open_anchor = true;
  /// Step "far growth" (with step open anchor): a cluster placed by its open anchoring end, whose major axis is that of
  /// the track's box, grew or shrank at its other end: its change of length since the track's last cluster does not
  /// enter the measurement's σ along that axis. That share (half the change) kept the velocity of a car coming out
  /// from behind an occluder near its prior: the first velocity reported for a car at 12 m/s was 7.9 m/s. A cluster
  /// whose axes differ from the box's (a bus turning its side to the sensor) keeps the share: its end seen along the
  /// box's axes is not the one found open.
  bool far_growth = true;

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
  get("tracker_background_zeta", p.background_zeta, { "", "a return on a cell whose counter ζ is above this lies on static background" });
  get("tracker_background_share", p.background_share, { "", "a cluster with more than this share of background returns is not tracked; 1: off" });
  get("tracker_building_background", p.building_background, { "", "step building background: a return on a cell decided mapped building (BetP(C) above tracker_background_building) lies on static background too" });
  get("tracker_background_building", p.background_building, { "", "BetP(C) above which a return lies on a mapped building" });
  get("tracker_background_split", p.background_split, { "", "step background split: the returns of a cluster too long or wide that are not on background are clustered again; pieces of a pedestrian's size are measurements" });
  get("tracker_background_split_size", p.background_split_size, { "m", "longest and widest piece of step background split, and largest track box it may be associated with" });
  get("tracker_max_object_length", p.max_object_length, { "m", "a longer cluster (wall, fence, hedge) is no object" });
  get("tracker_max_object_width", p.max_object_width, { "m", "a wider cluster is no object" });
  get("tracker_measurement_sigma", p.measurement_sigma, { "m", "standard deviation of a compact cluster's centroid" });
  get("tracker_extent_sigma", p.extent_sigma, { "m/m", "added standard deviation per metre of the cluster's extent on that axis" });
  get("tracker_acceleration_sigma", p.acceleration_sigma, { "m/s²", "white-noise acceleration of the constant-velocity model" });
  get("tracker_manoeuvre_jerk_sigma", p.manoeuvre_jerk_sigma, { "m/s³", "step manoeuvres: white-noise jerk of the constant-acceleration model that an interacting multiple model mixes with the constant-velocity one (braking, turning); 0: off" });
  get("tracker_initial_speed_sigma", p.initial_speed_sigma, { "m/s", "velocity standard deviation of a new track" });
  get("tracker_gate", p.gate, { "", "Mahalanobis² gate of an association (χ², 2 dof: 13.8 is 99.9 %)" });
  get("tracker_max_gate_distance", p.max_gate_distance, { "m", "no association farther than this, whatever the covariance" });
  get("tracker_confirm_hits", p.confirm_hits, { "scans", "consecutive associations that confirm a tentative track" });
  get("tracker_fragments", p.fragments, { "", "step fragments: a cluster in the box of a moving track seen this scan (grown by tracker_fragment_margin) starts no track" });
  get("tracker_duplicates", p.duplicates, { "", "step duplicates: a moving track whose object box centre lies in the object box of a moving track with more hits (grown by tracker_fragment_margin), moving within 60° of its heading, is deleted; its cluster and the fragments take that track's motion" });
  get("tracker_fragment_margin", p.fragment_margin, { "m", "how far beyond a moving track's box a cluster is a fragment of it (step fragments)" });
  get("tracker_max_coast_time", p.max_coast_time, { "s", "time without an association before a confirmed track is deleted" });
  get("tracker_max_measurements", p.max_measurements, { "measurements", "a scan's measurements beyond this, the farthest from the sensor, are dropped and counted" });
  get("tracker_max_tracks", p.max_tracks, { "tracks", "clusters that would start a track beyond this many tracks are counted, not tracked" });
  get("tracker_moving_speed", p.moving_speed, { "m/s", "moving when speed − motion_sigmas·σ(speed) is above this" });
  get("tracker_motion_sigmas", p.motion_sigmas, { "", "standard deviations the speed must clear to call a motion state" });
  get("tracker_stopped_speed", p.stopped_speed, { "m/s", "stopped when speed + motion_sigmas·σ(speed) stays below this for stopped_time" });
  get("tracker_stopped_time", p.stopped_time, { "s", "see tracker_stopped_speed" });
  get("tracker_max_speed", p.max_speed, { "m/s", "a track estimated faster is deleted (a wrong association)" });
  get("tracker_max_ego_speed", p.max_ego_speed, { "m/s", "a vehicle pose moving faster between two scans resets every track" });
  get("tracker_free_space_check", p.free_space_check, { "", "step free-space check: moving only once free space shows that the track left a place or came into one" });
  get("tracker_free_space_share", p.free_space_share, { "", "share of a sighting's returns that must lie in free space" });
  get("tracker_free_space_margin", p.free_space_margin, { "m", "a point is in free space when every ScanGrid cell this near (whole cells) was seen free" });
  get("tracker_free_space_time", p.free_space_time, { "s", "how far back the free-space check compares sightings and scans" });
  get("tracker_free_space_motion_sigmas", p.free_space_motion_sigmas, { "", "standard deviations the speed must clear to be moving while the free-space check runs" });
  get("tracker_free_space_small_size", p.free_space_small_size, { "m", "step small free space: a track at most this long and wide is checked with tracker_free_space_small_margin; 0: off" });
  get("tracker_free_space_small_margin", p.free_space_small_margin, { "m", "the free-space margin of a small track (step small free space)" });
  get("tracker_free_space_small_min_extent", p.free_space_small_min_extent, { "m", "… when at least this long and wide (a sliver of a wall is thinner)" });
  get("tracker_free_space_small_max_speed", p.free_space_small_max_speed, { "m/s", "… and no faster than this (a walk)" });
  get("tracker_heading_box", p.heading_box, { "", "step heading box: a short moving track's box turns to its heading once askew" });
  get("tracker_heading_box_angle", p.heading_box_angle, { "deg", "the box turns when its axes are this far from the track's heading" });
  get("tracker_heading_box_max_length", p.heading_box_max_length, { "m", "only boxes no longer than this turn to the heading" });
  get("tracker_long_box", p.long_box, { "", "step long box: a long moving track's box turns to its long cluster's axis" });
  get("tracker_long_box_min_length", p.long_box_min_length, { "m", "shortest cluster whose axis a moving track's box takes (step long box)" });
  get("tracker_evidence_weight", p.evidence_weight, { "", "step track evidence: weight w of a track's motion in its cells (β = w·P(motion)); 0: off" });
  get("tracker_evidence_hidden_length", p.evidence_hidden_length, { "m", "step hidden length: a moving track seen end-on has its box extended away from the sensor to this length; 0: off" });
  get("tracker_hidden_length", p.hidden_length, { "", "step hidden length on (with tracker_evidence_hidden_length > 0)" });
  get("tracker_evidence_box_hidden", p.evidence_box_hidden, { "", "step box hidden: box cells the scan did not see free also move their free sets to V" });
  get("tracker_evidence_end_width", p.evidence_end_width, { "m", "the narrowest face that is a vehicle's end (step hidden length)" });
  get("tracker_evidence_box_margin", p.evidence_box_margin, { "m", "step box margin: a moving track's box grows by this on each side across its axis (the cells its sides half cover); 0: off" });
  get("tracker_evidence_box", p.evidence_box, { "", "step track evidence also in the cells of the track's box that hold none of its returns" });
  get("tracker_evidence_small_size", p.evidence_small_size, { "m", "step small movers: a moving track at most this long and wide also moves the sets holding N to V; 0: off" });
  get("tracker_evidence_small_box", p.evidence_small_box, { "", "step small box: a small mover's track box is grown to tracker_evidence_small_size along and across the line of sight" });
  get("tracker_open_ends", p.open_ends, { "", "step open ends: a partly seen cluster whose end nearest the sensor is occluded, and the other open, is anchored on the other" });
  get("tracker_open_end_distance", p.open_end_distance, { "m", "how far beyond a cluster's end step open ends looks for free space and for an occluder's shadow" });
  get("tracker_common_motion", p.common_motion, { "", "step common motion: the motion decision takes speeds relative to the median velocity of many tracks that agree with it (a drifting pose)" });
  get("tracker_common_motion_min_tracks", p.common_motion_min_tracks, { "tracks", "confirmed tracks seen in the scan below which there is no common motion" });
  get("tracker_common_motion_share", p.common_motion_share, { "", "share of those tracks that must agree with the median velocity" });
  get("tracker_common_motion_sigmas", p.common_motion_sigmas, { "", "a track agrees with the median when within this many σ(speed) of it" });
  get("tracker_common_motion_max_speed", p.common_motion_max_speed, { "m/s", "a faster median is traffic, not a drift: no common motion" });
  get("tracker_common_turn", p.common_turn, { "", "step common turn: the common motion may turn about the sensor (a drifting heading)" });
  get("tracker_common_motion_max_turn_rate", p.common_motion_max_turn_rate, { "rad/s", "a faster common turn is not a drift: the median stays" });
  get("tracker_evidence_small_specialised", p.evidence_small_specialised, { "", "step small specialised: a small mover's cells also move their mass on {N}, {S}, {N, S} to V (the counter's specialisation of a walker's pavement cells)" });
  get("tracker_evidence_without_map", p.evidence_without_map, { "", "step movers without a map: without a prior a moving track's return cells (and a small mover's box) also move the sets holding C or N to V" });
  get("tracker_walked", p.walked, { "", "step walked: a small walker seen in each of its last tracker_walk_min_hits scans that moved tracker_walk_distance since its oldest sighting has shown its motion as free space would" });
  get("tracker_walk_min_hits", p.walk_min_hits, { "scans", "consecutive associations a track needs before step walked" });
  get("tracker_walk_distance", p.walk_distance, { "m", "how far a small walker must have moved since its oldest sighting (step walked)" });
  get("tracker_second_axes", p.second_axes, { "", "step second axes: a new track whose first cluster was nearly as wide as long takes the axes of its second cluster when that one is elongated and much longer" });
  get("tracker_second_axes_round", p.second_axes_round, { "", "a first cluster at least this wide for its length has no axis (step second axes)" });
  get("tracker_second_axes_elongation", p.second_axes_elongation, { "", "a second cluster at most this wide for its length has an axis (step second axes)" });
  get("tracker_second_axes_growth", p.second_axes_growth, { "", "the second cluster must be longer than this many times the first (step second axes)" });
  get("tracker_hidden_ends", p.hidden_ends, { "", "step hidden ends: a cluster whose two ends along its major axis are hidden and neither open tells a track not yet moving nothing along that axis" });
  get("tracker_hidden_ends_sigma", p.hidden_ends_sigma, { "m", "standard deviation added along such a cluster's major axis (step hidden ends)" });
  get("tracker_box_fit", p.box_fit, { "", "step box fit: a cluster's axes are those of the rectangle that fits its returns best (closeness criterion), not its principal axes" });
  get("tracker_box_fit_step", p.box_fit_step, { "deg", "angle between two rectangles tried (step box fit)" });
  get("tracker_box_fit_closeness", p.box_fit_closeness, { "m", "a return this near a rectangle's edge scores as if on it (step box fit)" });
  get("tracker_box_fit_min_length", p.box_fit_min_length, { "m", "a cluster whose principal extent is shorter keeps its principal axes (step box fit)" });
  get("tracker_open_anchor", p.open_anchor, { "", "step open anchor: a cluster whose anchoring end along its major axis is open is placed along that axis with measurement_sigma" });
  get("tracker_far_growth", p.far_growth, { "", "step far growth: a cluster placed by its open anchoring end along the box's axes grew at its other end, and its change of length does not widen its sigma" });
  get("tracker_hidden_centre", p.hidden_centre, { "", "step hidden centre: a moving track seen end-on reports the box of step hidden length and its centre" });
}

/**
 * @brief Per return of @p returns (vehicle frame, vehicle pose @p pose): 1 when it lies on static background, i.e.
 *        @p onBackground(its map point) is true (trackScan(): its map cell's counter ζ is above background_zeta or,
 *        with step building background, its BetP(C) above background_building).
 */
template <class OnBackground>
void backgroundFlags(const Pose2& pose, const ObstaclePoints& returns, OnBackground&& onBackground,
                     std::vector<std::uint8_t>& flags)
{
  flags.assign(returns.count, 0);
  const double c = std::cos(pose.yaw), s = std::sin(pose.yaw);
  for (std::size_t i = 0; i < returns.count; ++i)
  {
    const double x = returns.xy[2 * i], y = returns.xy[2 * i + 1];
    flags[i] = onBackground(Point2{ pose.x + c * x - s * y, pose.y + s * x + c * y }) ? 1 : 0;
  }
}

/**
 * @brief Step open ends: the open and occluded faces of @p m's box, from one scan. A face is open when the point
 *        @p distance beyond its middle is clear in @p free, occluded when the line of sight from the vehicle at
 *        @p pose to that point is blocked in @p scan (hiddenFromSensor()) at least 1 m before it. Sets ends_seen.
 */
void findOpenEnds(Measurement& m, const SeenFree& free, const ScanMassGrid& scan, const Pose2& pose, double distance);

/// True when the line of sight from the vehicle (the ScanGrid's origin, at @p pose) to the map-frame point @p p crosses
/// a ScanGrid cell with m(O) ≥ 0.5 at least @p gap metres before @p p.
bool hiddenFromSensor(const ScanMassGrid& scan, const Pose2& pose, Point2 p, double gap);

/**
 * @brief Clusters map-frame returns: cells of cluster_distance / 2 holding returns, 8-connected, are one cluster.
 *        Clusters with fewer than min_cluster_points returns, longer than max_object_length or wider than
 *        max_object_width, or (with @p background, one flag per point) with more than background_share of their
 *        returns on background are dropped; non-finite points are skipped. With @p background and step background
 *        split, the returns not on background of the clusters too long or wide are clustered again: the pieces at
 *        most background_split_size long and wide are measurements too, with Measurement::split set.
 */
std::vector<Measurement> clusterReturns(const std::vector<Point2>& points, const TrackerParams& params,
                                        const std::vector<std::uint8_t>* background = nullptr);

/// Where a track's returns were in one scan (at most Tracker::kSightingPoints of them, map frame).
struct Sighting
{
  double stamp = 0.0;
  std::vector<Point2> points;
  Point2 position;  ///< the track's position after this sighting's association (step walked)
};

/// The box a moving track reported in its last scan with a measurement (objectBox()), relative to its position and
/// heading then: a coasting track reports it moved and turned with the track.
struct SeenBox
{
  bool valid = false;
  double along = 0.0, across = 0.0;  ///< m, the box's centre from the track's position, along and across its heading
  double yaw = 0.0;                  ///< rad, the box's heading from the track's
  double length = 0.0, width = 0.0;  ///< m
};

/// A tracked object. State x = (x, y, vx, vy) in the map frame, covariance P: what it reports. The motion decision
/// reads the constant-velocity estimate instead (decisionVelocity(), speedSigma()): with step manoeuvres, the IMM's
/// quiet model, whose velocity and σ a possible manoeuvre does not inflate; otherwise x and P themselves.
struct Track
{
  std::uint32_t id = 0;
  TrackState state = TrackState::kTentative;
  TrackMotion motion = TrackMotion::kUnknown;
  Eigen::Vector4d x = Eigen::Vector4d::Zero();
  Eigen::Matrix4d P = Eigen::Matrix4d::Identity();
  /// Step manoeuvres: the two models whose mixture x and P are (used when manoeuvres is set).
  ImmState imm;
  bool manoeuvres = false;
  double yaw = 0.0, length = 0.0, width = 0.0;  ///< of the last associated cluster
  /// The object's box: heading fixed by its first cluster, extents the largest seen along the box's axes.
  double extent_yaw = 0.0, extent_length = 0.0, extent_width = 0.0;
  /// Measurements of the last scan (Tracker::measurements()) that are pieces of its object besides its own: with step
  /// duplicates, the fragments it kept from starting a track and the clusters of its duplicates.
  std::vector<int> fragments;
  int hits = 0;                                 ///< associations
  int measurement = -1;                         ///< its measurement of the last scan (Tracker::measurements()), or −1
  int consecutive_hits = 0;
  double first_stamp = 0.0;
  double last_hit = 0.0;                        ///< stamp of the last association
  double still_since = -1.0;                    ///< stamp since which it is confidently slow (−1: not)
  /// Step free-space check: free space showed that it moved (it stays so); its sightings of the last free_space_time.
  bool motion_seen = false;
  std::vector<Sighting> sightings;
  SeenBox seen_box;  ///< step hidden centre: the box it reported when last seen
  /// Born while the MapGrid's counter ζ could not yet mark static background (Tracker::setBackgroundKnown(false): the
  /// first scans after the grid was started or reset) and not associated since it could: it may be a facade or a
  /// parked car the background test has not yet had the scans to recognise.
  bool background_unchecked = false;

  Point2 position() const { return Point2{ x(0), x(1) }; }
  Point2 velocity() const { return Point2{ x(2), x(3) }; }
  double speed() const { return x.tail<2>().norm(); }
  /// The velocity the motion decision tests (m/s, map frame): the constant-velocity estimate.
  Point2 decisionVelocity() const
  {
    return manoeuvres ? Point2{ imm.x[0](2), imm.x[0](3) } : velocity();
  }
  /// Speed of decisionVelocity() relative to the velocity @p common (m/s, map frame).
  double speedRelativeTo(Point2 common) const
  {
    const Point2 v = decisionVelocity();
    return std::hypot(v.x - common.x, v.y - common.y);
  }
  /// Standard deviation of the speed of decisionVelocity() (along it; the largest when it is near zero).
  double speedSigma() const;
  /// Seconds since the first association.
  double age(double now) const { return now - first_stamp; }
  bool reported() const { return state != TrackState::kTentative; }
  /// What the nodelet publishes: reported, and either moving or checked against static background
  /// (background_unchecked false). After a start or a reset the grid's counter needs backgroundWarmupScans() scans
  /// before it tells static structure from objects; until then only the moving tracks go out.
  bool published() const
  {
    return reported() && (motion == TrackMotion::kMoving || !background_unchecked);
  }
};

/**
 * @brief The scans of consistent occupied evidence after which the counter ζ (0 after a reset, + @p delta_inc per
 *        scan) exceeds @p background_zeta, i.e. the first scan at which a return can be recognised as static
 *        background: ⌊background_zeta / delta_inc⌋ + 1. 0 when the counter never gets there (delta_inc ≤ 0 or
 *        background_zeta ≥ 1): then waiting would tell nothing.
 */
std::size_t backgroundWarmupScans(double background_zeta, double delta_inc);

/// What went wrong, counted since the start (diagnostics read differences).
struct TrackerCounts
{
  std::uint64_t scans = 0;
  std::uint64_t measurements = 0;
  std::uint64_t tracks_created = 0;
  std::uint64_t tracks_deleted = 0;
  std::uint64_t resets = 0;             ///< every track dropped: a pose or time jump
  std::uint64_t rejected_tracks = 0;    ///< deleted for a non-finite state or an implausible speed
  std::uint64_t fragments = 0;          ///< clusters that started no track: fragments of a moving track (step fragments)
  std::uint64_t duplicates = 0;         ///< moving tracks deleted as duplicates of another (step duplicates)
  std::uint64_t common_motion_scans = 0;  ///< scans with a common motion (step common motion)
  std::uint64_t common_turn_scans = 0;    ///< scans whose common motion turns (step common turn)
  std::uint64_t walked = 0;       ///< tracks whose motion was seen by the distance they walked (step walked)
  std::uint64_t split_measurements = 0;  ///< measurements that are pieces of a cluster too large (step background split)
  std::uint64_t second_axes = 0;  ///< new tracks whose box turned to their second cluster's axes (step second axes)
  std::uint64_t long_box = 0;     ///< boxes turned to a long cluster's axis (step long box)
  std::uint64_t hidden_ends = 0;  ///< associations of a track not yet moving with a cluster whose ends are hidden (step hidden ends)
  std::uint64_t box_fit = 0;      ///< measurements whose fitted axes are more than box_fit_step off their principal ones (step box fit)
  std::uint64_t open_anchor = 0;  ///< associations with a cluster placed by its open anchoring end (step open anchor)
  std::uint64_t far_growth = 0;   ///< ... of them whose change of length left their σ as it was (step far growth)
  std::uint64_t non_finite_inputs = 0;  ///< non-finite returns, poses or measurements (or boxes beyond 10⁶ m) skipped
  std::uint64_t measurements_dropped = 0;  ///< measurements over max_measurements in their scan, dropped
  std::uint64_t tracks_refused = 0;        ///< clusters that would have started a track beyond max_tracks
  std::uint64_t greedy_associations = 0;   ///< gated components too large for the exact assignment, solved greedily
  std::uint64_t peak_measurements = 0;     ///< the most measurements of one scan (before max_measurements)
  std::uint64_t peak_tracks = 0;           ///< the most tracks after one scan
};

/**
 * @brief The point of @p m that the track @p t follows: the centre of the track's box placed on the cluster. Along
 *        each of the box's axes, when the cluster's extent differs from the box's by more than 0.3 m, the cluster's
 *        end nearest the sensor is taken as the object's end (the rest is hidden, out of range, or not seen yet);
 *        otherwise the middle of the cluster's extent. Without a sensor position, or a box, the centroid.
 */
Point2 referencePoint(const Track& t, const Measurement& m);

/// What the measurement model reads of @p t (measurement_model.hpp).
TrackView trackView(const Track& t);

/// What a track reports as its object (the tracks topic, the scoring of evaluate): centre, heading and extents.
struct ObjectBox
{
  Point2 centre;
  double yaw = 0.0;     ///< rad, map frame
  double length = 0.0;  ///< m, along yaw
  double width = 0.0;   ///< m, across it
};

/// The track's own box: its position with Track::extent_yaw, extent_length and extent_width.
ObjectBox ownBox(const Track& t);

/// True when @p p lies in @p box grown by @p margin (m) on every side.
bool inBox(const ObjectBox& box, Point2 p, double margin);

/**
 * @brief Step "hidden length": @p m's box in the axes of @p heading (rad, map frame), extended away from the sensor
 *        along the heading to @p length when it is at least @p end_width wide across the heading and shallower than
 *        @p length along it (a vehicle seen end-on); nothing otherwise, or without a sensor position.
 */
std::optional<Measurement> hiddenLengthBox(const Measurement& m, double heading, double length, double end_width);

/**
 * @brief The object the track @p t reports, with its last scan's @p measurements: its position with its box
 *        (ownBox()); with step hidden centre (TrackerParams::hidden_centre and evidence_hidden_length > 0), a moving
 *        track seen end-on in its last measurement reports the box of step hidden length along its heading, its
 *        position moved by as much as that box's centre lies from the point the track follows (referencePoint());
 *        a moving track without a measurement in the last scan (coasting) reports Track::seen_box, moved and turned
 *        with its position and heading.
 */
ObjectBox objectBox(const Track& t, const TrackerParams& params, const std::vector<Measurement>& measurements);

/// The multi-object tracker.
class Tracker
{
public:
  /// @throws ParameterError when @p params are out of range.
  explicit Tracker(const TrackerParams& params = TrackerParams{});

  /**
   * @brief One scan: @p returns in the vehicle frame (ScanGridBuilder::obstaclePoints()), the vehicle pose @p pose
   *        in the map frame at @p stamp (s); @p background, when given, flags each return on static background
   *        (backgroundFlags()); @p scan, when given, is the scan's ScanGrid (vehicle frame), the free space of the
   *        step free-space check. A stamp not after the last one, or a pose moving faster than max_ego_speed, resets
   *        every track first (counted).
   */
  void update(double stamp, const Pose2& pose, const ObstaclePoints& returns,
              const std::vector<std::uint8_t>* background = nullptr, const ScanMassGrid* scan = nullptr);
  /// One scan's measurements (map frame), for tests and for callers that cluster themselves (no free-space check:
  /// the motion is decided from the velocity alone).
  void update(double stamp, const std::vector<Measurement>& measurements);

  /// Returns of a measurement a sighting keeps (evenly chosen).
  static constexpr int kSightingPoints = 32;

  const std::vector<Track>& tracks() const { return tracks_; }
  const std::vector<Measurement>& measurements() const { return measurements_; }
  /// The returns of the last scan in the map frame (what Measurement::returns index; empty after update(measurements)).
  const std::vector<Point2>& points() const { return map_points_; }
  const TrackerCounts& counts() const { return counts_; }
  const TrackerParams& params() const { return params_; }
  /// Step common motion: the last scan's common motion (m/s, map frame) at the sensor, (0, 0) when it had none.
  Point2 commonMotion() const { return common_.velocity; }
  bool hasCommonMotion() const { return common_.found; }
  /// Step common turn: the last scan's common motion's turn rate (rad/s, counter-clockwise), 0 when it does not turn.
  double commonTurnRate() const { return common_.turn_rate; }
  /// The last scan's common motion at @p p (map frame): commonMotion() + ω × (p − sensor).
  Point2 commonMotionAt(Point2 p) const { return common_.at(p); }
  /// The speed the motion decision takes: relative to the common motion at the track.
  double decisionSpeed(const Track& t) const { return t.speedRelativeTo(commonMotionAt(t.position())); }
  /// Whether the returns' background flags of the next update() can already mark static background (trackScan():
  /// the MapGrid has fused at least backgroundWarmupScans() scans since its reset). Tracks born while it cannot are
  /// Track::background_unchecked until an association while it can. Default true.
  void setBackgroundKnown(bool known) { background_known_ = known; }
  /// Drops every track and the free space of earlier scans, forgets the last stamp, and counts a reset
  /// (TrackerCounts::resets; ids keep counting up). Called on a time jump or a pose jump.
  void reset();

private:
  void predict(Track& t, double dt) const;
  LifecycleParams lifecycleParams() const { return LifecycleParams{ params_.confirm_hits, params_.max_coast_time }; }
  bool manoeuvres() const { return params_.manoeuvre_jerk_sigma > 0.0; }
  ManoeuvreModel manoeuvreModel() const;
  /// Keeps the max_measurements of @p found nearest the sensor (counted); records the peak.
  void capMeasurements(std::vector<Measurement>& found);
  /// Predicted tracks × measurements_: the gated global assignment and the corrections; which measurements it used.
  std::vector<char> associate(double stamp);
  /// The measurements of this scan that no track took and that are no fragment start tracks in @p kept, within
  /// max_tracks (the nearest first; the others counted).
  void startTracks(std::vector<Track>& kept, const std::vector<char>& used, double stamp);
  /// A new tentative track on @p z (measurement index @p measurement) at @p stamp.
  Track newTrack(const Measurement& z, int measurement, double stamp);
  /// The gated pairs of this scan's tracks and measurements (tracks_ × measurements_), found through a grid.
  SparseCosts gate() const;
  /// The Mahalanobis² of @p z's innovation for @p t, when within the gates.
  std::optional<double> gateCost(const Track& t, const Measurement& z) const;
  /// Kalman update of @p t with @p m and the box's bookkeeping; true when step long box turned the box.
  bool correct(Track& t, const Measurement& m, double stamp) const;
  void decideMotion(Track& t, double stamp) const;
  /// Step free-space check: records @p t's sighting of this scan and tells whether free space shows its motion.
  void seeFreeSpace(Track& t, double stamp);
  /// speed − sigmas · σ(speed) above moving_speed.
  bool fastEnough(const Track& t, double sigmas) const;
  /// Step small free space: @p t is checked with free_space_small_margin.
  bool smallWalker(const Track& t) const;
  /// Step duplicates: deletes from @p tracks the duplicates of moving tracks seen at @p stamp; their clusters become
  /// the kept tracks' fragments.
  void dropDuplicates(std::vector<Track>& tracks, double stamp);
  /// Step hidden centre: each moving track seen this scan remembers the box it reports (Track::seen_box).
  void rememberSeenBoxes();
  /// Step common motion: the common motion of the tracks seen at @p stamp (commonMotion()).
  void findCommonMotion(double stamp);

  TrackerParams params_;
  MeasurementModelParams measurement_model_;  ///< params_' share for the measurement model (set once)
  std::vector<Track> tracks_;
  std::vector<Measurement> measurements_;
  std::vector<Measurement> own_measurements_;  ///< the last scan's clusters (update(stamp, pose, returns))
  std::vector<Point2> map_points_;
  std::vector<std::uint8_t> map_flags_;
  std::deque<SeenFree> seen_free_;  ///< the free space of the scans of the last free_space_time, oldest first
  bool free_now_ = false;           ///< seen_free_ holds this scan's (the check runs)
  CommonMotion common_;             ///< steps common motion and common turn: the last scan's
  std::vector<SeenTrack> common_seen_;  ///< its buffer
  TrackerCounts counts_;
  std::uint32_t next_id_ = 1;
  double last_stamp_ = -1.0;
  Pose2 last_pose_;
  bool background_known_ = true;
};

}  // namespace core
}  // namespace map_aided_fusion

/**
 * @file tracker.hpp
 * @brief Tracked objects (ROS-free): the Tracker, which orchestrates the parts of core/tracking/ per scan: the scan's
 *        measurements (cluster_measurements.hpp, open_ends.hpp), the motion model (motion_model.hpp), the gated
 *        global association (association.hpp, core/assignment.hpp), the lifecycle (lifecycle.hpp: tentative →
 *        confirmed → coasting → deleted), the common motion (common_motion.hpp) and the motion decision
 *        (motion_decision.hpp: moving, stopped or not yet known). Its parameters are in tracker_params.hpp. A scan's
 *        cost is bounded: at most max_measurements measurements and max_tracks tracks, the nearest to the sensor first.
 *
 * Not in the paper: it gives each object an id and a velocity, and the motion evidence the grid's classes lack
 * (doc/evaluation.md scores it with CLEAR-MOT). The `paper` profile does not use it.
 */
#pragma once

#include <cmath>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "map_aided_fusion/core/assignment.hpp"
#include "map_aided_fusion/core/parameters.hpp"
#include "map_aided_fusion/core/grid_geometry.hpp"
#include "map_aided_fusion/core/mass_grid.hpp"
#include "map_aided_fusion/core/seen_free.hpp"
#include "map_aided_fusion/core/tracking/cluster_measurements.hpp"
#include "map_aided_fusion/core/tracking/common_motion.hpp"
#include "map_aided_fusion/core/tracking/lifecycle.hpp"
#include "map_aided_fusion/core/tracking/measurement_model.hpp"
#include "map_aided_fusion/core/tracking/motion_decision.hpp"
#include "map_aided_fusion/core/tracking/motion_model.hpp"
#include "map_aided_fusion/core/tracking/open_ends.hpp"
#include "map_aided_fusion/core/tracking/tracker_params.hpp"

namespace map_aided_fusion {
namespace core {



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
  bool manoeuvres = false;  ///< the IMM runs (step manoeuvres, and a first cluster larger than a pedestrian)
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
  std::uint64_t box_fit = 0;      ///< measurements whose fitted axes are more than BoxFitParams::step_deg off their principal ones (step box fit)
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
 *        (ownBox()); with step hidden centre (TrackerSteps::hidden_centre), a moving
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
  bool manoeuvres() const { return params_.steps.manoeuvres; }
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
  /// Step small free space: @p t is checked with kSmallFreeSpaceMargin.
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

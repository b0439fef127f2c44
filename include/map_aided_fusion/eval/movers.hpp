/**
 * @file movers.hpp
 * @brief Moving objects scored the way their users judge them (ROS-free): per object, when it is first seen and
 *        first detected as moving, the delay, how much of its observed time it is V and how much of it is called
 *        S; summaries per kind; false V where the labels are valid. The same code scores simulated drives (cells
 *        of the ground-truth class grid) and real labelled drives (lidar returns inside labelled boxes).
 *
 * Definitions (doc/evaluation.md, "Scoring moving objects"):
 *  - an object's *occupied cells* in a scan: simulator, the cells of its footprint that the ground truth marks
 *    observed with its class; real data, the decision cells holding an obstacle return that lies in its box;
 *  - it is *seen* in a scan when it has at least min(min_cells, ⌈min_share · footprint cells⌉) occupied cells
 *    (at least one), so that a pedestrian covering four cells is seen with two;
 *  - it is *V* (or *S*) in a scan when more than half of its occupied cells are decided V (or S);
 *  - a mover is an object whose ground truth says moving; its *first seen* is the first scan in which it is seen
 *    moving, its *first detected* the first such scan in which it is V; delay = first detected − first seen;
 *  - V share: of the scans in which it is seen moving, the share in which it is V; S share: of its occupied
 *    cells in those scans, the share decided S;
 *  - parked objects: their V share is the share of their occupied cells decided V;
 *  - false V: cells decided V where the labels are valid, farther than the match radius from the footprint of
 *    every object that is moving or whose motion is ambiguous.
 */
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "map_aided_fusion/core/scan_grid.hpp"
#include "map_aided_fusion/eval/truth.hpp"

namespace map_aided_fusion {
namespace eval {

/// Ground-truth motion of an object at one instant.
enum class MotionTruth : std::uint8_t
{
  kMoving,
  kParked,     ///< stopped or parked
  kAmbiguous,  ///< between the parked and the moving speed (real labels): not judged
};

/// The kind groups of the tables.
enum class ObjectGroup : std::uint8_t
{
  kVehicle,     ///< car, van, bus, truck, tram
  kCyclist,     ///< cyclist, bicycle, motorcyclist
  kPedestrian,  ///< pedestrian, person_sitting
  kOther,
};
constexpr int kNumObjectGroups = 4;
/// "vehicle", "cyclist", "pedestrian", "other".
const char* groupName(ObjectGroup g);
/// The group of a kind name (case-insensitive: "Car", "van", "Person_sitting"…).
ObjectGroup groupOf(const std::string& kind);
/// The motion of a ground-truth object's class code: V moving, S parked, unknown (−1) ambiguous; others: none.
bool motionOf(core::CellClass cell_class, MotionTruth& motion);

/// How a sighted object was decided in one scan (timeline codes).
enum class SightingState : std::int8_t
{
  kUnseen = 0,  ///< labelled, but fewer occupied cells than needed
  kV = 1,       ///< more than half of its occupied cells decided V
  kS = 2,       ///< more than half decided S
  kOther = 3,   ///< seen, neither
};

/// One labelled object in one scan and the decisions on its occupied cells.
struct ObjectSighting
{
  std::uint32_t id = 0;
  std::string kind;
  MotionTruth motion = MotionTruth::kMoving;
  double speed = 0.0;                 ///< m/s (ground truth)
  std::uint32_t footprint_cells = 0;  ///< decision cells whose centre lies in its footprint
  std::uint32_t occupied_cells = 0;
  /// Of the occupied cells, how many are decided F, C, N, S, V, 5 (occupied, motion not known), unknown.
  std::array<std::uint32_t, kNumCellClasses + 2> decided{};
  std::uint32_t decidedAs(core::CellClass c) const;
};

/// Thresholds of "seen" (see the file comment).
struct SightingRule
{
  int min_cells = 3;
  double min_share = 0.5;
  /// The number of occupied cells an object of @p footprint_cells cells needs to be seen.
  std::uint32_t needed(std::uint32_t footprint_cells) const;
};

/**
 * @brief The simulator's sightings: per moving or stopped object, its footprint cells in the decision grid and,
 *        of those, the cells that the ground truth marks observed with the object's own class.
 */
std::vector<ObjectSighting> sightingsFromClassGrid(const ClassGrid& truth, const std::vector<TruthObject>& objects,
                                                   const ClassGrid& decision);

/// A labelled object with the (map-frame) positions of the obstacle returns that lie in its box in one sweep.
struct ObjectReturns
{
  TruthObject object;
  std::vector<core::Point2> returns;
};

/// Which returns of a sweep belong to a labelled box (collectObjectReturns()).
struct ReturnsInBoxes
{
  double obstacle_low = 0.0;   ///< m, height band of an obstacle return in the vehicle frame (the ScanGrid's)
  double obstacle_high = 0.0;  ///< m
  double margin = 0.2;         ///< m, a box grown by this on every side (label noise)
};

/**
 * @brief The sweep's obstacle returns (vehicle-frame height within the band) that lie in each object's box grown by
 *        the margin (footprint, and height when the object's height is known), in the map frame.
 * @param map_sensor   map ← cloud frame
 * @param base_sensor  vehicle ← cloud frame
 */
std::vector<ObjectReturns> collectObjectReturns(const core::PointCloudView& cloud, const Eigen::Isometry3d& map_sensor,
                                                const Eigen::Isometry3d& base_sensor,
                                                const std::vector<TruthObject>& objects, const ReturnsInBoxes& rule);

/**
 * @brief Real data's sightings: per object, its footprint cells in the decision grid and the decision cells holding
 *        one of its returns (occupied cells). Objects whose class code is not V, S or unknown are skipped.
 */
std::vector<ObjectSighting> sightingsFromReturns(const std::vector<ObjectReturns>& objects, const ClassGrid& decision);

/**
 * @brief Cells decided V where @p valid (when given; map frame, code > 0 means labels valid) is valid, whose centre
 *        is farther than @p radius from the footprint of every object that is moving or ambiguous.
 */
std::uint64_t countFalseV(const ClassGrid& decision, const ClassGrid* valid, const std::vector<TruthObject>& objects,
                          double radius);

/// One object over the run.
struct MoverRecord
{
  std::uint32_t id = 0;
  std::string kind;
  ObjectGroup group = ObjectGroup::kOther;
  double max_speed = 0.0;     ///< m/s, the largest ground-truth speed while labelled
  // While moving:
  int moving_scans = 0;       ///< scans labelled moving
  int seen_moving = 0;        ///< of those, seen
  int v_scans = 0;            ///< of those, V
  double first_seen = -1.0;   ///< stamp (s) of the first scan seen moving; −1: never
  double first_detected = -1.0;
  std::uint64_t occupied = 0, occupied_v = 0, occupied_s = 0;  ///< cells summed over the moving, seen scans
  // While parked:
  int parked_seen = 0;
  std::uint64_t parked_occupied = 0, parked_v = 0;
  /// Per scan index (MoverScorer::stamps()), its state while moving (unseen when not labelled or not moving).
  std::vector<std::pair<std::size_t, SightingState>> timeline;
  bool isMover() const { return moving_scans > 0; }
  /// Delay in seconds, or −1 when never detected (or never seen).
  double delay() const { return first_detected >= 0.0 && first_seen >= 0.0 ? first_detected - first_seen : -1.0; }
  double vShare() const { return seen_moving ? static_cast<double>(v_scans) / seen_moving : 0.0; }
  double sShare() const { return occupied ? static_cast<double>(occupied_s) / static_cast<double>(occupied) : 0.0; }
  double vCellShare() const { return occupied ? static_cast<double>(occupied_v) / static_cast<double>(occupied) : 0.0; }
};

/// Accumulates sightings scan after scan.
class MoverScorer
{
public:
  explicit MoverScorer(SightingRule rule = SightingRule{});

  /**
   * @param stamp     s
   * @param sightings the labelled objects of the scan (objects with no label in the scan are absent)
   * @param false_v   countFalseV() of the scan
   */
  void add(double stamp, const std::vector<ObjectSighting>& sightings, std::uint64_t false_v);

  const SightingRule& rule() const { return rule_; }
  /// True when @p s is seen by this scorer's rule.
  bool seen(const ObjectSighting& s) const { return s.occupied_cells > 0 && s.occupied_cells >= rule_.needed(s.footprint_cells); }
  const std::vector<double>& stamps() const { return stamps_; }
  const std::map<std::uint32_t, MoverRecord>& records() const { return records_; }
  double falseVPerScan() const;

  /**
   * @brief Per group g in {all, vehicle, cyclist, pedestrian, other}: "movers.g.seen", "movers.g.labelled",
   *        "movers.g.detected_within_0_5s", "movers.g.detected_within_1s", "movers.g.never_detected",
   *        "movers.g.median_delay_s" (never detected counts as infinite: NaN when more than half never are),
   *        "movers.g.mean_v_share", "movers.g.s_share" (pooled cells), "parked.g.objects", "parked.g.v_share"
   *        (pooled cells); and "movers.false_v_per_scan", "movers.scans".
   */
  std::map<std::string, double> summary() const;

private:
  SightingRule rule_;
  std::vector<double> stamps_;
  std::uint64_t false_v_ = 0;
  std::map<std::uint32_t, MoverRecord> records_;
};

/**
 * @brief The movers table, Markdown: one row per scorer, and with @p per_kind one more per kind group that has movers
 *        or parked objects.
 */
std::string moversMarkdown(const std::vector<std::pair<std::string, const MoverScorer*>>& rows, bool per_kind = true);
/// The per-object table of one scorer (movers only), Markdown.
std::string moverObjectsMarkdown(const MoverScorer& scorer);
/**
 * @brief JSON of a scorer's objects: {"stamps": [...], "objects": [{"id", "kind", "group", "mover", "max_speed",
 *        "first_seen_s", "first_detected_s", "delay_s", "seen_scans", "occupied_cells" (while moving and seen),
 *        "v_share", "v_cell_share", "s_share", "parked_v_share",
 *        "timeline": [[scan, state], ...]}, ...]}; states: 0 unseen, 1 V, 2 S, 3 other.
 */
std::string moverObjectsJson(const MoverScorer& scorer);

}  // namespace eval
}  // namespace map_aided_fusion

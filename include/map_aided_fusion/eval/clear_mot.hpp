/**
 * @file clear_mot.hpp
 * @brief CLEAR-MOT scores of tracked objects against ground truth (ROS-free), after Bernardin and Stiefelhagen,
 *        "Evaluating Multiple Object Tracking Performance: The CLEAR MOT Metrics" (2008).
 *
 * Per frame: a correspondence of the previous frame (object ↔ hypothesis) is kept while both are present and
 * their centres are within the match distance; the remaining objects and hypotheses are paired by a gated global
 * assignment (core/assignment.hpp) that makes as many pairs as possible within the match distance and, among
 * those, minimises the summed distance. A new pair whose object was last paired with another hypothesis is an
 * identity switch. Unpaired judged objects are misses, unpaired hypotheses false positives — except hypotheses
 * within the match distance of the footprint of an object that is not judged (a parked car, one whose motion is
 * ambiguous or a mover out of sight, when only seen movers are scored): those are left out. The footprint, not the
 * centre, so that a track on the near end of a bus seen end-on, which is a real object, is not a false positive.
 *
 *  - MOTA = 1 − (misses + false positives + identity switches) / judged objects, summed over frames;
 *  - MOTP = summed distance of the pairs / number of pairs (metres; lower is better);
 *  - fragmentations: per object, how often its tracked state goes from tracked to untracked and is resumed later;
 *  - velocity error: |v_hypothesis − v_object| over the pairs where both velocities are known (RMSE and median);
 *  - per object, the identity share: of the frames it is present and judged, the share in which it is paired with
 *    its most frequent hypothesis id; and its own velocity errors (pairs, RMSE, median) with their share of the
 *    squared velocity error of all objects (which objects make the RMSE).
 */
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "map_aided_fusion/core/grid_geometry.hpp"

namespace map_aided_fusion {
namespace eval {

/// A ground-truth object in one frame.
struct MotObject
{
  std::uint32_t id = 0;
  core::Point2 position;
  bool judged = true;  ///< false: not scored (a hypothesis on it is neither a match nor a false positive)
  bool has_velocity = false;
  core::Point2 velocity;  ///< m/s, when has_velocity
  /// Footprint (m, rad) about position, for the objects that are not judged: a hypothesis within the match distance
  /// of it is left out. 0 × 0: a point.
  double length = 0.0, width = 0.0, yaw = 0.0;
};

/// A tracker's hypothesis (track) in one frame.
struct MotHypothesis
{
  std::uint32_t id = 0;
  core::Point2 position;
  bool has_velocity = false;
  core::Point2 velocity;  ///< m/s, when has_velocity
};

/// What one judged object got over the sequence.
struct MotObjectRecord
{
  std::uint32_t id = 0;
  std::uint64_t frames = 0;          ///< frames it is present and judged
  std::uint64_t tracked_frames = 0;  ///< of those, paired with a hypothesis
  std::uint64_t fragmentations = 0;
  std::uint64_t id_switches = 0;
  double identity_share = 0.0;       ///< frames paired with its most frequent hypothesis id / frames
  std::uint64_t velocity_pairs = 0;  ///< its pairs with both velocities known
  double velocity_rmse = 0.0;        ///< m/s over those pairs; NaN without any
  double velocity_median = 0.0;      ///< m/s; NaN without any
  /// Its squared velocity errors / those of every object (0 when no object has any): its share of RMSE².
  double velocity_error_share = 0.0;
};

/// Accumulates CLEAR-MOT counts frame after frame.
class ClearMot
{
public:
  /// @param match_distance  metres between centres for a pair (the threshold T), > 0
  explicit ClearMot(double match_distance = 2.0);

  void addFrame(const std::vector<MotObject>& objects, const std::vector<MotHypothesis>& hypotheses);

  double matchDistance() const { return threshold_; }
  std::uint64_t frames() const { return frames_; }
  std::uint64_t objects() const { return objects_; }  ///< judged objects summed over frames
  std::uint64_t matches() const { return matches_; }
  std::uint64_t misses() const { return misses_; }
  std::uint64_t falsePositives() const { return false_positives_; }
  std::uint64_t idSwitches() const { return id_switches_; }
  std::uint64_t fragmentations() const;
  /// 1 − (misses + false positives + switches) / objects; without judged objects, 1 − errors (1 with no error).
  double mota() const;
  /// Mean distance of the pairs (m); NaN without pairs.
  double motp() const;
  /// Pairs with both velocities known.
  std::uint64_t velocityPairs() const { return velocity_errors_.size(); }
  /// Root mean square of the velocity errors (m/s); NaN without such pairs.
  double velocityRmse() const;
  /// Median of the velocity errors (m/s); NaN without such pairs.
  double velocityMedian() const;
  /// Per judged object, ordered by id.
  std::vector<MotObjectRecord> records() const;
  /// "frames", "objects", "matches", "misses", "false_positives", "id_switches", "fragmentations", "mota", "motp_m",
  /// "velocity_pairs", "velocity_rmse_mps", "velocity_median_mps".
  std::map<std::string, double> summary() const;

private:
  struct History
  {
    std::uint64_t frames = 0, tracked = 0, switches = 0;
    std::int64_t last_hypothesis = -1;  ///< the hypothesis it was last paired with (−1: never)
    bool tracked_now = false;
    bool ever_tracked = false;
    std::uint64_t pending_gaps = 0;     ///< tracked → untracked transitions not yet resumed
    std::uint64_t fragmentations = 0;
    std::map<std::uint32_t, std::uint64_t> paired_with;
    std::vector<double> velocity_errors;  ///< m/s, its pairs with both velocities known
  };
  double threshold_;
  std::uint64_t frames_ = 0, objects_ = 0, matches_ = 0, misses_ = 0, false_positives_ = 0, id_switches_ = 0;
  double distance_sum_ = 0.0;
  std::vector<double> velocity_errors_;
  std::map<std::uint32_t, std::uint32_t> previous_;  ///< object id → hypothesis id, pairs of the last frame
  std::map<std::uint32_t, History> history_;
};

}  // namespace eval
}  // namespace map_aided_fusion

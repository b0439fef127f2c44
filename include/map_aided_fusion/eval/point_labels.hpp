/**
 * @file point_labels.hpp
 * @brief Scores of a MapGrid's decisions against per-point ground truth (real labelled lidar, e.g.
 *        SemanticKITTI), ROS-free: where moving and static points of each sweep fall in the decision grid.
 */
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "map_aided_fusion/eval/metrics.hpp"

namespace map_aided_fusion {
namespace eval {

/// Motion state of a labelled point (the codes of the `state` field of `/ground_truth/points`).
enum class LabelState : std::uint8_t
{
  kUnlabelled = 0,
  kStatic = 1,
  kMoving = 2,
};

/// One labelled point of a sweep, in the map frame.
struct LabelledPoint
{
  core::Point2 p;
  LabelState state = LabelState::kUnlabelled;
  /// True for a point the sensor model treats as an obstacle (height band, not a ground class).
  bool obstacle = false;
  std::uint32_t instance = 0;  ///< moving points: an id of the object (0: none)
};

/// The scores of one sweep.
struct PointScanScore
{
  double stamp = 0.0;
  bool labelled = false;
  std::uint64_t v_cells = 0;         ///< cells decided V
  std::uint64_t false_v = 0;         ///< labelled sweeps: V cells farther than the match radius from any moving point
  std::uint64_t v_on_static = 0;     ///< labelled sweeps: V cells holding a static obstacle point and no moving one
  std::uint64_t mover_cells = 0;     ///< labelled sweeps: cells holding a moving obstacle point
  std::uint64_t mover_v_cells = 0;   ///< of those, decided V
  /// Labelled sweeps: cells holding static obstacle points and no moving one, by decision (F, C, N, S, V, unknown).
  std::array<std::uint64_t, kNumCellClasses + 1> static_cells{};
};

/// One moving object over the run.
struct MovingInstance
{
  std::uint32_t id = 0;
  double first_seen = -1.0;  ///< stamp of the first labelled sweep that holds it
  double first_v = -1.0;     ///< stamp of the first sweep with one of its cells decided V (−1: never)
  int sweeps = 0;            ///< labelled sweeps that hold it
  std::vector<double> v_share;  ///< per such sweep, the share of its cells decided V
};

/**
 * @brief Accumulates sweep after sweep. A V cell counts as false when no moving point of the sweep lies within
 *        the match radius of its centre (a square neighbourhood of ceil(radius / resolution) cells); unlabelled
 *        sweeps only count V cells, never as static.
 */
class PointLabelScorer
{
public:
  explicit PointLabelScorer(double match_radius = 1.0);

  /// One sweep: the decision grid (map frame) and the sweep's points (map frame); @p labelled false when the
  /// sweep has no ground truth.
  void add(double stamp, const ClassGrid& decision, const std::vector<LabelledPoint>& points, bool labelled);

  const std::vector<PointScanScore>& sweeps() const { return sweeps_; }
  const std::map<std::uint32_t, MovingInstance>& instances() const { return instances_; }
  double matchRadius() const { return radius_; }

  /**
   * @brief Summary: "sweeps", "labelled_sweeps", "v_cells_per_sweep", "false_v_per_labelled_sweep",
   *        "v_on_static_per_labelled_sweep", "v_cells_per_unlabelled_sweep", "mover_cells_v_share" (pooled),
   *        "mover_min_v_share_from_third_sweep" (over instances and their sweeps from their third labelled one;
   *        −1 when none), "mover_first_v_delay_s" (mean over instances decided V at least once; −1 when none),
   *        "movers", "movers_never_v", "static_cells.{F,C,N,S,V,unknown}" (shares of static obstacle cells).
   */
  std::map<std::string, double> summary() const;

private:
  double radius_;
  std::vector<PointScanScore> sweeps_;
  std::map<std::uint32_t, MovingInstance> instances_;
};

/// A Markdown table of point-label scores, one row per named scorer.
std::string pointLabelMarkdown(const std::vector<std::pair<std::string, const PointLabelScorer*>>& rows);

}  // namespace eval
}  // namespace map_aided_fusion

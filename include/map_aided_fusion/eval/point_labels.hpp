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

#include "map_aided_fusion/core/return_class.hpp"
#include "map_aided_fusion/eval/metrics.hpp"
#include "map_aided_fusion/eval/scan_evidence.hpp"

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
  /// True for a ground class (SemanticKITTI road 40, parking 44, sidewalk 48, other-ground 49, lane-marking 60,
  /// terrain 72).
  bool ground = false;
  /// True for vegetation (SemanticKITTI 70): left out of the ground segmentation's scores, as in its literature.
  bool vegetation = false;
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
  std::uint64_t ground_cells = 0;    ///< cells holding ground-class points and no labelled point of another class
  std::uint64_t ground_f_cells = 0;  ///< of those, decided F
  bool has_evidence = false;         ///< the scan's evidence was given (ground_not_f is counted)
  /// Labelled-ground cells not decided F, by what the sweep's scan gave them (ScanEvidence codes).
  std::array<std::uint64_t, kNumScanEvidence> ground_not_f{};
  std::uint64_t obstacle_cells = 0;  ///< cells holding a labelled obstacle point (static or moving)
  std::uint64_t obstacle_f_cells = 0;  ///< of those, decided F (false free)
  std::uint64_t rigid_cells = 0;     ///< cells holding a labelled obstacle point that is not vegetation
  std::uint64_t rigid_f_cells = 0;   ///< of those, decided F
  std::uint64_t mover_s_cells = 0;   ///< cells holding a moving obstacle point, decided S (stopped)
  /// Points (unlabelled left out): moving and in a V cell, static in a V cell, moving elsewhere. Static points of a
  /// ground class are left out of moving_fp: the ground under a mover shares its cells in a 2-D grid.
  std::uint64_t moving_tp = 0, moving_fp = 0, moving_fn = 0;
};

/// Point-level ground segmentation counts (a ground class is the positive class; vegetation and unlabelled points
/// are left out, and so are the returns the sensor model rejects).
struct GroundSegmentationCounts
{
  std::uint64_t tp = 0;  ///< ground points the model calls ground
  std::uint64_t fp = 0;  ///< other points the model calls ground
  std::uint64_t fn = 0;  ///< ground points the model does not call ground
  std::uint64_t tn = 0;  ///< other points the model does not call ground
  std::uint64_t ground_as_obstacle = 0;  ///< ground points the model calls obstacle (they mark occupied cells)
  GroundSegmentationCounts& operator+=(const GroundSegmentationCounts& o);
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
  /// Default of settleTime(): ground cells are also scored from this long after the first sweep on, s.
  static constexpr double kDefaultSettleTime = 0.5;

  explicit PointLabelScorer(double match_radius = 1.0, double settle_time = kDefaultSettleTime);

  /// One sweep: the decision grid (map frame) and the sweep's points (map frame); @p labelled false when the
  /// sweep has no ground truth.
  void add(double stamp, const ClassGrid& decision, const std::vector<LabelledPoint>& points, bool labelled);
  /// add(), and for each labelled-ground cell not decided F what the sweep's scan gave it: @p evidence, on the
  /// decision's geometry (scanEvidence(), then refineAmbiguous()); nullptr or another geometry: not counted.
  void add(double stamp, const ClassGrid& decision, const std::vector<LabelledPoint>& points, bool labelled,
           const EvidenceGrid* evidence);

  /**
   * @brief The ScanGrid's ground segmentation of one labelled sweep: @p classes holds what the sensor model made of
   *        each of @p points (same order, ScanGridBuilder::returnClasses()). A size mismatch throws
   *        std::invalid_argument.
   */
  void addSegmentation(const std::vector<LabelledPoint>& points, const std::vector<core::ReturnClass>& classes);
  const GroundSegmentationCounts& segmentation() const { return segmentation_; }
  /// True once addSegmentation() was called.
  bool scoresSegmentation() const { return segmented_sweeps_ > 0; }

  const std::vector<PointScanScore>& sweeps() const { return sweeps_; }
  const std::map<std::uint32_t, MovingInstance>& instances() const { return instances_; }
  double matchRadius() const { return radius_; }
  double settleTime() const { return settle_; }

  /**
   * @brief Summary: "sweeps", "labelled_sweeps", "v_cells_per_sweep", "false_v_per_labelled_sweep",
   *        "v_on_static_per_labelled_sweep", "v_cells_per_unlabelled_sweep", "mover_cells_v_share" (pooled),
   *        "mover_min_v_share_from_third_sweep" (over instances and their sweeps from their third labelled one;
   *        −1 when none), "mover_first_v_delay_s" (mean over instances decided V at least once; −1 when none),
   *        "movers", "movers_never_v", "static_cells.{F,C,N,S,V,unknown}" (shares of static obstacle cells);
   *        "ground_cells_f_recall" (labelled-ground cells decided F, pooled over the labelled sweeps; −1 when none),
   *        "ground_cells_f_recall_settled" (the same from settleTime() after the first sweep on),
   *        "obstacle_cells_false_free" (labelled-obstacle cells decided F), "rigid_cells_false_free" (the same for
   *        the cells holding an obstacle point other than vegetation), "mover_cells_s_share" (cells holding a moving
   *        obstacle point decided S), "moving_point_iou" (points in V cells
   *        against moving points: TP / (TP + FP + FN); −1 without a moving point or a V point), with
   *        addSegmentation() "ground_segmentation.{precision,recall,f1,ground_as_obstacle}", with evidence
   *        "ground_cells_not_f.{free,occupied,cleared,unreached,ambiguous}" (labelled-ground cells not decided F by
   *        what the sweep's scan gave them, as shares of the labelled-ground cells of those sweeps), and every count
   *        behind them under "counts." (for pooling several sequences: sum the counts, then divide).
   */
  std::map<std::string, double> summary() const;

private:
  /// summary()'s ground, obstacle, moving-point and segmentation scores and their counts.
  void addCellAndPointScores(std::map<std::string, double>& m) const;
  /// summary()'s labelled-ground cells not decided F, by the scan's evidence (nothing without evidence).
  void addGroundLossScores(std::map<std::string, double>& m) const;

  double radius_;
  double settle_;
  double first_stamp_ = -1.0;
  std::size_t segmented_sweeps_ = 0;
  GroundSegmentationCounts segmentation_;
  std::vector<PointScanScore> sweeps_;
  std::map<std::uint32_t, MovingInstance> instances_;
};

/// Ratio a / b of two counts; −1 when b is 0 (nothing to score).
double countRatio(double a, double b);
/// F1 of precision and recall counts: 2 TP / (2 TP + FP + FN); −1 when the denominator is 0.
double f1Score(double tp, double fp, double fn);

/// A Markdown table of point-label scores, one row per named scorer.
std::string pointLabelMarkdown(const std::vector<std::pair<std::string, const PointLabelScorer*>>& rows);

}  // namespace eval
}  // namespace map_aided_fusion

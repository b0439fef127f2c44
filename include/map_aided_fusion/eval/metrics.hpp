/**
 * @file metrics.hpp
 * @brief Scores of a MapGrid against ground truth (ROS-free): per-cell confusion over F, C, N, S, V and
 *        object-level scores for moving and stopped objects.
 */
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "map_aided_fusion/core/cell_class.hpp"
#include "map_aided_fusion/core/grid_geometry.hpp"
#include "map_aided_fusion/eval/clear_mot.hpp"
#include "map_aided_fusion/eval/movers.hpp"
#include "map_aided_fusion/eval/truth.hpp"

namespace map_aided_fusion {
namespace eval {

/// Confusion counts: rows = ground truth, columns = decision (plus a column for "unknown" decisions).
class ConfusionMatrix
{
public:
  /// Index of the "no decision" column.
  static constexpr int kUnknownColumn = kNumCellClasses;

  void add(int truth, int decision, std::uint64_t count = 1);
  void add(const ConfusionMatrix& other);
  std::uint64_t count(int truth, int decision) const { return counts_[truth][decision]; }

  /// Of the cells decided c, the fraction that are c (0 when none is decided c).
  double precision(int c) const;
  /// Of the cells that are c, the fraction decided c (an unknown decision counts as a miss).
  double recall(int c) const;
  /// |decided c ∩ truly c| / |decided c ∪ truly c|.
  double iou(int c) const;
  /// Observed cells that are c.
  std::uint64_t support(int c) const;
  /// Fraction of observed cells that got a decision.
  double coverage() const;
  /// Fraction of decided cells whose decision is right.
  double accuracy() const;
  /// Mean IoU over the classes present in the ground truth.
  double meanIou() const;

private:
  std::array<std::array<std::uint64_t, kNumCellClasses + 1>, kNumCellClasses> counts_{};
};

/**
 * @brief Adds to @p m every cell of @p truth that is observed (not kUnknown), compared with the decision at
 *        the same world position. Returns the number of cells compared.
 */
std::uint64_t accumulate(const ClassGrid& truth, const ClassGrid& decision, ConfusionMatrix& m);

/// Object-level scores accumulated scan after scan.
class ObjectScorer
{
public:
  /**
   * @param min_visible_cells  an object is visible in a scan when this many of its footprint cells are
   *                           observed with its own class in the ground truth
   * @param detection_window   a moving object counts as detected when the majority of its visible cells are
   *                           decided V within this many seconds of first becoming visible
   */
  explicit ObjectScorer(int min_visible_cells = 3, double detection_window = 1.0, double hidden_window = 3.0);

  /// One scan: ground truth classes and objects, the decision grid.
  void add(double stamp, const ClassGrid& truth, const std::vector<TruthObject>& objects, const ClassGrid& decision);

  /// Moving objects ever visible.
  int movingVisible() const;
  /// Moving objects detected within the window.
  int movingDetected() const;
  /// Mean delay from first visibility to first detection (detected objects), seconds.
  double meanDetectionDelay() const;
  /// Fraction of (stopped object, scan) pairs, where visible, whose majority of cells is decided V.
  double stoppedCalledMoving() const;
  /// Fraction of (stopped object, scan) pairs, where visible, whose majority of cells is decided S.
  double stoppedRecognised() const;
  /**
   * @brief Of the (stopped object, scan) pairs where the object is hidden (fewer than min_visible_cells observed)
   *        but was visible less than @p hidden_window seconds ago, the fraction whose footprint is still mostly
   *        decided S: "the parked bus is still in evidence despite being occluded".
   */
  double stoppedKeptWhileHidden() const;
  /// Number of such (hidden stopped object, scan) pairs.
  std::uint64_t stoppedHiddenPairs() const { return hidden_pairs_; }
  /// Cells decided V where the ground truth is free, per scan (V trails left behind movers).
  double trailCellsPerScan() const;
  /// Fraction of observed free cells decided V.
  double trailFraction() const;

private:
  struct Track
  {
    double first_visible = -1.0;
    double first_detected = -1.0;
  };
  int min_visible_;
  double window_;
  double hidden_window_;
  std::map<std::uint32_t, Track> moving_;
  std::map<std::uint32_t, double> stopped_last_visible_;
  std::uint64_t hidden_pairs_ = 0, hidden_kept_ = 0;
  std::uint64_t stopped_pairs_ = 0, stopped_moving_ = 0, stopped_stopped_ = 0;
  std::uint64_t scans_ = 0, trail_cells_ = 0, free_cells_ = 0;
};

/// Scores of one pipeline variant over a run.
struct VariantScores
{
  std::string name;
  std::string description;
  ConfusionMatrix confusion;
  ObjectScorer objects;
  std::uint64_t scans = 0;
  MoverScorer movers = MoverScorer{};  ///< moving objects per object (eval/movers.hpp); empty when nothing was added
  ClearMot tracks = ClearMot{};        ///< the tracker's moving tracks against the movers; no frame without a tracker
};

/**
 * @brief The truth of one scan for CLEAR-MOT: movers seen in the scan (@p sightings, @p scorer's rule) are judged;
 *        every other object (parked, ambiguous, a mover hidden or out of range) is not.
 */
std::vector<MotObject> motObjects(const std::vector<TruthObject>& objects, const std::vector<ObjectSighting>& sightings,
                                  const MoverScorer& scorer);

/// CLEAR-MOT per variant with tracks (Markdown): the counts, MOTA, MOTP, velocity errors, then per mover its
/// identity share.
std::string tracksMarkdown(const std::vector<VariantScores>& variants);

/// A flat, self-explaining map of metric names ("moving.recall", "objects.moving.detection_rate"…) to values;
/// with movers scored, also MoverScorer::summary()'s keys; with tracks, ClearMot::summary()'s as "tracks.*".
std::map<std::string, double> flatten(const VariantScores& v);

/// metrics.json: {"variants": {name: {"description": …, metric: value…, "movers_objects": {…}, "tracks_objects":
/// […]}}, "meta": {…}}; "movers_objects" (moverObjectsJson()) only when movers were scored, "tracks_objects" (each
/// judged object's ClearMot record: identity share, velocity pairs, RMSE, median and share of the squared velocity
/// error) only with tracks.
std::string toJson(const std::vector<VariantScores>& variants, const std::map<std::string, std::string>& meta);

/// metrics.json of labelled boxes (no class grid): {"meta": {…}, "variants": {name: {"description": …, "scans": …,
/// MoverScorer::summary()'s keys…, "movers_objects": {…}, "tracks_objects": […]}}} (as toJson()).
std::string moversJson(const std::vector<VariantScores>& variants, const std::map<std::string, std::string>& meta);

/// A Markdown table, one row per variant.
std::string toMarkdown(const std::vector<VariantScores>& variants);

}  // namespace eval
}  // namespace map_aided_fusion

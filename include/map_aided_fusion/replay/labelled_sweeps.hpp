/**
 * @file labelled_sweeps.hpp
 * @brief The labelled sweeps of a replay waiting to be scored (ROS-free): a bag holds a sweep's cloud and its
 *        labelled points (`/ground_truth/points`) in either order, so what each variant made of the cloud waits for
 *        the points, or the points for it.
 */
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <vector>

#include "map_aided_fusion/core/return_class.hpp"
#include "map_aided_fusion/eval/metrics.hpp"
#include "map_aided_fusion/eval/point_labels.hpp"
#include "map_aided_fusion/eval/scan_evidence.hpp"

namespace map_aided_fusion {
namespace replay {

/// What one variant made of a labelled sweep's cloud.
struct VariantSweep
{
  eval::ClassGrid decision;                 ///< its decisions after the sweep
  std::vector<core::ReturnClass> classes;   ///< what its ScanGrid made of each point (ScanGridBuilder::returnClasses)
  eval::EvidenceGrid evidence;              ///< what its scan gave each window cell (eval::scanEvidence)
};

/// A labelled sweep with both halves: every variant's, in variant order, and the labelled points (map frame).
struct LabelledSweep
{
  std::vector<VariantSweep> variants;
  std::vector<eval::LabelledPoint> points;
};

/// The labelled sweeps waiting for their other half, keyed by the sweep's stamp (ns).
class LabelledSweeps
{
public:
  /// The next variant's half of the sweep stamped @p stamp_ns (variants in their order).
  void addVariant(std::int64_t stamp_ns, VariantSweep sweep) { variants_[stamp_ns].push_back(std::move(sweep)); }
  /// The labelled points of the sweep stamped @p stamp_ns (a second call replaces the first).
  void addPoints(std::int64_t stamp_ns, std::vector<eval::LabelledPoint> points)
  {
    points_[stamp_ns] = std::move(points);
  }
  /// The sweep stamped @p stamp_ns once both halves are there, removed from the waiting ones; nothing otherwise.
  std::optional<LabelledSweep> take(std::int64_t stamp_ns);
  /// Sweeps not taken yet (one half or both).
  std::size_t waiting() const;

private:
  std::map<std::int64_t, std::vector<VariantSweep>> variants_;
  std::map<std::int64_t, std::vector<eval::LabelledPoint>> points_;
};

/**
 * @brief Scores one variant's half of a complete labelled sweep into @p scorer: the evidence's ambiguous cells
 *        (eval::refineAmbiguous, when the classes match the points), the decisions with the evidence
 *        (PointLabelScorer::add) and the ground segmentation (PointLabelScorer::addSegmentation).
 * @throws std::invalid_argument when the classes do not match the points (from addSegmentation)
 */
void scoreSweep(double stamp, VariantSweep& sweep, const std::vector<eval::LabelledPoint>& points,
                eval::PointLabelScorer& scorer);

}  // namespace replay
}  // namespace map_aided_fusion

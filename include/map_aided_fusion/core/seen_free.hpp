/**
 * @file seen_free.hpp
 * @brief Where one scan saw free space, clear of every obstacle (ROS-free): the evidence of step "free-space check"
 *        (core/tracker.hpp), which calls a track moving only once free space shows that it left a place or came into
 *        one.
 */
#pragma once

#include <cstdint>
#include <vector>

#include "map_aided_fusion/core/grid_geometry.hpp"
#include "map_aided_fusion/core/mass_grid.hpp"

namespace map_aided_fusion {
namespace core {

/**
 * @brief One scan's free space: a ScanGrid cell is clear when it and every cell within the margin (square
 *        neighbourhood, whole cells, rounded up) have m(F) ≥ kSeenFreeMass. A point on a cell's edge, next to a wall
 *        or an object, or where the scan did not look is then never in clear space.
 */
class SeenFree
{
public:
  /// m(F) a ScanGrid cell needs to count as seen free.
  static constexpr float kSeenFreeMass = 0.5f;

  SeenFree() = default;
  /**
   * @param scan    the ScanGrid (vehicle frame)
   * @param pose    the vehicle pose in the map frame
   * @param stamp   the scan's time, s
   * @param margin  m: every cell this near (whole cells, rounded up) must be seen free too; ≥ 0
   * @param small_margin  m: the margin of a second, tighter test (clear(p, true)); negative: none, clear(p, true) is
   *                      clear(p)
   */
  SeenFree(const ScanMassGrid& scan, const Pose2& pose, double stamp, double margin, double small_margin = -1.0);

  /// True when the map-frame point @p p lies in a clear cell (false outside the grid or for a non-finite point); with
  /// @p small, clear at small_margin.
  bool clear(Point2 p, bool small = false) const;
  /// Share of @p points that lie in clear cells (0 for none); with @p small, at small_margin.
  double clearShare(const std::vector<Point2>& points, bool small = false) const;
  double stamp() const { return stamp_; }
  /// Number of clear cells.
  std::size_t clearCells() const { return clear_count_; }

private:
  GridGeometry geometry_;
  Pose2 pose_;
  double cos_ = 1.0, sin_ = 0.0;
  double stamp_ = 0.0;
  std::vector<std::uint8_t> clear_;
  std::vector<std::uint8_t> clear_small_;  ///< empty without a small margin
  std::size_t clear_count_ = 0;
};

}  // namespace core
}  // namespace map_aided_fusion

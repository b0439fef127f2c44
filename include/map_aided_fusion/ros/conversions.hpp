/**
 * @file conversions.hpp
 * @brief Static converters between the ROS-free core grids and ROS messages
 *        (map_aided_fusion/EvidentialGrid, nav_msgs/OccupancyGrid), in the spirit of grid_map_ros.
 *        None of them needs a ROS master.
 */
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>

#include <nav_msgs/MapMetaData.h>
#include <nav_msgs/OccupancyGrid.h>
#include <std_msgs/Header.h>

#include "map_aided_fusion/EvidentialGrid.h"
#include "map_aided_fusion/core/grid_ops.hpp"
#include "map_aided_fusion/core/mass_grid.hpp"

namespace map_aided_fusion {

/// Thrown when a message cannot be turned into a core grid; the message says why.
class ConversionError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

/// Which planes toMessage() writes.
enum class PlaneSelection
{
  kNonZero,  ///< only the focal sets with mass somewhere (compact; the others are zero by definition)
  kAll       ///< every subset the grid stores (all of a ScanGrid's, ∅ included; the MapGrid's 29, PlaneLayout)
};

/// Static converters; every function is pure and thread-safe.
class GridConversions
{
public:
  /// GridGeometry → MapMetaData (origin without rotation, z = 0).
  static void toMapMetaData(const core::GridGeometry& g, nav_msgs::MapMetaData& info);
  /// MapMetaData → GridGeometry. @throws ConversionError for a rotated origin or a bad size/resolution.
  static core::GridGeometry fromMapMetaData(const nav_msgs::MapMetaData& info);

  /// A core grid → EvidentialGrid (classes, focal sets, masses and, when @p with_counter, ζ).
  template <class Frame>
  static void toMessage(const core::MassGrid<Frame>& grid, const std_msgs::Header& header, EvidentialGrid& msg,
                        PlaneSelection planes = PlaneSelection::kNonZero, bool with_counter = false);

  /**
   * @brief EvidentialGrid → core grid. Layers not in the message are zero; the counter is read when present.
   * @throws ConversionError when the classes are not those of @p Frame, a focal set is out of range or
   *         repeated, mass is on a subset @p grid does not store (PlaneLayout), or the array sizes do not match
   *         info.width × info.height.
   */
  template <class Frame>
  static void fromMessage(const EvidentialGrid& msg, core::MassGrid<Frame>& grid);

  /// |Σm − 1| a ScanGrid cell's masses must stay below (float sums of four masses).
  static constexpr float kScanMassTolerance = 1e-3f;
  /// Cells copied, then checked, at a time by scanFromMessage() (its planes' chunks stay in cache for the check).
  static constexpr std::size_t kScanCheckChunk = 16384;

  /**
   * @brief A ScanGrid's EvidentialGrid → ScanMassGrid, as fromMessage(), each cell checked to be a mass function
   *        (every mass ≥ 0, |Σm − 1| < kScanMassTolerance) right after it is copied.
   * @throws ConversionError as fromMessage(), or naming the first cell that is not a mass function (@p grid then
   *         holds the copy so far).
   */
  static void scanFromMessage(const EvidentialGrid& msg, core::ScanMassGrid& grid);

  /**
   * @brief EvidentialGrid of a PriorGrid (focal sets among B, R, T, W = {F, C}, Ω and ∅) → PriorWindow.
   * @throws ConversionError when another focal set carries mass, or as fromMessage().
   */
  static void fromMessage(const EvidentialGrid& msg, core::PriorWindow& prior);

  /// A PriorWindow → EvidentialGrid with the focal sets B, R, T and Ω, and W when some cell has mass on it.
  static void toMessage(const core::PriorWindow& prior, const std_msgs::Header& header, EvidentialGrid& msg);

  /**
   * @brief One class's BetP as an OccupancyGrid: round(100·BetP(element)), and −1 (unknown) where the
   *        cell is vacuous (m(Ω) ≥ 1 − @p vacuous_tolerance).
   */
  static void pignisticToOccupancy(const core::MapMassGrid& grid, const core::PignisticPlanes& betp, int element,
                                   const std_msgs::Header& header, nav_msgs::OccupancyGrid& out,
                                   float vacuous_tolerance = 1e-3f);

  /// m(O) of a ScanGrid as an OccupancyGrid for rviz: round(100·BetP(O)), −1 where vacuous.
  static void scanToOccupancy(const core::ScanMassGrid& grid, const std_msgs::Header& header,
                              nav_msgs::OccupancyGrid& out, float vacuous_tolerance = 1e-3f);
};

}  // namespace map_aided_fusion

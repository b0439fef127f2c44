/**
 * @file open_ends.hpp
 * @brief Step open ends: which faces of a cluster's box the scan shows open (free space beyond) or occluded (a
 *        nearer obstacle on the line of sight), the evidence the measurement model's anchor point reads.
 */
#pragma once

#include "map_aided_fusion/core/grid_geometry.hpp"
#include "map_aided_fusion/core/mass_grid.hpp"
#include "map_aided_fusion/core/seen_free.hpp"
#include "map_aided_fusion/core/tracking/measurement_model.hpp"

namespace map_aided_fusion {
namespace core {

/**
 * @brief Step open ends: the open and occluded faces of @p m's box, from one scan. A face is open when the point
 *        @p distance beyond its middle is clear in @p free, occluded when the line of sight from the vehicle at
 *        @p pose to that point is blocked in @p scan (hiddenFromSensor()) at least 1 m before it. Sets ends_seen.
 */
void findOpenEnds(Measurement& m, const SeenFree& free, const ScanMassGrid& scan, const Pose2& pose, double distance);

/// True when the line of sight from the vehicle (the ScanGrid's origin, at @p pose) to the map-frame point @p p crosses
/// a ScanGrid cell with m(O) ≥ 0.5 at least @p gap metres before @p p.
bool hiddenFromSensor(const ScanMassGrid& scan, const Pose2& pose, Point2 p, double gap);

}  // namespace core
}  // namespace map_aided_fusion

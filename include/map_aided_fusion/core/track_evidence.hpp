/**
 * @file track_evidence.hpp
 * @brief Step "track evidence" (not in the paper): what the tracked objects say of the MapGrid's cells. A
 *        confidently moving track supports {V} in the cells holding its returns of the last scan, a confidently
 *        stopped one {S}, with weight β = tracker_evidence_weight · P(motion); a track whose motion is not yet known
 *        makes its cells neither S nor V (MapGrid::applyTrackedMotion()).
 *
 * P(moving) = Φ((speed − tracker_moving_speed) / σ(speed)), P(stopped) = Φ((tracker_stopped_speed − speed) /
 * σ(speed)), Φ the standard normal distribution function: how sure the track's velocity makes the motion (the speed
 * relative to the scan's common motion, step common motion).
 */
#pragma once

#include <vector>

#include "map_aided_fusion/core/map_grid.hpp"
#include "map_aided_fusion/core/tracker.hpp"

namespace map_aided_fusion {
namespace core {

/// The probability, from the track's speed relative to @p common_motion (step common motion: the common motion at the
/// track, Tracker::commonMotionAt()) and its σ, that it moves faster than moving_speed (moving) or slower than
/// stopped_speed (stopped); 0 for a track whose motion is not decided.
double motionProbability(const Track& track, const TrackerParams& params, Point2 common_motion = Point2{ 0.0, 0.0 });

/// objectBox() of the track @p t of @p tracker, with its last scan's measurements.
ObjectBox reportedBox(const Track& t, const Tracker& tracker);

/// reportedBox() of every track of @p tracker, in the order of Tracker::tracks().
std::vector<ObjectBox> reportedBoxes(const Tracker& tracker);

/**
 * @brief The cells of @p geometry holding the returns of the last scan of every reported track associated in that
 *        scan (its measurement's and, with step duplicates, its fragments', Track::fragments), with the track's
 *        motion and β; with step track box also the cells whose centre lies in its measurement's box (interior
 *        cells): a moving vehicle's box extended by step hidden length and grown across by kBoxMargin on
 *        each side (step box margin), a small mover's by step small box. Empty when step track evidence is off or the
 *        tracker was given measurements without returns.
 */
std::vector<CellMotion> trackEvidence(const Tracker& tracker, const GridGeometry& geometry);

/**
 * @brief Step "box hidden": marks hidden (CellMotion::hidden) the interior cells of moving tracks in @p cells (cells of
 *        @p geometry) that the scan's ScanGrid @p scan (vehicle frame, vehicle pose @p pose in the map frame) did not
 *        see free (m(F) = 0 at the cell's centre, or outside the ScanGrid).
 */
void markHidden(std::vector<CellMotion>& cells, const GridGeometry& geometry, const ScanMassGrid& scan,
                const Pose2& pose);

/// BetP(C) of the prior mass function of cell @p i of @p prior: m(B) + m(W)/2 + m(Ω)/5.
float priorBetPBuilding(const PriorWindow& prior, std::size_t i);

/**
 * @brief One scan of tracking after @p grid's update(): flags the returns on static background (backgroundFlags():
 *        the grid's counter ζ above background_zeta or, with step building background, its BetP(C) above
 *        kBuildingBackgroundBetP; beyond the grid's window, where it has neither, @p prior's own BetP(C),
 *        priorBetPBuilding(), when given), updates @p tracker with the scan's ScanGrid @p scan (vehicle frame; the
 *        free space of step free-space check, nullptr: none), and applies its evidence to @p grid
 *        (MapGrid::applyTrackedMotion()). @p background is the caller's buffer, kept from scan to scan; @p prior is
 *        the prior the grid's update() fused (nullptr: none). Without a prior, with step movers without a map, the
 *        cells of a moving track's returns and a small mover's box cells also take N and C (CellMotion::take_n,
 *        take_c). Until @p grid has fused backgroundWarmupScans() scans since its reset the tracker is told that
 *        background is not yet known (Tracker::setBackgroundKnown()): the tracks born then are published only once
 *        moving or associated after it (Track::published()).
 */
void trackScan(Tracker& tracker, MapGrid& grid, double stamp, const Pose2& pose, const ObstaclePoints& returns,
               std::vector<std::uint8_t>& background, const ScanMassGrid* scan = nullptr,
               const PriorWindow* prior = nullptr);

}  // namespace core
}  // namespace map_aided_fusion

#include "map_aided_fusion/core/track_evidence.hpp"

#include <algorithm>
#include <cmath>

namespace map_aided_fusion {
namespace core {

namespace {

constexpr double kMinSigma = 1e-6;  // m/s

double normalCdf(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

}  // namespace

double motionProbability(const Track& t, const TrackerParams& p)
{
  const double sigma = std::max(t.speedSigma(), kMinSigma);
  switch (t.motion)
  {
    case TrackMotion::kMoving: return normalCdf((t.speed() - p.moving_speed) / sigma);
    case TrackMotion::kStopped: return normalCdf((p.stopped_speed - t.speed()) / sigma);
    case TrackMotion::kUnknown: break;
  }
  return 0.0;
}

std::vector<CellMotion> trackEvidence(const Tracker& tracker, const GridGeometry& g)
{
  std::vector<CellMotion> out;
  const TrackerParams& p = tracker.params();
  if (!(p.evidence_weight > 0.0)) return out;
  const std::vector<Point2>& points = tracker.points();
  const std::vector<Measurement>& measurements = tracker.measurements();
  for (const Track& t : tracker.tracks())
  {
    if (!t.reported() || t.measurement < 0 || t.measurement >= static_cast<int>(measurements.size())) continue;
    CellMotion c;
    c.motion = t.motion == TrackMotion::kMoving    ? CellClass::kMoving
               : t.motion == TrackMotion::kStopped ? CellClass::kStopped
                                                   : CellClass::kOccupied;
    c.weight = static_cast<float>(p.evidence_weight * motionProbability(t, p));
    const std::size_t first = out.size();
    for (const int i : measurements[t.measurement].returns)
    {
      if (i < 0 || i >= static_cast<int>(points.size())) continue;
      CellIndex ci;
      if (!g.worldToCell(points[i], ci)) continue;
      c.cell = g.index(ci);
      out.push_back(c);
    }
    // One entry per cell and track.
    std::sort(out.begin() + static_cast<std::ptrdiff_t>(first), out.end(),
              [](const CellMotion& a, const CellMotion& b) { return a.cell < b.cell; });
    out.erase(std::unique(out.begin() + static_cast<std::ptrdiff_t>(first), out.end(),
                          [](const CellMotion& a, const CellMotion& b) { return a.cell == b.cell; }),
              out.end());
  }
  return out;
}

void trackScan(Tracker& tracker, MapGrid& grid, double stamp, const Pose2& pose, const ObstaclePoints& returns,
               std::vector<std::uint8_t>& background)
{
  const GridGeometry& g = grid.geometry();
  const MapMassGrid& masses = grid.masses();
  backgroundFlags(pose, returns, tracker.params().background_zeta,
                  [&](Point2 p) {
                    CellIndex c;
                    return g.worldToCell(p, c) ? masses.zeta(g.index(c)) : -1.0f;
                  },
                  background);
  tracker.update(stamp, pose, returns, &background);
  grid.applyTrackedMotion(trackEvidence(tracker, g));
}

}  // namespace core
}  // namespace map_aided_fusion

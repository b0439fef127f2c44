#include "map_aided_fusion/core/track_evidence.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

namespace map_aided_fusion {
namespace core {

namespace {

constexpr double kMinSigma = 1e-6;  // m/s
constexpr int kBetPBuilding = 1;     // the BetP plane of C (FrameMG::kC is bit 1)
static_assert(FrameMG::kC == 1u << kBetPBuilding, "BetP planes are in bit order");

double normalCdf(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

/// Appends to @p out, as interior cells like @p c, the cells of @p g whose centre lies in the box of @p m and that are
/// not among out[first, end) (sorted).
void addBoxInterior(const Measurement& m, const GridGeometry& g, CellMotion c, std::size_t first,
                    std::vector<CellMotion>& out)
{
  const double cu = std::cos(m.yaw), su = std::sin(m.yaw);
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
  for (double u : { m.lo_u, m.hi_u })
    for (double v : { m.lo_v, m.hi_v })
    {
      const double x = m.centroid.x + u * cu - v * su, y = m.centroid.y + u * su + v * cu;
      x0 = std::min(x0, x);
      y0 = std::min(y0, y);
      x1 = std::max(x1, x);
      y1 = std::max(y1, y);
    }
  if (!std::isfinite(x0) || !std::isfinite(y0) || !std::isfinite(x1) || !std::isfinite(y1)) return;
  const CellIndex a = g.cellAt(Point2{ x0, y0 }), b = g.cellAt(Point2{ x1, y1 });
  const std::size_t end = out.size();
  c.interior = true;
  for (int cy = std::max(0, a.y); cy <= std::min(g.height - 1, b.y); ++cy)
    for (int cx = std::max(0, a.x); cx <= std::min(g.width - 1, b.x); ++cx)
    {
      const Point2 q = g.cellCentre(CellIndex{ cx, cy });
      const double dx = q.x - m.centroid.x, dy = q.y - m.centroid.y;
      const double u = dx * cu + dy * su, v = -dx * su + dy * cu;
      if (u < m.lo_u || u > m.hi_u || v < m.lo_v || v > m.hi_v) continue;
      c.cell = g.index(CellIndex{ cx, cy });
      const auto from = out.begin() + static_cast<std::ptrdiff_t>(first), to = out.begin() + static_cast<std::ptrdiff_t>(end);
      if (std::binary_search(from, to, c, [](const CellMotion& l, const CellMotion& r) { return l.cell < r.cell; }))
        continue;
      out.push_back(c);
    }
}

/// Step "small box": @p m's box in the axes of the line of sight, grown to @p size along it (away from the sensor:
/// the rays end on the near side) and across it (on both sides); nothing when it already is that large.
std::optional<Measurement> smallMoverBox(const Measurement& m, double size)
{
  if (!m.has_sensor || !(size > 0.0)) return std::nullopt;
  const double dx = m.centroid.x - m.sensor.x, dy = m.centroid.y - m.sensor.y, r = std::hypot(dx, dy);
  if (!(r > 0.0)) return std::nullopt;
  const Eigen::Vector2d along(dx / r, dy / r), across(-along.y(), along.x());
  const AxisView u = viewAlong(m, along), v = viewAlong(m, across);
  if (u.hi - u.lo >= size && v.hi - v.lo >= size) return std::nullopt;
  Measurement e = m;
  e.yaw = std::atan2(along.y(), along.x());
  e.lo_u = u.lo;
  e.hi_u = std::max(u.hi, u.lo + size);
  const double grow = std::max(0.0, 0.5 * (size - (v.hi - v.lo)));
  e.lo_v = v.lo - grow;
  e.hi_v = v.hi + grow;
  return e;
}

double heading(const Track& t) { return std::atan2(t.x(3), t.x(2)); }

/// Step "box margin": @p m's box grown by @p margin on each side across its axis.
Measurement widened(Measurement m, double margin)
{
  m.lo_v -= margin;
  m.hi_v += margin;
  return m;
}

}  // namespace

ObjectBox reportedBox(const Track& t, const Tracker& tracker)
{
  return objectBox(t, tracker.params(), tracker.measurements());
}

std::vector<ObjectBox> reportedBoxes(const Tracker& tracker)
{
  std::vector<ObjectBox> out;
  out.reserve(tracker.tracks().size());
  for (const Track& t : tracker.tracks()) out.push_back(reportedBox(t, tracker));
  return out;
}

double motionProbability(const Track& t, const TrackerParams& p, Point2 common_motion)
{
  const double sigma = std::max(t.speedSigma(), kMinSigma), speed = t.speedRelativeTo(common_motion);
  switch (t.motion)
  {
    case TrackMotion::kMoving: return normalCdf((speed - p.moving_speed) / sigma);
    case TrackMotion::kStopped: return normalCdf((p.stopped_speed - speed) / sigma);
    case TrackMotion::kUnknown: break;
  }
  return 0.0;
}

void markHidden(std::vector<CellMotion>& cells, const GridGeometry& g, const ScanMassGrid& scan, const Pose2& pose)
{
  const GridGeometry& sg = scan.geometry();
  const float* const f = scan.plane(FrameSG::kF);
  const double c = std::cos(pose.yaw), s = std::sin(pose.yaw);
  for (CellMotion& m : cells)
  {
    if (!m.interior || m.motion != CellClass::kMoving || m.cell >= g.numCells()) continue;
    const Point2 q = g.cellCentre(g.cellOf(m.cell));
    const double dx = q.x - pose.x, dy = q.y - pose.y;
    CellIndex ci;
    m.hidden = !sg.worldToCell(Point2{ c * dx + s * dy, -s * dx + c * dy }, ci) || !(f[sg.index(ci)] > 0.0f);
  }
}

std::vector<CellMotion> trackEvidence(const Tracker& tracker, const GridGeometry& g)
{
  std::vector<CellMotion> out;
  const TrackerParams& p = tracker.params();
  if (!p.steps.track_evidence || !(p.evidence_weight > 0.0)) return out;
  const std::vector<Point2>& points = tracker.points();
  const std::vector<Measurement>& measurements = tracker.measurements();
  for (const Track& t : tracker.tracks())
  {
    if (!t.reported() || t.measurement < 0 || t.measurement >= static_cast<int>(measurements.size())) continue;
    CellMotion c;
    c.motion = t.motion == TrackMotion::kMoving    ? CellClass::kMoving
               : t.motion == TrackMotion::kStopped ? CellClass::kStopped
                                                   : CellClass::kOccupied;
    c.weight = static_cast<float>(p.evidence_weight * motionProbability(t, p, tracker.commonMotionAt(t.position())));
    c.take_n = c.motion == CellClass::kMoving && p.steps.small_movers && t.extent_length <= p.pedestrian_size &&
               t.extent_width <= p.pedestrian_size;
    c.take_specialised = c.take_n && p.steps.small_specialised;
    const std::size_t first = out.size();
    auto addReturns = [&](int measurement) {
      if (measurement < 0 || measurement >= static_cast<int>(measurements.size())) return;
      for (const int i : measurements[measurement].returns)
      {
        if (i < 0 || i >= static_cast<int>(points.size())) continue;
        CellIndex ci;
        if (!g.worldToCell(points[i], ci)) continue;
        c.cell = g.index(ci);
        out.push_back(c);
      }
    };
    addReturns(t.measurement);
    for (const int f : t.fragments) addReturns(f);
    // One entry per cell and track.
    std::sort(out.begin() + static_cast<std::ptrdiff_t>(first), out.end(),
              [](const CellMotion& a, const CellMotion& b) { return a.cell < b.cell; });
    out.erase(std::unique(out.begin() + static_cast<std::ptrdiff_t>(first), out.end(),
                          [](const CellMotion& a, const CellMotion& b) { return a.cell == b.cell; }),
              out.end());
    if (p.steps.track_box && c.motion != CellClass::kOccupied)
    {
      const Measurement& m = measurements[t.measurement];
      if (c.take_n && p.steps.small_box)
        addBoxInterior(smallMoverBox(m, p.pedestrian_size).value_or(m), g, c, first, out);
      else if (c.motion == CellClass::kMoving && t.speed() > 0.0)
        addBoxInterior(widened(hiddenLengthBox(m, heading(t), p.steps.hidden_length ? p.vehicle_length : 0.0,
                                               kVehicleMinEndWidth)
                                   .value_or(m),
                               p.steps.box_margin ? kBoxMargin : 0.0),
                       g, c, first, out);
      else
        addBoxInterior(m, g, c, first, out);
    }
  }
  return out;
}

float priorBetPBuilding(const PriorWindow& prior, std::size_t i)
{
  const float b = prior.building[i], w = prior.wall.empty() ? 0.0f : prior.wall[i];
  const float omega = std::max(0.0f, 1.0f - b - prior.road[i] - prior.other[i] - w);
  return b + 0.5f * w + omega / static_cast<float>(FrameMG::kSize);
}

void trackScan(Tracker& tracker, MapGrid& grid, double stamp, const Pose2& pose, const ObstaclePoints& returns,
               std::vector<std::uint8_t>& background, const ScanMassGrid* scan, const PriorWindow* prior)
{
  const GridGeometry& g = grid.geometry();
  const MapMassGrid& masses = grid.masses();
  const TrackerParams& p = tracker.params();
  const AlignedVector<float>& betp_c = grid.pignistic()[kBetPBuilding];
  const bool building = p.steps.building_background && betp_c.size() == g.numCells();
  backgroundFlags(pose, returns,
                  [&](Point2 q) {
                    CellIndex c;
                    if (!g.worldToCell(q, c))
                    {
                      // Beyond the window: no counter, and the prior's own BetP(C) for the fused one.
                      if (!p.steps.building_background || !prior || !prior->geometry.worldToCell(q, c)) return false;
                      return priorBetPBuilding(*prior, prior->geometry.index(c)) > kBuildingBackgroundBetP;
                    }
                    const std::size_t i = g.index(c);
                    return masses.zeta(i) > p.background_zeta || (building && betp_c[i] > kBuildingBackgroundBetP);
                  },
                  background);
  // After a start or a reset ζ is 0 everywhere: a facade is no background until the counter has had its scans.
  tracker.setBackgroundKnown(grid.scans() >=
                             backgroundWarmupScans(p.background_zeta, grid.params().fusion.counter.delta_inc));
  tracker.update(stamp, pose, returns, &background, scan);
  std::vector<CellMotion> cells = trackEvidence(tracker, g);
  if (!prior && p.steps.movers_without_map)
    for (CellMotion& c : cells)
      if (c.motion == CellClass::kMoving && (c.take_n || !c.interior)) c.take_n = c.take_c = true;
  if (scan && tracker.params().steps.box_hidden) markHidden(cells, g, *scan, pose);
  grid.applyTrackedMotion(cells);
}

}  // namespace core
}  // namespace map_aided_fusion

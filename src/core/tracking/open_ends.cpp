#include "map_aided_fusion/core/tracking/open_ends.hpp"

#include <cmath>

#include <Eigen/Core>

namespace map_aided_fusion {
namespace core {

namespace {

constexpr float kOccluderMass = 0.5f;  // m(O) of a ScanGrid cell that blocks the view (step open ends)
constexpr double kOccluderGap = 1.0;   // m: an occluder lies at least this much nearer the sensor than an end it cuts

}  // namespace

bool hiddenFromSensor(const ScanMassGrid& scan, const Pose2& pose, Point2 p, double gap)
{
  const GridGeometry& g = scan.geometry();
  const double c = std::cos(pose.yaw), s = std::sin(pose.yaw), dx = p.x - pose.x, dy = p.y - pose.y;
  const double vx = c * dx + s * dy, vy = -s * dx + c * dy, range = std::hypot(vx, vy), reach = range - gap;
  if (!(reach > 0.0)) return false;
  const float* occupied = scan.plane(FrameSG::kO);
  const double step = 0.5 * g.resolution;
  for (double r = step; r <= reach; r += step)
  {
    CellIndex cell;
    if (!g.worldToCell(Point2{ vx * r / range, vy * r / range }, cell)) return false;
    if (occupied[g.index(cell)] >= kOccluderMass) return true;
  }
  return false;
}

void findOpenEnds(Measurement& m, const SeenFree& free, const ScanMassGrid& scan, const Pose2& pose, double distance)
{
  const Eigen::Vector2d c(m.centroid.x, m.centroid.y), mu(std::cos(m.yaw), std::sin(m.yaw)), mv(-mu.y(), mu.x());
  const double mid_u = 0.5 * (m.lo_u + m.hi_u), mid_v = 0.5 * (m.lo_v + m.hi_v);
  m.open = m.occluded = 0;
  auto probe = [&](double u, double v, std::uint8_t bit) {
    const Eigen::Vector2d q = c + u * mu + v * mv;
    const Point2 p{ q.x(), q.y() };
    if (free.clear(p)) m.open |= bit;
    if (hiddenFromSensor(scan, pose, p, distance + kOccluderGap)) m.occluded |= bit;
  };
  probe(m.lo_u - distance, mid_v, Measurement::kLowU);
  probe(m.hi_u + distance, mid_v, Measurement::kHighU);
  probe(mid_u, m.lo_v - distance, Measurement::kLowV);
  probe(mid_u, m.hi_v + distance, Measurement::kHighV);
  m.ends_seen = true;
}

}  // namespace core
}  // namespace map_aided_fusion

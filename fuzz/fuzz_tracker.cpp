// libFuzzer target: bytes -> scans for the tracker, either measurements given whole (centroid, covariance, box,
// sensor) or returns (vehicle frame) with a vehicle pose and a small ScanGrid -> Tracker::update(). Small bounds
// (max_measurements, max_tracks) so that the input reaches them. Checks, after every scan, the bounds, unique ids and
// finite states. Built and run by scripts/fuzz.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <set>
#include <vector>

#include "fuzz_input.hpp"
#include "map_aided_fusion/core/tracker.hpp"

namespace {

using maf_fuzz::take;

/// A value from the input: small and on a grid of @p scale most of the time, any float (NaN, ±inf, huge) otherwise.
double value(const std::uint8_t*& p, std::size_t& n, double scale)
{
  const std::uint8_t kind = take<std::uint8_t>(p, n);
  if (kind % 8 != 0) return scale * static_cast<double>(take<std::int8_t>(p, n));
  return static_cast<double>(take<float>(p, n));
}

map_aided_fusion::core::Measurement measurement(const std::uint8_t*& p, std::size_t& n)
{
  using namespace map_aided_fusion::core;
  Measurement m;
  m.centroid = Point2{ value(p, n, 0.5), value(p, n, 0.5) };
  const double sx = value(p, n, 0.05), sy = value(p, n, 0.05), sxy = value(p, n, 0.01);
  m.covariance << sx * sx, sxy, sxy, sy * sy;
  m.yaw = value(p, n, 0.1);
  m.lo_u = -std::abs(value(p, n, 0.25));
  m.hi_u = std::abs(value(p, n, 0.25));
  m.lo_v = -std::abs(value(p, n, 0.1));
  m.hi_v = std::abs(value(p, n, 0.1));
  m.length = m.hi_u - m.lo_u;
  m.width = m.hi_v - m.lo_v;
  m.points = take<std::uint8_t>(p, n);
  const std::uint8_t flags = take<std::uint8_t>(p, n);
  m.has_sensor = flags & 1;
  m.split = flags & 2;
  m.ends_seen = flags & 4;
  m.open = take<std::uint8_t>(p, n) & 15;
  m.occluded = take<std::uint8_t>(p, n) & 15;
  m.sensor = Point2{ value(p, n, 1.0), value(p, n, 1.0) };
  return m;
}

void check(const map_aided_fusion::core::Tracker& tracker)
{
  const auto& params = tracker.params();
  if (tracker.tracks().size() > static_cast<std::size_t>(params.max_tracks)) std::abort();
  if (tracker.measurements().size() > static_cast<std::size_t>(params.max_measurements)) std::abort();
  std::set<std::uint32_t> ids;
  for (const auto& t : tracker.tracks())
  {
    if (!ids.insert(t.id).second || !t.x.allFinite() || !t.P.allFinite()) std::abort();
    if (t.measurement >= static_cast<int>(tracker.measurements().size())) std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  using namespace map_aided_fusion::core;
  TrackerParams params;
  params.max_measurements = 12;
  params.max_tracks = 16;
  params.min_cluster_points = 2;
  Tracker tracker(params);
  static ScanMassGrid scan = [] {
    ScanMassGrid g(GridGeometry::centred(30.0, 30.0, 0.5));
    for (std::size_t c = 0; c < g.geometry().numCells(); ++c)
      g.setCell(c, MassSG{ { FrameSG::kF, 0.6 }, { FrameSG::kOmega, 0.4 } });
    return g;
  }();
  const std::uint8_t* p = data;
  std::size_t n = size;
  double stamp = 0.0;
  std::vector<Measurement> measurements;
  std::vector<float> xy;
  std::vector<std::uint8_t> background;
  while (n > 0)
  {
    const std::uint8_t op = take<std::uint8_t>(p, n);
    stamp += value(p, n, 0.05);
    const int count = take<std::uint8_t>(p, n) % 40;
    if (op & 1)
    {
      measurements.clear();
      for (int i = 0; i < count && n > 0; ++i) measurements.push_back(measurement(p, n));
      tracker.update(stamp, measurements);
    }
    else
    {
      const Pose2 pose{ value(p, n, 0.5), value(p, n, 0.5), value(p, n, 0.05) };
      xy.clear();
      background.clear();
      for (int i = 0; i < 4 * count && n > 0; ++i)
      {
        xy.push_back(static_cast<float>(value(p, n, 0.1)));
        xy.push_back(static_cast<float>(value(p, n, 0.1)));
        background.push_back(take<std::uint8_t>(p, n) & 1);
      }
      const ObstaclePoints returns{ xy.data(), xy.size() / 2 };
      tracker.update(stamp, pose, returns, (op & 2) ? &background : nullptr, (op & 4) ? &scan : nullptr);
    }
    check(tracker);
  }
  return 0;
}

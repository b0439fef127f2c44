// libFuzzer target: bytes -> a stream of fused scans and `scan_grid/started` headers (frame, stamp, vehicle
// position, the caller's clock check) -> core::checkStarted() and, for each header honoured, MapGrid::follow() as
// the fusion does (shift_ahead). Checks that an honoured header is one of a scan that will be fused: the fused
// scans' frame, newer than the last fused scan and the last header honoured, reachable at max_plausible_speed.
// Built and run by scripts/fuzz.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>

#include "fuzz_input.hpp"
#include "map_aided_fusion/core/map_grid.hpp"
#include "map_aided_fusion/core/stamp_guard.hpp"

namespace {

using maf_fuzz::take;

/// A coordinate or stamp from the input: a small step most of the time, any double (NaN, ±inf, huge) otherwise.
double value(const std::uint8_t*& p, std::size_t& n, double scale)
{
  const std::uint8_t kind = take<std::uint8_t>(p, n);
  if (kind % 4 != 0) return scale * static_cast<double>(take<std::int8_t>(p, n));
  return take<double>(p, n);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  using namespace map_aided_fusion::core;
  static const char* const kFrames[] = { "base_link", "map", "odom", "" };
  TimeGuardParams params;
  params.max_plausible_speed = 30.0;
  MapGridParams grid_params;
  grid_params.size_x = grid_params.size_y = 20.0;
  grid_params.resolution = 1.0;
  MapGrid grid(grid_params);
  const std::uint8_t* p = data;
  std::size_t n = size;
  StartedReference ref;
  double stamp = 100.0, x = 0.0, y = 0.0;
  while (n > 0)
  {
    const std::uint8_t op = take<std::uint8_t>(p, n);
    const std::string frame = kFrames[(op >> 1) % 4];
    stamp += value(p, n, 0.01);
    x += value(p, n, 0.5);
    y += value(p, n, 0.5);
    if (op & 1)
    {
      // A scan fused at (x, y): the fusion's reference from now on.
      ref.frame = frame;
      ref.fused_stamp = stamp;
      ref.fused_x = x;
      ref.fused_y = y;
      ref.shifted_stamp.reset();
      continue;
    }
    const bool stamp_ok = (op >> 3) & 1;
    const StartedVerdict v = checkStarted(ref, frame, stamp, stamp_ok, x, y, params);
    if (v != StartedVerdict::kShift) continue;
    const bool newer = stamp > ref.fused_stamp && (!ref.shifted_stamp || stamp > *ref.shifted_stamp);
    const double reach = params.max_plausible_speed * (stamp - ref.fused_stamp);
    if (ref.frame.empty() || frame != ref.frame || !stamp_ok || !newer || !std::isfinite(x) || !std::isfinite(y) ||
        !(std::hypot(x - ref.fused_x, y - ref.fused_y) <= reach))
      std::abort();  // a header that describes no scan to fuse was honoured
    ref.shifted_stamp = stamp;
    grid.follow(Point2{ x, y });
  }
  return 0;
}

/**
 * @file stamp_guard.hpp
 * @brief Time hygiene of a stream of scans, ROS-free: which scan may be fused, which is dropped, and when
 *        time really jumped back (a looping bag, a restarted `/clock`) so that the MapGrid must start again.
 *
 * Accumulated evidence is only thrown away on a genuine time jump, when the stamps and the clock both went
 * back: an out-of-order scan (a second lidar on the same topic, a large cloud that arrives late, scans a tf
 * message filter releases newest first, even seconds late) is dropped and counted; a scan stamped 0 or twice
 * with the same stamp is dropped and counted.
 */
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "map_aided_fusion/core/parameters.hpp"

namespace map_aided_fusion {
namespace core {

/**
 * Wall seconds after a backward clock jump during which data and transforms stamped ahead of the clock by more than
 * time_jump_threshold are taken for data of before the jump (in flight when the bag looped) and dropped. Outside
 * it, data ahead of a lagging clock wait for their transform and are fused, up to future_tolerance.
 */
constexpr double kAfterJumpWatch = 5.0;

/// Parameters of StampGuard, ClockJumpDetector and PoseJumpCheck (config/fusion.yaml).
struct TimeGuardParams
{
  /**
   * A scan older than the last fused one by more than this (s) is a time jump: the grid is reset and the
   * scan fused. Older by less (or equal): out of order, dropped. In [0.001, 3600].
   */
  double time_jump_threshold = 1.0;
  /// Vehicle speeds above this between two fused scans (m/s) are reported as a pose jump. In (0, 1000].
  double max_plausible_speed = 70.0;
  /// @throws ParameterError naming the first parameter out of range.
  void validate() const;
};

/// Calls get(name, field) for every parameter of @p p, with the names of config/fusion.yaml.
template <class Get>
void forEachParam(TimeGuardParams& p, Get&& get)
{
  get("time_jump_threshold", p.time_jump_threshold, { "s", "a scan older than the last fused by more than this is a time jump (reset); less: dropped" });
  get("max_plausible_speed", p.max_plausible_speed, { "m/s", "faster vehicle motion between two fused scans is reported as a pose jump" });
}

/// What to do with a scan.
enum class StampVerdict
{
  kFuse,        ///< newer than the last fused scan (or the first one)
  kZeroStamp,   ///< stamped 0 (or negative, or not finite): no pose can be looked up for it
  kDuplicate,   ///< the same stamp as the last fused scan
  kOutOfOrder,  ///< older than the last fused scan by at most time_jump_threshold
  kTimeJump,    ///< older by more than time_jump_threshold, no clock to tell otherwise: reset, then fuse
  kLate,        ///< older by more than time_jump_threshold while a watched clock did not go back (released late)
};

/// A short name for logs and diagnostics ("fuse", "zero stamp", "duplicate stamp", "out of order", "time jump",
/// "released late").
const char* toString(StampVerdict v);

/**
 * @brief Classifies scan stamps against the last fused one.
 *
 * check() does not change the state; the caller calls accept() once the scan is fused, and reset() when
 * the grid is reset for any other reason (a /clock jump).
 */
class StampGuard
{
public:
  explicit StampGuard(const TimeGuardParams& params = TimeGuardParams{}) : params_(params) {}

  /**
   * @brief The verdict for a scan stamped @p stamp (seconds).
   * @param clock_watched true when a ClockJumpDetector watches the clock the stamps come with (ROS time, `/clock`
   *        under simulated time) and resets this guard on a backward jump. A scan older than the last fused one by
   *        more than time_jump_threshold is then not a jump (the clock did not go back, or the guard would have
   *        been reset): it was held back, as by a tf message filter releasing its queue after a transform gap,
   *        newest first, and is kLate. A clock merely lagging behind the data is not a jump either. Without a
   *        watched clock (offline replays), stamps alone decide: kTimeJump.
   */
  StampVerdict check(double stamp, bool clock_watched = false) const;
  /// Records @p stamp as the last fused scan.
  void accept(double stamp)
  {
    last_ = stamp;
    late_since_.reset();
  }
  /// Forgets the last fused stamp: the next scan is fused whatever its stamp (but 0).
  void reset()
  {
    last_.reset();
    late_since_.reset();
  }
  /**
   * @brief Records a kLate verdict at @p wall (seconds, a monotonic clock); true when late scans have kept coming,
   *        none fused, for more than time_jump_threshold: the source's own time went back (a bag looping on wall
   *        time, a sensor clock reset), not a queue released after a tf gap (which is over in milliseconds).
   */
  bool lateRun(double wall)
  {
    if (!late_since_) late_since_ = wall;
    return wall - *late_since_ > params_.time_jump_threshold;
  }
  const std::optional<double>& last() const { return last_; }

private:
  TimeGuardParams params_;
  std::optional<double> last_;
  std::optional<double> late_since_;  ///< wall time of the first kLate since the last fused scan
};

/**
 * @brief Watches a clock (ROS time, i.e. `/clock` under simulated time) for backward jumps.
 *
 * observe() is called with the clock's value now and then (a wall timer, every scan); it returns true once
 * per jump, when the clock is more than the threshold behind the latest value it saw.
 */
class ClockJumpDetector
{
public:
  explicit ClockJumpDetector(double threshold = TimeGuardParams{}.time_jump_threshold) : threshold_(threshold) {}
  void setThreshold(double threshold) { threshold_ = threshold; }
  /// True when @p now (seconds) is more than the threshold behind the latest value observed.
  bool observe(double now);
  std::size_t jumps() const { return jumps_; }

private:
  double threshold_;
  std::optional<double> latest_;
  std::size_t jumps_ = 0;
};

/// Implied speed between two fused poses, for a warning when localisation jumps.
struct PoseJump
{
  bool jumped = false;   ///< speed above TimeGuardParams::max_plausible_speed
  double distance = 0.0; ///< metres between the two poses
  double speed = 0.0;    ///< metres per second (infinite when dt ≤ 0)
};

/// Distance and speed between (x0, y0) at t0 and (x1, y1) at t1, judged against @p max_speed.
PoseJump checkPoseJump(double x0, double y0, double t0, double x1, double y1, double t1, double max_speed);


/// What the fusion does with a `scan_grid/started` header (FusionNodeParams::shift_ahead), checkStarted().
enum class StartedVerdict : std::uint8_t
{
  kShift,        ///< it announces a scan the fusion will fuse: move the window now
  kNoScanYet,    ///< no scan fused yet, so no frame to compare: nothing to move (not counted as a refusal)
  kOtherFrame,   ///< not the frame of the fused scans (a fixed frame, `map` or `odom`, moves the window to its origin)
  kBadStamp,     ///< stamped 0, not finite, or further ahead of the clock than the scans may be
  kNotNewer,     ///< not newer than the last fused scan and the last header honoured: a scan the fusion would drop
  kImplausible,  ///< its pose lies further from the last fused one than max_plausible_speed allows in the time between
  kNoTransform,  ///< tf has no finite pose of its frame at its stamp
};

/// A short name for logs and diagnostics ("shift", "no scan yet", "other frame", …).
const char* toString(StartedVerdict v);

/// The last fused scan, and the last `started` header honoured, against which checkStarted() judges a header.
struct StartedReference
{
  std::string frame;             ///< frame of the fused scans ("" before the first)
  double fused_stamp = 0.0;      ///< s, stamp of the last fused scan
  double fused_x = 0.0, fused_y = 0.0;  ///< m, map frame: the vehicle there
  std::optional<double> shifted_stamp;  ///< s, the last header honoured since (none: none)
};

/**
 * @brief The verdict on a `started` header in @p frame at @p stamp whose vehicle position in the map frame is
 *        (@p x, @p y) (NaN when tf has none). It is honoured only when it describes a scan the fusion will fuse:
 *        the frame of its scans, a stamp newer than the last fused scan and than the last header honoured
 *        (@p stamp_ok: the caller's own stamp checks, zero and ahead of the clock, passed), and a position reachable
 *        from the last fused one at max_plausible_speed (@p params). A window so moved is one the scan itself would
 *        have moved to: a header whose scan never comes costs at most the cells a vehicle at that speed leaves.
 */
StartedVerdict checkStarted(const StartedReference& ref, const std::string& frame, double stamp, bool stamp_ok,
                            double x, double y, const TimeGuardParams& params);

}  // namespace core
}  // namespace map_aided_fusion

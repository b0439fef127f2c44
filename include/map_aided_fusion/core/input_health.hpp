/**
 * @file input_health.hpp
 * @brief Health of a lidar's input stream, ROS-free: a blind cloud (no or too few valid returns) is told apart
 *        from a scene, and clouds missing from the stream are counted from the gaps between the stamps that did
 *        arrive (upstream: a paused player, a driver that skips, the network). Clouds the node discards itself
 *        (a full input queue) it counts one by one where it discards them, never from the stamps.
 *
 * A blind cloud must not be fused: the ScanGrid of a cloud without returns says "free nowhere, occupied
 * nowhere" only by accident of the sensor model, and a few stray returns would carve free space that was never
 * observed. The node counts it by reason and reports the blind spell; the MapGrid keeps its evidence.
 */
#pragma once

#include <cstddef>
#include <deque>
#include <optional>
#include <string>

#include "map_aided_fusion/core/parameters.hpp"
#include "map_aided_fusion/core/sliding_window.hpp"

namespace map_aided_fusion {
namespace core {

/// Parameters of the input health checks (config/scan_grid.yaml).
struct InputHealthParams
{
  /**
   * Valid returns (finite, not the (0, 0, 0) of "no return") a cloud needs to be turned into evidence; a cloud
   * with fewer is blind, counted and not fused. In [0, 10⁷]; 0 turns the check off. About 1 % of a sweep of the
   * sensor in use is a sound choice (a 4-layer IBEO gives some 3,000 returns, a 64-beam Velodyne 120,000).
   */
  int min_valid_returns = 50;
  /**
   * Expected time between clouds (s): a gap of more than 1.5 periods between two received stamps counts the
   * clouds that should have come in it as missing from the stream. 0: learnt from the stream (the shortest of the last 20 gaps).
   * In [0, 10].
   */
  double input_period = 0.0;
  /// @throws ParameterError naming the first parameter out of range.
  void validate() const;
};

/// Calls get(name, field) for every parameter of @p p, with the names of config/scan_grid.yaml.
template <class Get>
void forEachParam(InputHealthParams& p, Get&& get)
{
  get("min_valid_returns", p.min_valid_returns, { "returns", "a cloud with fewer valid returns is blind: counted, not fused; 0: off" });
  get("input_period", p.input_period, { "s", "expected time between clouds, to count lost ones; 0: learnt from the stream" });
}

/// Why a cloud is blind.
enum class BlindReason
{
  kNone,         ///< enough valid returns: not blind
  kEmpty,        ///< no point at all
  kNonFinite,    ///< points, but none valid (all NaN, ±inf or (0, 0, 0))
  kTooFewValid,  ///< some valid returns, fewer than min_valid_returns
};

/// The rejection reason as the diagnostics count it ("blind_empty", "blind_non_finite", "blind_too_few_valid").
const char* toString(BlindReason r);

/// Judges a cloud of @p points points of which @p valid are valid returns.
BlindReason judgeReturns(std::size_t points, std::size_t valid, const InputHealthParams& params);

/**
 * @brief A blind spell: from the first blind cloud after a sighted one to the next sighted cloud.
 *
 * Times are seconds on any monotonic clock.
 */
class BlindSpell
{
public:
  /// A cloud at @p now was blind.
  void blind(double now)
  {
    if (!since_) since_ = now;
    ++clouds_;
  }
  /// A cloud at @p now had enough returns: the spell, if any, is over.
  void sighted()
  {
    since_.reset();
    clouds_ = 0;
  }
  bool active() const { return since_.has_value(); }
  /// Seconds since the spell began (0 when not blind).
  double duration(double now) const { return since_ ? now - *since_ : 0.0; }
  /// Blind clouds in the current spell.
  std::size_t clouds() const { return clouds_; }

private:
  std::optional<double> since_;
  std::size_t clouds_ = 0;
};

/**
 * @brief Counts inputs missing from a stream, from the gaps between the stamps that arrived (every input received
 *        is observed, whatever becomes of it: inputs a node discards itself it counts one by one, apart).
 *
 * With a configured period T (or, when T is 0, the shortest of the last kLearnedGaps gaps between consecutive
 * stamps, which lost inputs can only lengthen), a gap g > 1.5 T means round(g / T) − 1 inputs were missing. A stamp
 * that does not advance (a duplicate, an input out of order) is not judged and leaves the reference at the newest
 * stamp; one older than it by more than kOutageFactor periods (a looping bag, a restarted source), or any older one
 * while the period is unknown, restarts the count.
 */
class InputGapCounter
{
public:
  /// Gaps the learnt period is the shortest of.
  static constexpr std::size_t kLearnedGaps = 20;
  /// A gap this many periods long or more loses inputs.
  static constexpr double kLostGapFactor = 1.5;
  /// Gaps longer than this many periods are an outage (the stream stopped and restarted), not losses.
  static constexpr double kOutageFactor = 100.0;

  explicit InputGapCounter(double period = 0.0) : configured_(period) {}
  /// Inputs missing between the newest stamp so far and @p stamp (seconds).
  std::size_t observe(double stamp);
  /// The period in force (configured or learnt), 0 while unknown.
  double period() const;
  /// Inputs judged missing since construction.
  std::size_t lost() const { return lost_; }

private:
  double configured_;
  std::optional<double> last_;
  std::deque<double> gaps_;
  std::size_t lost_ = 0;
};

/// What the input checks found over the diagnostics window, for inputHealth().
struct InputFindings
{
  bool blind = false;              ///< the last cloud was blind
  double blind_for = 0.0;          ///< s since the blind spell began
  std::size_t blind_clouds = 0;    ///< blind clouds in the spell
  std::string blind_reason;        ///< reason of the last blind cloud (toString(BlindReason))
  std::size_t lost = 0;            ///< inputs lost in the node's input queue in the window
  std::size_t overruns = 0;        ///< inputs whose processing took longer than the input period, in the window
};

/**
 * @brief The stream's summary @p base, made worse by what the input checks found.
 *
 * Blind: WARN "lidar blind for N s", ERROR once the spell lasts stale_error (a blind sensor is not healthier than
 * a silent one). Lost inputs or overruns in the window: at least WARN, the message says how many and why.
 */
HealthSummary inputHealth(HealthSummary base, const StreamHealthParams& params, const InputFindings& found);

}  // namespace core
}  // namespace map_aided_fusion

/**
 * @file sliding_window.hpp
 * @brief Event counts over the last few seconds, for diagnostics that tell the truth about now rather
 *        than about the whole history.
 */
#pragma once

#include <chrono>
#include <cstddef>
#include <deque>
#include <string>

#include "map_aided_fusion/core/parameters.hpp"

namespace map_aided_fusion {
namespace core {

/// Seconds on the monotonic clock the diagnostics windows are fed with (never jumps with ROS or wall time).
inline double steadySeconds()
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

/**
 * @brief Counts events whose time (seconds, any monotonic clock) lies in (now − span, now].
 *
 * Memory is bounded by the events in one span (older ones are pruned on every call).
 */
class SlidingCounter
{
public:
  /// @param span window length, seconds (> 0)
  explicit SlidingCounter(double span = 5.0) : span_(span) {}

  void setSpan(double span) { span_ = span; }

  /// Records @p n events at time @p t.
  void add(double t, std::size_t n = 1)
  {
    if (n == 0) return;
    events_.push_back(Event{ t, n });
    total_ += n;
    prune(t);
  }

  /// Events in (now − span, now].
  std::size_t count(double now)
  {
    prune(now);
    return total_;
  }

  /// Events per second over the window; over the time since @p start when that is shorter than the span.
  double rate(double now, double start)
  {
    const double elapsed = now - start;
    const double window = elapsed < span_ ? elapsed : span_;
    return window > 0.0 ? static_cast<double>(count(now)) / window : 0.0;
  }

private:
  struct Event
  {
    double t;
    std::size_t n;
  };
  void prune(double now)
  {
    while (!events_.empty() && events_.front().t <= now - span_)
    {
      total_ -= events_.front().n;
      events_.pop_front();
    }
  }

  double span_;
  std::deque<Event> events_;
  std::size_t total_ = 0;
};

/**
 * @brief Values (a latency, a stage's time) recorded at times (seconds, any monotonic clock) in (now − span, now],
 *        and their quantiles: what a stage took over the last few seconds, not since start.
 *
 * Memory is bounded by the samples of one span (older ones are pruned on every call).
 */
class SlidingSamples
{
public:
  /// @param span window length, seconds (> 0)
  explicit SlidingSamples(double span = 5.0) : span_(span) {}

  void setSpan(double span) { span_ = span; }

  /// Records @p value at time @p t.
  void add(double t, double value)
  {
    samples_.push_back(Sample{ t, value });
    prune(t);
  }

  /// Samples in (now − span, now].
  std::size_t count(double now)
  {
    prune(now);
    return samples_.size();
  }

  /**
   * @brief The nearest-rank @p q-quantile (q in [0, 1]: 0.5 the median, 0.9 the p90) of the samples in
   *        (now − span, now]: the smallest value with at least ⌈q·n⌉ samples at or below it; NaN without samples.
   */
  double quantile(double now, double q);

private:
  struct Sample
  {
    double t;
    double value;
  };
  void prune(double now)
  {
    while (!samples_.empty() && samples_.front().t <= now - span_) samples_.pop_front();
  }

  double span_;
  std::deque<Sample> samples_;
};

/**
 * @brief The age of data (ms since its stamp) when a stage is done, over a sliding window. An age is a latency only
 *        when it is not negative: a stamp ahead of the clock (a `/clock` lagging behind the data) gives no latency
 *        sample; it is counted, with its lead over the clock, apart.
 */
class LatencyWindow
{
public:
  /// @param span window length, seconds (> 0)
  explicit LatencyWindow(double span = 5.0) : ages_(span), leads_(span) {}

  void setSpan(double span)
  {
    ages_.setSpan(span);
    leads_.setSpan(span);
  }

  /// Records at time @p t an age of @p age_ms (NaN: nothing).
  void add(double t, double age_ms)
  {
    if (age_ms >= 0.0)
      ages_.add(t, age_ms);
    else if (age_ms < 0.0)
      leads_.add(t, -age_ms);
  }

  /// The nearest-rank @p q-quantile of the latencies in the window (SlidingSamples::quantile()); NaN without one.
  double quantile(double now, double q) { return ages_.quantile(now, q); }
  /// Data stamped ahead of the clock in the window.
  std::size_t aheadOfClock(double now) { return leads_.count(now); }
  /// The largest lead of a stamp over the clock in the window, ms; NaN without one.
  double largestLead(double now) { return leads_.quantile(now, 1.0); }

private:
  SlidingSamples ages_, leads_;
};

/// Parameters of the diagnostics of a node that expects a stream of scans (config/*.yaml).
struct StreamHealthParams
{
  double diagnostic_period = 1.0;  ///< s between diagnostic messages, wall time, in [0.05, 60]
  double diagnostic_window = 5.0;  ///< s of history the rates and counts cover, in [0.1, 600]
  double stale_warn = 1.0;         ///< s without output before WARN, in (0, stale_error]
  double stale_error = 3.0;        ///< s without output before ERROR, in [stale_warn, 3600]
  /// @throws ParameterError naming the first parameter out of range.
  void validate() const;
};

/// Calls get(name, field) for every parameter of @p p (the same names in every config/*.yaml).
template <class Get>
void forEachParam(StreamHealthParams& p, Get&& get)
{
  get("diagnostic_period", p.diagnostic_period, { "s", "time between diagnostic messages (wall time)" });
  get("diagnostic_window", p.diagnostic_window, { "s", "history the diagnostics' rates and counts cover" });
  get("stale_warn", p.stale_warn, { "s", "time without output before the status is WARN" });
  get("stale_error", p.stale_error, { "s", "time without output before the status is ERROR" });
}

/// Severity of a diagnostic status, with diagnostic_msgs' numbering (OK 0, WARN 1, ERROR 2).
enum class HealthLevel : int
{
  kOk = 0,
  kWarn = 1,
  kError = 2,
};

/// One diagnostic summary.
struct HealthSummary
{
  HealthLevel level = HealthLevel::kOk;
  std::string message;
};

/**
 * @brief The summary of a stream over the last window.
 * @param params           thresholds
 * @param ever             true once the node produced any output
 * @param since_last       seconds since the last output (ignored when !ever)
 * @param produced         outputs in the window
 * @param lost             inputs dropped or rejected in the window
 * @param what             the noun for the outputs ("scans fused", "clouds published")
 *
 * ERROR when nothing came for stale_error; WARN when nothing came for stale_warn, before the first output,
 * or when inputs were lost in the window; OK otherwise. The message says which and gives the numbers.
 */
HealthSummary streamHealth(const StreamHealthParams& params, bool ever, double since_last, std::size_t produced,
                           std::size_t lost, const std::string& what);

}  // namespace core
}  // namespace map_aided_fusion

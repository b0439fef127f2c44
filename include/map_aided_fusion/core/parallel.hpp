/**
 * @file parallel.hpp
 * @brief Deterministic data parallelism for the per-scan pipeline: fixed chunks of work run on a bounded number of
 *        threads (TBB, kept out of this header).
 *
 * Why TBB and not OpenMP: several nodelets share one process (the manager), each with its own thread budget; a
 * tbb::task_arena per component bounds each one without a process-wide setting (OpenMP's thread count and its
 * pool are global), work stealing balances uneven chunks (rows with obstacles), and nothing leaks into the
 * compiler flags of code that includes the core's headers.
 *
 * Determinism: a job is cut into chunks that depend only on its size, never on the thread count, and every chunk
 * writes only its own cells (or its own slot of a per-chunk partial result, reduced in chunk order). Results are
 * therefore bit-identical for any number of threads (tested).
 */
#pragma once

#include <cstddef>
#include <functional>
#include <memory>

namespace map_aided_fusion {
namespace core {

/// Largest `threads` a component accepts.
constexpr int kMaxThreads = 256;

/// Threads for a `threads` parameter: 0 means every core of the machine; otherwise the value, at most the cores.
int resolveThreads(int threads);

/// @throws ParameterError(name) unless 0 ≤ threads ≤ kMaxThreads.
void validateThreads(const char* name, int threads);

/**
 * @brief A bounded set of worker threads (a TBB arena) that runs chunked jobs.
 *
 * With one thread every job runs inline on the caller, without TBB.
 */
class Parallel
{
public:
  /// @param threads 0: every core; ≥ 1: that many threads (the caller included), at most the cores.
  explicit Parallel(int threads = 1);
  ~Parallel();
  Parallel(const Parallel&) = delete;
  Parallel& operator=(const Parallel&) = delete;

  /// Threads jobs run on (≥ 1).
  int threads() const { return threads_; }

  /// A shared one-thread instance: every job inline on the caller.
  static const Parallel& serial();

  /**
   * Runs body(c) for every chunk c in [0, chunks), each exactly once, in any order and on any of the threads;
   * returns when all are done. Exceptions thrown by body are rethrown here.
   */
  void forChunks(std::size_t chunks, const std::function<void(std::size_t)>& body) const;

  /// Splits [0, n) into chunks of @p chunk items (the last one shorter) and runs body(begin, end) for each.
  void forRange(std::size_t n, std::size_t chunk, const std::function<void(std::size_t, std::size_t)>& body) const;

private:
  struct Arena;
  int threads_;
  std::unique_ptr<Arena> arena_;
};

/// @p parallel, or the serial instance when it is null (the optional argument of the pipeline's functions).
inline const Parallel& orSerial(const Parallel* parallel) { return parallel ? *parallel : Parallel::serial(); }

/// Number of chunks of @p chunk items that cover n items.
inline std::size_t chunkCount(std::size_t n, std::size_t chunk) { return chunk == 0 ? 0 : (n + chunk - 1) / chunk; }

}  // namespace core
}  // namespace map_aided_fusion

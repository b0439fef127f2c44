#include "map_aided_fusion/core/parallel.hpp"

#include <algorithm>
#include <string>
#include <thread>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include "map_aided_fusion/core/parameters.hpp"

namespace map_aided_fusion {
namespace core {

struct Parallel::Arena
{
  explicit Arena(int threads) : arena(threads) {}
  tbb::task_arena arena;
};

int resolveThreads(int threads)
{
  const unsigned hw = std::thread::hardware_concurrency();
  const int cores = std::clamp(static_cast<int>(hw == 0 ? 1 : hw), 1, kMaxThreads);
  // More threads than cores only adds switching (and TBB would refuse the extra workers).
  return threads > 0 ? std::min(threads, cores) : cores;
}

void validateThreads(const char* name, int threads)
{
  if (threads < 0 || threads > kMaxThreads)
    throw ParameterError(name, "value " + std::to_string(threads) + " is outside [0, " + std::to_string(kMaxThreads) +
                                   "] (0: every core)");
}

Parallel::Parallel(int threads) : threads_(resolveThreads(threads))
{
  if (threads_ > 1) arena_ = std::make_unique<Arena>(threads_);
}

Parallel::~Parallel() = default;

const Parallel& Parallel::serial()
{
  static const Parallel one(1);
  return one;
}

void Parallel::forChunks(std::size_t chunks, const std::function<void(std::size_t)>& body) const
{
  if (chunks == 0) return;
  if (!arena_ || chunks == 1)
  {
    for (std::size_t c = 0; c < chunks; ++c) body(c);
    return;
  }
  arena_->arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chunks, 1),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t c = r.begin(); c != r.end(); ++c) body(c);
                      },
                      tbb::simple_partitioner());
  });
}

void Parallel::forRange(std::size_t n, std::size_t chunk, const std::function<void(std::size_t, std::size_t)>& body) const
{
  forChunks(chunkCount(n, chunk), [&](std::size_t c) { body(c * chunk, std::min(n, (c + 1) * chunk)); });
}

}  // namespace core
}  // namespace map_aided_fusion

// The MapGrid windows the benchmarks update: N × N cells, 200 at the paper's 0.5 m (100 m), otherwise 0.2 m (800:
// 160 m).
#pragma once

#include "map_aided_fusion/core/map_grid.hpp"

namespace maf_bench {

/// Cell side of an N × N benchmark window, m.
inline double windowResolution(int n) { return n == 200 ? 0.5 : 0.2; }

/// The parameters of an N × N benchmark window updated on @p threads, with @p skip_unchanged.
inline map_aided_fusion::core::MapGridParams windowParams(int n, int threads,
                                                          bool skip_unchanged = map_aided_fusion::core::MapGridParams{}.skip_unchanged)
{
  map_aided_fusion::core::MapGridParams params;
  params.threads = threads;
  params.skip_unchanged = skip_unchanged;
  params.resolution = windowResolution(n);
  params.size_x = params.size_y = n * params.resolution;
  return params;
}

}  // namespace maf_bench

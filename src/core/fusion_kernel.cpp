#include "fusion_kernel.hpp"

#include "cell_kernels.hpp"

namespace map_aided_fusion {
namespace core {
namespace kernels {

namespace {

/// kPaper: the paper's method (⊛, contextual discounting, counter) compiled without the ablation branches,
/// which costs about a fifth of the time; otherwise the options are read at run time.
template <bool kHasPrior, bool kPaper, bool kWall>
MAF_INLINE void fusionLoop(const StepInputs& in, const ContextualDiscountWeights<float>& w, FusionStepStats& stats)
{
  float* __restrict base = in.base;
  float* __restrict zeta = in.zeta;
  const std::size_t stride = in.stride;
  float sum_fo = 0.0f, sum_of = 0.0f, sum_other = 0.0f;
  const ContextualDiscountWeights8 w8(w);
  forEachCell(in.cells, base, stride, kMapPlanes + 1, [&](auto lane, std::size_t i) MAF_LAMBDA_INLINE {
    using T = decltype(lane);
    T m[kSubsets];
    loadMasses(base, stride, i, m);
    T sp[kNumScanPrior];
    const T zero{};
    scanWithPrior(load<T>(in.sf + i), load<T>(in.so + i), load<T>(in.sw + i), kHasPrior ? load<T>(in.pb + i) : zero,
                  kHasPrior ? load<T>(in.pr + i) : zero, kHasPrior ? load<T>(in.pt + i) : zero,
                  kWall ? load<T>(in.pw + i) : zero, sp, in.threshold);
    if (kPaper || in.contextual)
      contextualDiscount(m, weightsFor<T>(w, w8, lane));
    else
      classicalDiscount(m, in.alpha_single);
    const auto c = modifiedYager<kWall>(m, sp, kPaper ? kRuleModifiedYager : in.rule);
    if (kPaper || in.use_counter)
    {
      const T z = updateCounter(load<T>(zeta + i), occupiedMass(m), c.free_occupied + c.occupied_free, in.delta_inc,
                                in.delta_dec, in.gamma_occupied, in.gamma_conflict);
      store(zeta + i, z);
      specialise(m, z, in.literal);
    }
    if (in.moving_expiry) expireMoving(m, load<T>(in.so + i));
    renormalise(m);
    storeMasses(base, stride, i, m);
    if (in.betp[0])
    {
      T p[FrameMG::kSize];
      pignistic(m, p);
      MAF_UNROLL
      for (int e = 0; e < FrameMG::kSize; ++e) store(in.betp[e] + i, p[e]);
    }
    sum_fo += horizontalSum(c.free_occupied);
    sum_of += horizontalSum(c.occupied_free);
    sum_other += horizontalSum(c.other);
  });
  stats.sum_conflict_free_occupied = sum_fo;
  stats.sum_conflict_occupied_free = sum_of;
  stats.sum_conflict_other = sum_other;
  stats.num_cells = in.cells;
}

}  // namespace

// Compiled for each target of MAF_TARGET_CLONES (a lambda would get only the default one).
MAF_TARGET_CLONES
void fusionChunk(const StepInputs& in, const ContextualDiscountWeights<float>& w, bool has_prior, bool wall, bool paper,
                 FusionStepStats& out)
{
  if (has_prior && wall)
    paper ? fusionLoop<true, true, true>(in, w, out) : fusionLoop<true, false, true>(in, w, out);
  else if (has_prior)
    paper ? fusionLoop<true, true, false>(in, w, out) : fusionLoop<true, false, false>(in, w, out);
  else
    paper ? fusionLoop<false, true, false>(in, w, out) : fusionLoop<false, false, false>(in, w, out);
}

}  // namespace kernels
}  // namespace core
}  // namespace map_aided_fusion

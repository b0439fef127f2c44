#include "fusion_kernel.hpp"

#include "cell_kernels.hpp"

namespace map_aided_fusion {
namespace core {
namespace kernels {

namespace {

/// The chunk's conflict sums: one per lane of the vector cells (reduced once, in lane order, at the end), then the
/// remainder cells; the same order for any thread count, since the chunks are.
struct ConflictSums
{
  Vec8 lanes[3] = {};
  float tail[3] = {};

  MAF_INLINE void add(const CellConflicts<Vec8>& c)
  {
    lanes[0] += c.free_occupied;
    lanes[1] += c.occupied_free;
    lanes[2] += c.other;
  }
  MAF_INLINE void add(const CellConflicts<float>& c)
  {
    tail[0] += c.free_occupied;
    tail[1] += c.occupied_free;
    tail[2] += c.other;
  }
  void reduce(FusionStepStats& stats) const
  {
    stats.sum_conflict_free_occupied = horizontalSum(lanes[0]) + tail[0];
    stats.sum_conflict_occupied_free = horizontalSum(lanes[1]) + tail[1];
    stats.sum_conflict_other = horizontalSum(lanes[2]) + tail[2];
  }
};

/// Appends the cells @p first + lane whose lane of @p seed is set (rare: moving cells the scan sees occupied).
MAF_INLINE void appendSeeds(int seed, std::size_t first, std::vector<std::size_t>& out)
{
  if (seed) out.push_back(first);
}
template <typename M>
MAF_INLINE void appendSeeds(M seed, std::size_t first, std::vector<std::size_t>& out)
{
  for (std::size_t l = 0; l < kLanes; ++l)
    if (seed[l]) out.push_back(first + l);
}

/// kPaper: the paper's method (⊛, contextual discounting, counter) compiled without the ablation branches,
/// which costs about a fifth of the time; otherwise the options are read at run time.
template <bool kHasPrior, bool kPaper, bool kWall>
MAF_INLINE void fusionLoop(const StepInputs& in, const ContextualDiscountWeights<float>& w, FusionStepStats& stats)
{
  float* __restrict base = in.base;
  ConflictSums sums;
  const ContextualDiscountWeights8 w8(w);
  forEachCell(in.cells, [&](auto lane, std::size_t i) MAF_LAMBDA_INLINE {
    using T = decltype(lane);
    T m[kSubsets];
    loadMasses(base, i, m);
    T sp[kNumScanPrior];
    const T zero{};
    const T sf = load<T>(in.sf + i), so = load<T>(in.so + i);
    T pb = kHasPrior ? load<T>(in.pb + i) : zero, pr = kHasPrior ? load<T>(in.pr + i) : zero;
    T pt = kHasPrior ? load<T>(in.pt + i) : zero, pw = kWall ? load<T>(in.pw + i) : zero;
    if (kHasPrior && in.eta)
    {
      T eta = load<T>(in.eta + i);
      mapConflict(sf, so, in.conflict_gain, eta, pb, pr, pt, pw);
      store(in.eta + i, eta);
    }
    scanWithPrior(sf, so, load<T>(in.sw + i), pb, pr, pt, pw, sp, in.threshold);
    if (kPaper || in.contextual)
      contextualDiscount(m, weightsFor<T>(w, w8, lane));
    else
      classicalDiscount(m, in.alpha_single);
    const auto c = modifiedYager<kWall>(m, sp, kPaper ? kRuleModifiedYager : in.rule);
    if (kPaper || in.use_counter)
    {
      float* const zeta = zetaAt(base, i);
      const T z = updateCounter(load<T>(zeta), occupiedMass(m), c.free_occupied + c.occupied_free, in.delta_inc,
                                in.delta_dec, in.gamma_occupied, in.gamma_conflict);
      store(zeta, z);
      specialise(m, z, in.literal);
    }
    if (in.moving_expiry) expireMoving(m, load<T>(in.so + i));
    renormalise(m);
    storeMasses(base, i, m);
    if (in.betp[0])
    {
      T p[FrameMG::kSize];
      pignistic(m, p);
      MAF_UNROLL
      for (int e = 0; e < FrameMG::kSize; ++e) store(in.betp[e] + i, p[e]);
      if (in.decision) storeClass(in.decision + i, decideCell(p, m[FrameMG::kOmega], in.decision_rule));
      if (in.seeds) appendSeeds(isMovingSeed(load<T>(in.so + i), p[FrameMG::kSize - 1], p[FrameMG::kSize - 2],
                                             in.decision_rule.threshold, in.decision_rule.margin),
                                in.first + i, *in.seeds);
    }
    sums.add(c);
  });
  sums.reduce(stats);
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

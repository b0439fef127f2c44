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

using Vec8i = int __attribute__((vector_size(32)));

/// The bits by which two vectors differ (zero when they are the same bits, −0 and +0 told apart).
MAF_INLINE Vec8i bitDifference(Vec8 a, Vec8 b) { return (Vec8i)a ^ (Vec8i)b; }

MAF_INLINE bool allZero(Vec8i v)
{
  int any = 0;
  for (std::size_t l = 0; l < kLanes; ++l) any |= v[l];
  return any == 0;
}

/// A vacuous scan in every lane: m(F) = m(O) = 0, m(Ω) = 1, bit for bit.
MAF_INLINE bool vacuousScan(Vec8 sf, Vec8 so, Vec8 sw)
{
  const Vec8 one = splat<Vec8>(1.0f);
  return allZero((Vec8i)sf | (Vec8i)so | bitDifference(sw, one));
}

/// StepSkip: the block of cells from @p g on was left as it was under the prior @p pb, @p pr, @p pt, @p pw.
MAF_INLINE bool sameKeptPrior(const StepInputs& in, std::size_t g, Vec8 pb, Vec8 pr, Vec8 pt, Vec8 pw)
{
  return allZero(bitDifference(pb, load<Vec8>(in.kept[0] + g)) | bitDifference(pr, load<Vec8>(in.kept[1] + g)) |
                 bitDifference(pt, load<Vec8>(in.kept[2] + g)) | bitDifference(pw, load<Vec8>(in.kept[3] + g)));
}

/// kPaper: the paper's method (⊛, contextual discounting, counter) compiled without the ablation branches,
/// which costs about a fifth of the time; otherwise the options are read at run time. kBuilding: step building
/// conflict, compiled in with kPaper (the default profile's rule) and read at run time otherwise.
template <bool kHasPrior, bool kPaper, bool kWall, bool kBuilding>
MAF_INLINE void fusionLoop(const StepInputs& in, const ContextualDiscountWeights<float>& w, FusionStepStats& stats)
{
  float* __restrict base = in.base;
  ConflictSums sums;
  std::size_t skipped = 0, observed = 0;
  const ContextualDiscountWeights8 w8(w);
  forEachCell(in.cells, [&](auto lane, std::size_t i) MAF_LAMBDA_INLINE {
    using T = decltype(lane);
    constexpr bool kBlock = std::is_same_v<T, Vec8>;
    const T zero{};
    const T sf = load<T>(in.sf + i), so = load<T>(in.so + i), sw = load<T>(in.sw + i);
    T pb = kHasPrior ? load<T>(in.pb + i) : zero, pr = kHasPrior ? load<T>(in.pr + i) : zero;
    T pt = kHasPrior ? load<T>(in.pt + i) : zero, pw = kWall ? load<T>(in.pw + i) : zero;
    [[maybe_unused]] bool vacuous = false;
    if constexpr (kBlock)
    {
      if (in.stable)
      {
        vacuous = vacuousScan(sf, so, sw);
        const std::size_t g = in.first + i;
        if (vacuous && in.stable[g / kLanes] && sameKeptPrior(in, g, pb, pr, pt, pw))
        {
          skipped += kLanes;
          return;
        }
        if (!vacuous) observed += kLanes;
      }
    }
    T m[kSubsets];
    loadMasses(base, i, m);
    [[maybe_unused]] Vec8i changed{};
    T sp[kNumScanPrior];
    if (kHasPrior && in.eta)
    {
      T eta = load<T>(in.eta + i);
      [[maybe_unused]] const T eta0 = eta;
      mapConflict(sf, so, in.conflict_gain, eta, pb, pr, pt, pw);
      store(in.eta + i, eta);
      if constexpr (kBlock) changed |= bitDifference(eta, eta0);
    }
    scanWithPrior(sf, so, sw, pb, pr, pt, pw, sp, in.threshold);
    if (kPaper || in.contextual)
      contextualDiscount(m, weightsFor<T>(w, w8, lane));
    else
      classicalDiscount(m, in.alpha_single);
    const auto c = modifiedYager<kWall>(m, sp, kPaper ? kRuleModifiedYager : in.rule,
                                        kPaper ? kBuilding : in.building_conflict);
    if (kPaper || in.use_counter)
    {
      float* const zeta = zetaAt(base, i);
      const T z0 = load<T>(zeta);
      const T z = updateCounter(z0, occupiedMass(m), c.free_occupied + c.occupied_free, in.delta_inc, in.delta_dec,
                                in.gamma_occupied, in.gamma_conflict);
      store(zeta, z);
      if constexpr (kBlock) changed |= bitDifference(z, z0);
      specialise(m, z, in.literal);
    }
    if (in.moving_expiry) expireMoving(m, so);
    renormalise(m);
    if constexpr (kBlock)
    {
      if (in.stable && vacuous)
      {
        // The block's masses in memory are still the step's input.
        const float* const cell = cellAt(base, i);
        MAF_UNROLL
        for (int a = 0; a < kSubsets; ++a)
          if (MapMassGrid::kSlots[a] >= 0)
            changed |= bitDifference(m[a], load<Vec8>(cell + MapMassGrid::kSlots[a] * kSlotStride));
      }
    }
    storeMasses(base, i, m);
    if (in.betp[0])
    {
      T p[FrameMG::kSize];
      pignistic(m, p);
      MAF_UNROLL
      for (int e = 0; e < FrameMG::kSize; ++e) store(in.betp[e] + i, p[e]);
      if (in.decision) storeClass(in.decision + i, decideCell(p, m[FrameMG::kOmega], in.decision_rule));
      if (in.seeds) appendSeeds(isMovingSeed(so, p[FrameMG::kSize - 1], p[FrameMG::kSize - 2],
                                             in.decision_rule.threshold, in.decision_rule.margin),
                                in.first + i, *in.seeds);
    }
    sums.add(c);
    if constexpr (kBlock)
    {
      if (in.stable)
      {
        // Stable when nothing changed and nothing was summed: a skipped block then adds nothing either.
        const auto conflict = (c.free_occupied != zero) | (c.occupied_free != zero) | (c.other != zero);
        const std::size_t g = in.first + i;
        const bool stable = vacuous && allZero(changed | conflict);
        in.stable[g / kLanes] = stable;
        if (stable)
        {
          store(in.kept[0] + g, pb);
          store(in.kept[1] + g, pr);
          store(in.kept[2] + g, pt);
          store(in.kept[3] + g, pw);
        }
      }
    }
  });
  sums.reduce(stats);
  stats.num_cells = in.cells;
  stats.num_skipped = skipped;
  stats.num_observed = observed;
}

}  // namespace

// Compiled for each target of MAF_TARGET_CLONES (a lambda would get only the default one).
MAF_TARGET_CLONES
void fusionChunk(const StepInputs& in, const ContextualDiscountWeights<float>& w, bool has_prior, bool wall, bool paper,
                 FusionStepStats& out)
{
  // Without a prior sp({C}) is 0, so step building conflict changes nothing there.
  const bool building = paper && has_prior && in.building_conflict;
  if (has_prior && wall)
  {
    if (building)
      fusionLoop<true, true, true, true>(in, w, out);
    else
      paper ? fusionLoop<true, true, true, false>(in, w, out) : fusionLoop<true, false, true, false>(in, w, out);
  }
  else if (has_prior)
  {
    if (building)
      fusionLoop<true, true, false, true>(in, w, out);
    else
      paper ? fusionLoop<true, true, false, false>(in, w, out) : fusionLoop<true, false, false, false>(in, w, out);
  }
  else
    paper ? fusionLoop<false, true, false, false>(in, w, out) : fusionLoop<false, false, false, false>(in, w, out);
}

}  // namespace kernels
}  // namespace core
}  // namespace map_aided_fusion

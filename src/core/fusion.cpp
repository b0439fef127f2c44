#include "map_aided_fusion/core/fusion.hpp"

#include <algorithm>
#include <stdexcept>
#include <vector>

#include "cell_kernels.hpp"

namespace map_aided_fusion {
namespace core {

using kernels::kSubsets;

const char* toString(CombinationRule rule)
{
  switch (rule)
  {
    case CombinationRule::kYager:
      return "yager";
    case CombinationRule::kDempster:
      return "dempster";
    case CombinationRule::kModifiedYager:
      break;
  }
  return "modified_yager";
}

CombinationRule parseCombinationRule(const std::string& name)
{
  for (CombinationRule r : { CombinationRule::kModifiedYager, CombinationRule::kYager, CombinationRule::kDempster })
    if (name == toString(r)) return r;
  throw ParameterError("combination_rule", "'" + name + "' is not modified_yager, yager or dempster");
}

CellFusionResult fuseCell(const MassMG& map_prev, double zeta_prev, const MassSG& scan, const MassMG& prior,
                          const FusionParams& params)
{
  CellFusionResult r;
  DempsterReport report;
  const MassMG scan_prior = dempster(refine(scan), prior, &report);
  r.scan_prior_total_conflict = report.total_conflict;
  const MassMG discounted = params.contextual_discounting ? contextualDiscount(map_prev, params.discount)
                                                          : discount(map_prev, params.alpha_single);
  MassMG fused = modifiedYager(discounted, scan_prior, &r.conflicts);
  if (params.rule == CombinationRule::kYager) fused = yager(discounted, scan_prior);
  if (params.rule == CombinationRule::kDempster) fused = dempster(discounted, scan_prior);
  if (!params.use_counter)
  {
    r.zeta = zeta_prev;
    r.mass = fused;
  }
  else
  {
    r.zeta = updateCounter(zeta_prev, fused.massInside(FrameMG::kO), r.conflicts, params.counter);
    r.mass = specialise(fused, r.zeta, params.counter.mode);
  }
  if (params.moving_expiry && !(scan[FrameSG::kO] > 0.0))
  {
    r.mass[FrameMG::kOmega] += r.mass[FrameMG::kV];
    r.mass[FrameMG::kV] = 0.0;
  }
  return r;
}

namespace {

/// Everything the fused loop reads, hoisted out of it.
struct StepInputs
{
  float* base;
  float* zeta;
  std::size_t stride;
  std::size_t cells;
  const float* sf;
  const float* so;
  const float* sw;
  const float* pb;
  const float* pr;
  const float* pt;
  const float* pw;
  float delta_inc, delta_dec, gamma_occupied, gamma_conflict, threshold;
  bool literal;
  int rule;
  bool contextual;
  float alpha_single;
  bool use_counter;
  bool moving_expiry;
  float* betp[FrameMG::kSize];  ///< BetP planes to fill, or nullptr

  /// The same inputs for the cells [begin, begin + count): every per-cell pointer moved, the plane stride kept.
  StepInputs offset(std::size_t begin, std::size_t count) const
  {
    StepInputs o = *this;
    auto move = [begin](auto*& p) {
      if (p) p += begin;
    };
    move(o.base);
    move(o.zeta);
    move(o.sf);
    move(o.so);
    move(o.sw);
    move(o.pb);
    move(o.pr);
    move(o.pt);
    move(o.pw);
    for (auto*& b : o.betp) move(b);
    o.cells = count;
    return o;
  }
};

/// kPaper: the paper's method (⊛, contextual discounting, counter) compiled without the ablation branches,
/// which costs about a fifth of the time; otherwise the options are read at run time.
template <bool kHasPrior, bool kPaper, bool kWall>
MAF_INLINE void fusionLoop(const StepInputs& in, const ContextualDiscountWeights<float>& w, FusionStepStats& stats)
{
  float* __restrict base = in.base;
  float* __restrict zeta = in.zeta;
  const std::size_t stride = in.stride;
  float sum_fo = 0.0f, sum_of = 0.0f, sum_other = 0.0f;
  const kernels::ContextualDiscountWeights8 w8(w);
  kernels::forEachCell(in.cells, base, stride, kSubsets + 1, [&](auto lane, std::size_t i) MAF_LAMBDA_INLINE {
    using T = decltype(lane);
    using kernels::load;
    T m[kSubsets];
    MAF_UNROLL
    for (int a = 0; a < kSubsets; ++a) m[a] = load<T>(base + a * stride + i);
    T sp[kernels::kNumScanPrior];
    const T zero{};
    kernels::scanWithPrior(load<T>(in.sf + i), load<T>(in.so + i), load<T>(in.sw + i),
                           kHasPrior ? load<T>(in.pb + i) : zero, kHasPrior ? load<T>(in.pr + i) : zero,
                           kHasPrior ? load<T>(in.pt + i) : zero, kWall ? load<T>(in.pw + i) : zero, sp,
                           in.threshold);
    if (kPaper || in.contextual)
      kernels::contextualDiscount(m, kernels::weightsFor<T>(w, w8, lane));
    else
      kernels::classicalDiscount(m, in.alpha_single);
    const auto c = kernels::modifiedYager<kWall>(m, sp, kPaper ? kernels::kRuleModifiedYager : in.rule);
    if (kPaper || in.use_counter)
    {
      const T z = kernels::updateCounter(load<T>(zeta + i), kernels::occupiedMass(m),
                                         c.free_occupied + c.occupied_free, in.delta_inc, in.delta_dec,
                                         in.gamma_occupied, in.gamma_conflict);
      kernels::store(zeta + i, z);
      kernels::specialise(m, z, in.literal);
    }
    if (in.moving_expiry) kernels::expireMoving(m, load<T>(in.so + i));
    kernels::renormalise(m);
    MAF_UNROLL
    for (int a = 0; a < kSubsets; ++a) kernels::store(base + a * stride + i, m[a]);
    if (in.betp[0])
    {
      T p[FrameMG::kSize];
      kernels::pignistic(m, p);
      MAF_UNROLL
      for (int e = 0; e < FrameMG::kSize; ++e) kernels::store(in.betp[e] + i, p[e]);
    }
    sum_fo += kernels::horizontalSum(c.free_occupied);
    sum_of += kernels::horizontalSum(c.occupied_free);
    sum_other += kernels::horizontalSum(c.other);
  });
  stats.sum_conflict_free_occupied = sum_fo;
  stats.sum_conflict_occupied_free = sum_of;
  stats.sum_conflict_other = sum_other;
  stats.num_cells = in.cells;
}

/// One chunk of the step, compiled for each target of MAF_TARGET_CLONES (a lambda would get only the default one).
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

}  // namespace

void fusionStep(MapMassGrid& map, const ScanMassGrid& scan, const PriorWindow* prior, const FusionParams& params,
                FusionStepStats* stats, PignisticPlanes* betp, const Parallel* parallel)
{
  params.validate();
  if (scan.geometry() != map.geometry()) throw std::invalid_argument("fusionStep: scan grid and map grid differ");
  if (prior && prior->geometry != map.geometry())
    throw std::invalid_argument("fusionStep: prior window and map grid differ");
  const ContextualDiscountWeights<float> w(params.discount);
  StepInputs in;
  in.base = map.plane(0);
  in.zeta = map.counter();
  in.stride = map.stride();
  in.cells = map.numCells();
  in.sf = scan.plane(FrameSG::kF);
  in.so = scan.plane(FrameSG::kO);
  in.sw = scan.plane(FrameSG::kOmega);
  in.pb = prior ? prior->building.data() : nullptr;
  in.pr = prior ? prior->road.data() : nullptr;
  in.pt = prior ? prior->other.data() : nullptr;
  in.pw = prior ? prior->wall.data() : nullptr;
  in.delta_inc = static_cast<float>(params.counter.delta_inc);
  in.delta_dec = static_cast<float>(params.counter.delta_dec);
  in.gamma_occupied = static_cast<float>(params.counter.gamma_occupied);
  in.gamma_conflict = static_cast<float>(params.counter.gamma_conflict);
  in.threshold = static_cast<float>(kTotalConflictThreshold);
  in.literal = params.counter.mode == SpecialisationMode::kLiteral;
  in.rule = params.rule == CombinationRule::kModifiedYager ? kernels::kRuleModifiedYager
            : params.rule == CombinationRule::kYager       ? kernels::kRuleYager
                                                           : kernels::kRuleDempster;
  in.contextual = params.contextual_discounting;
  in.alpha_single = static_cast<float>(params.alpha_single);
  in.use_counter = params.use_counter;
  in.moving_expiry = params.moving_expiry;
  for (int e = 0; e < FrameMG::kSize; ++e)
  {
    if (betp) betp->p[e].resize(in.cells);
    in.betp[e] = betp ? betp->p[e].data() : nullptr;
  }
  const bool paper = in.rule == kernels::kRuleModifiedYager && in.contextual && in.use_counter;
  const bool has_prior = prior != nullptr, wall = prior && prior->hasWall();
  // Fixed chunks (independent of the thread count), their statistics summed in chunk order: bit-identical results.
  const std::size_t chunks = chunkCount(in.cells, kFusionChunkCells);
  std::vector<FusionStepStats> partial(chunks);
  auto chunk = [&](std::size_t c) {
    const std::size_t begin = c * kFusionChunkCells, end = std::min(in.cells, begin + kFusionChunkCells);
    fusionChunk(in.offset(begin, end - begin), w, has_prior, wall, paper, partial[c]);
  };
  orSerial(parallel).forChunks(chunks, chunk);
  FusionStepStats total;
  for (const FusionStepStats& p : partial)
  {
    total.sum_conflict_free_occupied += p.sum_conflict_free_occupied;
    total.sum_conflict_occupied_free += p.sum_conflict_occupied_free;
    total.sum_conflict_other += p.sum_conflict_other;
    total.num_cells += p.num_cells;
  }
  if (stats) *stats = total;
}

}  // namespace core
}  // namespace map_aided_fusion

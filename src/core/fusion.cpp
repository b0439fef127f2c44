#include "map_aided_fusion/core/fusion.hpp"

#include <algorithm>
#include <stdexcept>

#include "cell_kernels.hpp"

namespace map_aided_fusion {
namespace core {

using kernels::kSubsets;

CellFusionResult fuseCell(const MassMG& map_prev, double zeta_prev, const MassSG& scan, const MassMG& prior,
                          const FusionParams& params)
{
  CellFusionResult r;
  DempsterReport report;
  const MassMG scan_prior = dempster(refine(scan), prior, &report);
  r.scan_prior_total_conflict = report.total_conflict;
  const MassMG discounted = contextualDiscount(map_prev, params.discount);
  const MassMG fused = modifiedYager(discounted, scan_prior, &r.conflicts);
  r.zeta = updateCounter(zeta_prev, fused.massInside(FrameMG::kO), r.conflicts, params.counter);
  r.mass = specialise(fused, r.zeta, params.counter.mode);
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
  float delta_inc, delta_dec, gamma_occupied, gamma_conflict, threshold;
  bool literal;
};

template <bool kHasPrior>
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
                           kHasPrior ? load<T>(in.pt + i) : zero, sp, in.threshold);
    kernels::contextualDiscount(m, kernels::weightsFor<T>(w, w8, lane));
    const auto c = kernels::modifiedYager(m, sp);
    const T z = kernels::updateCounter(load<T>(zeta + i), kernels::occupiedMass(m), c.free_occupied + c.occupied_free,
                                       in.delta_inc, in.delta_dec, in.gamma_occupied, in.gamma_conflict);
    kernels::store(zeta + i, z);
    kernels::specialise(m, z, in.literal);
    MAF_UNROLL
    for (int a = 0; a < kSubsets; ++a) kernels::store(base + a * stride + i, m[a]);
    sum_fo += kernels::horizontalSum(c.free_occupied);
    sum_of += kernels::horizontalSum(c.occupied_free);
    sum_other += kernels::horizontalSum(c.other);
  });
  stats.sum_conflict_free_occupied = sum_fo;
  stats.sum_conflict_occupied_free = sum_of;
  stats.sum_conflict_other = sum_other;
  stats.num_cells = in.cells;
}

}  // namespace

MAF_TARGET_CLONES
void fusionStep(MapMassGrid& map, const ScanMassGrid& scan, const PriorWindow* prior, const FusionParams& params,
                FusionStepStats* stats)
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
  in.delta_inc = static_cast<float>(params.counter.delta_inc);
  in.delta_dec = static_cast<float>(params.counter.delta_dec);
  in.gamma_occupied = static_cast<float>(params.counter.gamma_occupied);
  in.gamma_conflict = static_cast<float>(params.counter.gamma_conflict);
  in.threshold = static_cast<float>(kTotalConflictThreshold);
  in.literal = params.counter.mode == SpecialisationMode::kLiteral;
  FusionStepStats local;
  if (prior)
    fusionLoop<true>(in, w, local);
  else
    fusionLoop<false>(in, w, local);
  if (stats) *stats = local;
}

}  // namespace core
}  // namespace map_aided_fusion

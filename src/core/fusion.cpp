#include "map_aided_fusion/core/fusion.hpp"

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

MAF_TARGET_CLONES
void fusionStep(MapMassGrid& map, const ScanMassGrid& scan, const PriorWindow* prior, const FusionParams& params,
                FusionStepStats* stats)
{
  params.validate();
  if (scan.geometry() != map.geometry()) throw std::invalid_argument("fusionStep: scan grid and map grid differ");
  if (prior && prior->geometry != map.geometry())
    throw std::invalid_argument("fusionStep: prior window and map grid differ");
  const ContextualDiscountWeights<float> w(params.discount);
  const std::size_t n = map.numCells();
  const std::size_t stride = map.stride();
  float* __restrict base = map.plane(0);
  float* __restrict zeta = map.counter();
  const float* __restrict sf = scan.plane(FrameSG::kF);
  const float* __restrict so = scan.plane(FrameSG::kO);
  const float* __restrict sw = scan.plane(FrameSG::kOmega);
  const float* __restrict pb = prior ? prior->building.data() : nullptr;
  const float* __restrict pr = prior ? prior->road.data() : nullptr;
  const float* __restrict pt = prior ? prior->other.data() : nullptr;
  const float di = static_cast<float>(params.counter.delta_inc), dd = static_cast<float>(params.counter.delta_dec);
  const float go = static_cast<float>(params.counter.gamma_occupied);
  const float gc = static_cast<float>(params.counter.gamma_conflict);
  const bool literal = params.counter.mode == SpecialisationMode::kLiteral;
  const float threshold = static_cast<float>(kTotalConflictThreshold);
  float sum_fo = 0.0f, sum_of = 0.0f, sum_other = 0.0f;
#pragma omp simd reduction(+ : sum_fo, sum_of, sum_other)
  for (std::size_t i = 0; i < n; ++i)
  {
    float m[kSubsets];
    MAF_UNROLL
    for (int a = 0; a < kSubsets; ++a) m[a] = base[a * stride + i];
    float sp[kernels::kNumScanPrior];
    kernels::scanWithPrior(sf[i], so[i], sw[i], pb ? pb[i] : 0.0f, pr ? pr[i] : 0.0f, pt ? pt[i] : 0.0f, sp,
                           threshold);
    kernels::contextualDiscount(m, w);
    const auto c = kernels::modifiedYager(m, sp);
    const float z = kernels::updateCounter(zeta[i], kernels::occupiedMass(m), c.free_occupied + c.occupied_free, di,
                                           dd, go, gc);
    zeta[i] = z;
    kernels::specialise(m, z, literal);
    MAF_UNROLL
    for (int a = 0; a < kSubsets; ++a) base[a * stride + i] = m[a];
    sum_fo += c.free_occupied;
    sum_of += c.occupied_free;
    sum_other += c.other;
  }
  if (stats)
  {
    stats->sum_conflict_free_occupied = sum_fo;
    stats->sum_conflict_occupied_free = sum_of;
    stats->sum_conflict_other = sum_other;
    stats->num_cells = n;
  }
}

}  // namespace core
}  // namespace map_aided_fusion

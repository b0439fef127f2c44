#include "map_aided_fusion/core/fusion.hpp"

#include <algorithm>
#include <stdexcept>
#include <vector>

#include "cell_kernels.hpp"
#include "fusion_kernel.hpp"

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

void fusionStep(MapMassGrid& map, const ScanMassGrid& scan, const PriorWindow* prior, const FusionParams& params,
                FusionStepStats* stats, PignisticPlanes* betp, const Parallel* parallel, const StepDecisions* decisions)
{
  params.validate();
  if (scan.geometry() != map.geometry()) throw std::invalid_argument("fusionStep: scan grid and map grid differ");
  if (prior && prior->geometry != map.geometry())
    throw std::invalid_argument("fusionStep: prior window and map grid differ");
  const ContextualDiscountWeights<float> w(params.discount);
  kernels::StepInputs in;
  in.base = map.planes();
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
  in.decision = nullptr;
  in.seeds = nullptr;
  in.first = 0;
  if (decisions && (decisions->out || decisions->motion_seeds))
  {
    if (!betp) throw std::invalid_argument("fusionStep: decisions need the BetP planes");
    in.decision_rule.threshold = static_cast<float>(decisions->threshold);
    in.decision_rule.motion_margin = decisions->motion_margin > 0.0;
    in.decision_rule.margin = static_cast<float>(decisions->motion_margin);
  }
  if (decisions && decisions->out)
  {
    decisions->out->resize(in.cells);
    in.decision = decisions->out->data();
  }
  const bool paper = in.rule == kernels::kRuleModifiedYager && in.contextual && in.use_counter;
  const bool has_prior = prior != nullptr;
  const float* const wall_plane = prior && prior->wall.size() == in.cells ? prior->wall.data() : nullptr;
  // Fixed chunks (independent of the thread count), their statistics summed in chunk order: bit-identical results.
  static_assert(kFusionChunkCells % MapMassGrid::kBlockCells == 0, "chunks start on a block of the MapGrid");
  const std::size_t chunks = chunkCount(in.cells, kFusionChunkCells);
  std::vector<FusionStepStats> partial(chunks);
  std::vector<std::vector<std::size_t>>* const seeds = decisions ? decisions->motion_seeds : nullptr;
  if (seeds && seeds->size() < chunks) seeds->resize(chunks);
  auto chunk = [&](std::size_t c) {
    const std::size_t begin = c * kFusionChunkCells, end = std::min(in.cells, begin + kFusionChunkCells);
    // The wall terms only in chunks with mass on W: on a zero wall mass both loops give the same bits.
    const bool wall = wall_plane && anyNonZero(wall_plane + begin, end - begin);
    kernels::StepInputs chunk_in = in.offset(begin, end - begin);
    if (seeds)
    {
      (*seeds)[c].clear();
      chunk_in.seeds = &(*seeds)[c];
    }
    kernels::fusionChunk(chunk_in, w, has_prior, wall, paper, partial[c]);
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

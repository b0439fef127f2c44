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
  MassMG fused = modifiedYager(discounted, scan_prior, &r.conflicts, params.building_conflict);
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
  if (prior && prior->geometry != map.geometry())
    throw std::invalid_argument("fusionStep: prior window and map grid differ");
  StepPrior rows;
  rows.grid = prior;
  rows.row_stride = static_cast<std::size_t>(map.geometry().width);
  fusionStep(map, scan, rows, params, stats, betp, parallel, decisions);
}

namespace {

constexpr std::size_t kScanPlanes = 3;  // F, O and Ω of a chunk's scan buffer

/// fusionStep() with the scan's planes in the map's cells (@p scan) or filled chunk by chunk (@p cells).
void fuse(MapMassGrid& map, const ScanMassGrid* scan, const ScanCells* cells, const StepPrior& prior,
          const FusionParams& params, FusionStepStats* stats, PignisticPlanes* betp, const Parallel* parallel,
          const StepDecisions* decisions)
{
  params.validate();
  if ((scan ? scan->geometry() : cells->geometry()) != map.geometry())
    throw std::invalid_argument("fusionStep: scan grid and map grid differ");
  const std::size_t width = static_cast<std::size_t>(map.geometry().width);
  const std::size_t height = static_cast<std::size_t>(map.geometry().height);
  const PriorWindow* const pg = prior.grid;
  // The prior's rows: one run of cells per map row when they are not the map's own rows.
  const bool by_rows = pg && prior.row_stride != width;
  if (pg)
  {
    const std::size_t n = pg->building.size();
    const bool fits = prior.row_stride >= width && height > 0 &&
                      prior.first + (height - 1) * prior.row_stride + width <= n && pg->road.size() == n &&
                      pg->other.size() == n && (pg->wall.size() == n || pg->wall.empty());
    if (!fits) throw std::invalid_argument("fusionStep: the map's cells are not all inside the prior");
    if (by_rows && width % MapMassGrid::kBlockCells != 0)
      throw std::invalid_argument("fusionStep: prior rows need a map width that is a multiple of the blocks");
  }
  if (prior.doubt && !pg) throw std::invalid_argument("fusionStep: a map doubt needs a prior");
  const ContextualDiscountWeights<float> w(params.discount);
  kernels::StepInputs in;
  in.base = map.planes();
  in.cells = map.numCells();
  in.sf = scan ? scan->plane(FrameSG::kF) : nullptr;
  in.so = scan ? scan->plane(FrameSG::kO) : nullptr;
  in.sw = scan ? scan->plane(FrameSG::kOmega) : nullptr;
  in.pb = in.pr = in.pt = in.pw = nullptr;
  in.eta = prior.doubt;
  in.conflict_gain = static_cast<float>(prior.conflict_gain);
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
  in.building_conflict = params.building_conflict;
  for (int e = 0; e < FrameMG::kSize; ++e)
  {
    if (betp) betp->p[e].resize(in.cells);
    in.betp[e] = betp ? betp->p[e].data() : nullptr;
  }
  in.decision = nullptr;
  in.seeds = nullptr;
  in.first = 0;
  in.stable = nullptr;
  for (float*& k : in.kept) k = nullptr;
  if (decisions && decisions->skip && decisions->skip->stable)
  {
    in.stable = decisions->skip->stable;
    for (int k = 0; k < 4; ++k) in.kept[k] = decisions->skip->kept[k];
  }
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
  const bool has_prior = pg != nullptr;
  // Fixed chunks (independent of the thread count), their statistics summed in chunk order: bit-identical results.
  static_assert(kFusionChunkCells % MapMassGrid::kBlockCells == 0, "chunks start on a block of the MapGrid");
  const std::size_t chunks = chunkCount(in.cells, kFusionChunkCells);
  std::vector<FusionStepStats> partial(chunks);
  std::vector<std::vector<std::size_t>>* const seeds = decisions ? decisions->motion_seeds : nullptr;
  if (seeds && seeds->size() < chunks) seeds->resize(chunks);
  // Cells [begin, end) whose prior is the prior grid's cells from @p at on; with @p local, their scan masses are
  // the chunk's buffer from cell @p chunk_begin on (F, O, Ω planes of kFusionChunkCells).
  auto run = [&](const kernels::StepInputs& chunk_in, std::size_t begin, std::size_t end, std::size_t at,
                 FusionStepStats& sum, const float* local, std::size_t chunk_begin) {
    kernels::StepInputs r = chunk_in.offset(begin, end - begin);
    if (local)
    {
      r.sf = local + (begin - chunk_begin);
      r.so = r.sf + kFusionChunkCells;
      r.sw = r.so + kFusionChunkCells;
    }
    bool wall = false;
    if (pg)
    {
      r.pb = pg->building.data() + at;
      r.pr = pg->road.data() + at;
      r.pt = pg->other.data() + at;
      r.pw = pg->wall.empty() ? nullptr : pg->wall.data() + at;
      // The wall terms only where there is mass on W: on a zero wall mass both loops give the same bits.
      wall = r.pw && anyNonZero(r.pw, end - begin);
    }
    FusionStepStats s;
    kernels::fusionChunk(r, w, has_prior, wall, paper, s);
    sum.sum_conflict_free_occupied += s.sum_conflict_free_occupied;
    sum.sum_conflict_occupied_free += s.sum_conflict_occupied_free;
    sum.sum_conflict_other += s.sum_conflict_other;
    sum.num_cells += s.num_cells;
    sum.num_skipped += s.num_skipped;
    sum.num_observed += s.num_observed;
  };
  auto chunk = [&](std::size_t c) {
    const std::size_t begin = c * kFusionChunkCells, end = std::min(in.cells, begin + kFusionChunkCells);
    kernels::StepInputs chunk_in = in;
    if (seeds)
    {
      (*seeds)[c].clear();
      chunk_in.seeds = &(*seeds)[c];
    }
    float* local = nullptr;
    if (cells)
    {
      thread_local AlignedVector<float> buffer;  // the fusing thread's (a worker's own in a parallel step)
      if (buffer.size() < kScanPlanes * kFusionChunkCells) buffer.resize(kScanPlanes * kFusionChunkCells);
      local = buffer.data();
      cells->fill(begin, end, local, local + kFusionChunkCells, local + 2 * kFusionChunkCells);
    }
    if (!by_rows)
    {
      run(chunk_in, begin, end, prior.first + begin, partial[c], local, begin);
      return;
    }
    for (std::size_t i = begin; i < end;)
    {
      const std::size_t y = i / width, row_end = std::min(end, (y + 1) * width);
      run(chunk_in, i, row_end, prior.first + y * prior.row_stride + (i - y * width), partial[c], local, begin);
      i = row_end;
    }
  };
  orSerial(parallel).forChunks(chunks, chunk);
  FusionStepStats total;
  for (const FusionStepStats& p : partial)
  {
    total.sum_conflict_free_occupied += p.sum_conflict_free_occupied;
    total.sum_conflict_occupied_free += p.sum_conflict_occupied_free;
    total.sum_conflict_other += p.sum_conflict_other;
    total.num_cells += p.num_cells;
    total.num_skipped += p.num_skipped;
    total.num_observed += p.num_observed;
  }
  if (stats) *stats = total;
}

}  // namespace

void fusionStep(MapMassGrid& map, const ScanMassGrid& scan, const StepPrior& prior, const FusionParams& params,
                FusionStepStats* stats, PignisticPlanes* betp, const Parallel* parallel, const StepDecisions* decisions)
{
  fuse(map, &scan, nullptr, prior, params, stats, betp, parallel, decisions);
}

void fusionStep(MapMassGrid& map, const ScanCells& scan, const StepPrior& prior, const FusionParams& params,
                FusionStepStats* stats, PignisticPlanes* betp, const Parallel* parallel, const StepDecisions* decisions)
{
  fuse(map, nullptr, &scan, prior, params, stats, betp, parallel, decisions);
}

}  // namespace core
}  // namespace map_aided_fusion

/**
 * @file fusion.hpp
 * @brief One step of the paper's temporal fusion, for one cell (scalar reference) and for a grid.
 *
 * In the paper's order (sections 2.3–2.5):
 *   m'_SG,t = r(m_SG,t) ⊕ m_PG                       (refining, then Dempster with the prior)
 *   m_MG,t  = ^α m'_MG,t−1 ⊛ m'_SG,t                 (contextual discounting, modified Yager rule)
 *   ζ_t     = update(ζ_t−1, m_MG,t(O), ∅_FO, ∅_OF)   (counter, equation 3)
 *   m'_MG,t = specialise(m_MG,t, ζ_t)                (equation 4)
 */
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "map_aided_fusion/core/counter.hpp"
#include "map_aided_fusion/core/discounting.hpp"
#include "map_aided_fusion/core/grid_ops.hpp"
#include "map_aided_fusion/core/mass_grid.hpp"
#include "map_aided_fusion/core/parallel.hpp"
#include "map_aided_fusion/core/parameters.hpp"
#include "map_aided_fusion/core/prior.hpp"
#include "map_aided_fusion/core/rules.hpp"

namespace map_aided_fusion {
namespace core {

/// The rule that fuses the discounted MapGrid with the ScanGrid (the paper's is kModifiedYager).
enum class CombinationRule
{
  kModifiedYager,  ///< ⊛: ∅_FO → {V}, the rest of the conflict → Ω (the paper)
  kYager,          ///< all the conflict → Ω
  kDempster,       ///< normalised; total conflict gives the vacuous mass function
};

/// The rule's name in config/fusion.yaml (`combination_rule`): modified_yager, yager or dempster.
const char* toString(CombinationRule rule);
/// @throws ParameterError("combination_rule") for a name other than modified_yager, yager or dempster.
CombinationRule parseCombinationRule(const std::string& name);

/// Everything one fusion step needs. The defaults are the paper's method; the other options exist for
/// ablation studies (evaluate's variants).
struct FusionParams
{
  ContextualRates discount;  ///< α, per scan
  CounterParams counter;     ///< δ_inc, δ_dec, γ_O, γ_∅ and the specialisation mode
  CombinationRule rule = CombinationRule::kModifiedYager;
  /// false: classical discounting with the single rate alpha_single instead of contextual discounting
  bool contextual_discounting = true;
  double alpha_single = 0.1;  ///< rate of the classical discounting, in [0, 1]
  /// false: no counter and no specialisation (ζ stays 0)
  bool use_counter = true;
  /**
   * Step "moving expiry" (not in the paper): after the step, where the scan holds no occupied mass, m({V}) moves to
   * Ω. A moving object is where the sensor sees it now; without this, V left behind a mover (in the cells it
   * vacated, often hidden behind it) or by a one-sweep flicker decays only by discounting, a trail of V.
   */
  bool moving_expiry = true;
  /**
   * Step "building conflict" (not in the paper): the conflict between the map's {F} and scan-and-prior evidence
   * that can only be the mapped building, m({C}), goes to Ω instead of V (modifiedYager()). A wall whose cell was
   * seen free (a pose error, a wall seen at a grazing angle, the free part of an outline cell) did not move.
   */
  bool building_conflict = true;
  /// @throws ParameterError naming the first parameter out of range.
  void validate() const
  {
    discount.validate();
    counter.validate();
    requireUnit("alpha_single", alpha_single);
  }
};

/// Result of one fusion step on one cell.
struct CellFusionResult
{
  MassMG mass;                 ///< m'_MG,t
  double zeta = 0.0;           ///< ζ_t
  ConflictMasses conflicts;    ///< ∅_FO, ∅_OF and the rest, as met by ⊛
  bool scan_prior_total_conflict = false;  ///< r(m_SG) ⊕ m_PG met total conflict (m'_SG vacuous)
};

/// The scalar reference of one step, from the definitions (used to test the grid kernels).
CellFusionResult fuseCell(const MassMG& map_prev, double zeta_prev, const MassSG& scan, const MassMG& prior,
                          const FusionParams& params);

/// Aggregates of one grid fusion step, for diagnostics.
struct FusionStepStats
{
  double sum_conflict_free_occupied = 0.0;  ///< Σ ∅_FO over cells
  double sum_conflict_occupied_free = 0.0;  ///< Σ ∅_OF over cells
  double sum_conflict_other = 0.0;          ///< Σ remaining conflict over cells
  std::size_t num_cells = 0;
  std::size_t num_skipped = 0;  ///< cells of num_cells the step left as they were without computing them (StepSkip)
  /// With StepSkip: cells of num_cells in blocks whose scan was not vacuous (the scan observed them). The cells neither
  /// skipped nor observed are those still changing under a vacuous scan (evidence decaying towards the prior).
  std::size_t num_observed = 0;
  double meanConflict() const
  {
    return num_cells ? (sum_conflict_free_occupied + sum_conflict_occupied_free + sum_conflict_other) / num_cells : 0.0;
  }
};

/**
 * @brief What fusionStep() needs to skip, bit-exactly, the cells the step would leave as they are
 *        (MapGridParams::skip_unchanged).
 *
 * One flag per block of MapMassGrid::kBlockCells cells: a step sets it when it left the block's masses, ζ and map
 * doubt η bit for bit as they were, under a vacuous scan (m(F) = m(O) = 0, m(Ω) = 1) and with no conflict, and keeps
 * in @ref kept the prior it read there (0 where there is none). A later step skips a flagged block while its scan is
 * vacuous and its prior the same bits: the step, a function of those inputs and the parameters, would give the same
 * bits again. BetP and the decisions of a skipped block stay what that step wrote. The caller clears the flags of
 * every cell it changes between steps, and all of them when the parameters, the window's place, the outputs asked
 * for, or whether there is a prior or a map doubt change.
 */
struct StepSkip
{
  std::uint8_t* stable = nullptr;  ///< (cells + kBlockCells − 1) / kBlockCells flags
  float* kept[4] = {};             ///< building, road, other and wall of the prior, one per cell
};

/// The decisions fusionStep() can write in the pass that computes BetP: the rule of decide() in map_grid.hpp.
struct StepDecisions
{
  std::vector<std::int8_t>* out = nullptr;  ///< resized to the grid's cells; CellClass codes
  double threshold = 0.4;                   ///< MapGridParams::decision_threshold
  double motion_margin = 0.0;               ///< MapGridParams::motion_margin (0: the step is off)
  /// When not null, also the cells that seed motion spreading (see spreadMotion() in map_grid.hpp, with this threshold
  /// and margin): one list per chunk of kFusionChunkCells cells, in index order.
  std::vector<std::vector<std::size_t>>* motion_seeds = nullptr;
  /// When not null, blocks the step would leave as they are are skipped (see StepSkip).
  const StepSkip* skip = nullptr;
};

/**
 * @brief One fusion step on a whole grid, in place, all stages fused in one pass over the cells.
 *
 * @param map    the MapGrid m'_MG,t−1 with its counter; becomes m'_MG,t.
 * @param scan   the ScanGrid already in @p map's cells (same geometry).
 * @param prior  the prior window of the same geometry, or nullptr for a vacuous prior.
 * @param betp   when not null, receives BetP of m'_MG,t (computed in the same pass).
 * @param parallel  when not null, the threads the cells are shared among (chunks of kFusionChunkCells); the masses,
 *                  BetP, decisions and statistics are bit-identical for any number of threads.
 * @param decisions when not null (with @p betp), receives the decision of each cell, the same as decide() on the new
 *                  masses and BetP would give.
 * @throws std::invalid_argument when the geometries differ, or decisions are asked for without BetP.
 */
void fusionStep(MapMassGrid& map, const ScanMassGrid& scan, const PriorWindow* prior, const FusionParams& params,
                FusionStepStats* stats = nullptr, PignisticPlanes* betp = nullptr, const Parallel* parallel = nullptr,
                const StepDecisions* decisions = nullptr);

/**
 * @brief The prior as the fused step reads it (MapGrid::update): the rows of a prior grid that holds the map's cells
 *        on the same lattice, so that no prior window is copied, and the step "map conflict" applied cell by cell.
 */
struct StepPrior
{
  const PriorWindow* grid = nullptr;  ///< the prior; its cell @p first is the map's cell (0, 0)
  std::size_t first = 0;              ///< index in @p grid of the map's cell (0, 0)
  /// Cells from one row of the map to the next in @p grid (its width); when it differs from the map's width, that
  /// width must be a multiple of MapMassGrid::kBlockCells.
  std::size_t row_stride = 0;
  /// When not null: the map doubt η of each map cell, updated, by which the prior is discounted before it is combined
  /// (applyMapConflict() in map_grid.hpp, with the same scan); nullptr: the prior as it is.
  float* doubt = nullptr;
  double conflict_gain = 0.0;  ///< MapGridParams::map_conflict_gain
};

/**
 * @brief fusionStep() with the prior read from @p prior's rows (and its map doubt): the same masses, ζ, BetP and
 *        decisions as extractPriorWindow(), applyMapConflict() and fusionStep() on that window.
 * @throws std::invalid_argument when the map's cells are not all inside @p prior.grid, or the widths do not allow it.
 */
void fusionStep(MapMassGrid& map, const ScanMassGrid& scan, const StepPrior& prior, const FusionParams& params,
                FusionStepStats* stats = nullptr, PignisticPlanes* betp = nullptr, const Parallel* parallel = nullptr,
                const StepDecisions* decisions = nullptr);

/// Cells per chunk of a parallel fusion step (a multiple of the 8-cell vectors and of the prefetch blocks).
constexpr std::size_t kFusionChunkCells = 16384;

/**
 * @brief A scan in the map's cells that is written where it is read: the fused step asks for each chunk's scan
 *        masses just before it fuses that chunk, so no window of scan masses goes through memory
 *        (ScanProjection in scan_projection.hpp).
 */
class ScanCells
{
public:
  virtual ~ScanCells() = default;
  /// The cells the scan is given in (the map's).
  virtual const GridGeometry& geometry() const = 0;
  /**
   * @brief m(F), m(O) and m(Ω) of the cells [begin, end) into @p f, @p o, @p omega [0, end − begin). Called from
   *        several threads at once, on disjoint runs of cells.
   */
  virtual void fill(std::size_t begin, std::size_t end, float* f, float* o, float* omega) const = 0;
};

/**
 * @brief fusionStep() with the scan of each chunk written by @p scan into a buffer of the thread that fuses it: the
 *        same masses, ζ, BetP and decisions as fusionStep() on a ScanGrid holding what @p scan fills.
 * @throws std::invalid_argument as the other overloads.
 */
void fusionStep(MapMassGrid& map, const ScanCells& scan, const StepPrior& prior, const FusionParams& params,
                FusionStepStats* stats = nullptr, PignisticPlanes* betp = nullptr, const Parallel* parallel = nullptr,
                const StepDecisions* decisions = nullptr);

}  // namespace core
}  // namespace map_aided_fusion

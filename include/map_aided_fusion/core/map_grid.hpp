/**
 * @file map_grid.hpp
 * @brief The MapGrid: a rolling window of mass functions on Ω_MG in the `map` frame that follows the
 *        vehicle and fuses one ScanGrid per scan with the PriorGrid (sections 2.3–2.5 of the paper).
 */
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "map_aided_fusion/core/parameters.hpp"
#include "map_aided_fusion/core/cell_class.hpp"
#include "map_aided_fusion/core/fusion.hpp"
#include "map_aided_fusion/core/grid_ops.hpp"
#include "map_aided_fusion/core/scan_projection.hpp"

namespace map_aided_fusion {
namespace core {

/// Parameters of the MapGrid (config/fusion.yaml).
/// MapGridParams::motion_share of step motion spreading when on: the share it was designed with (KITTI 00's first
/// labelled sweeps), off by default.
constexpr double kMotionSpreadingShare = 0.2;

struct MapGridParams
{
  double size_x = 100.0;     ///< window length along x, metres (> 0)
  double size_y = 100.0;     ///< window length along y, metres (> 0)
  double resolution = 0.5;   ///< cell side, metres (> 0); the paper's 0.5 m
  FusionParams fusion;       ///< α, δ, γ and the specialisation mode
  /**
   * When true the rates α are per second: a scan Δt after the previous one is discounted with
   * 1 − (1 − α)^Δt, so that a varying scan rate or a dropped scan forgets the right amount.
   * When false (the paper) they are per scan.
   */
  bool rates_per_second = false;
  /**
   * The window is recentred (whole-cell shift of all planes) once the vehicle is farther than this from its
   * centre, metres (≥ 0; 0: every scan). Shifting moves every plane, so a few metres of slack saves most of
   * that memory traffic while the vehicle always keeps at least size/2 − recentre_distance of view.
   */
  double recentre_distance = 5.0;
  double decision_threshold = 0.4;  ///< BetP a class needs to be a cell's decision, in [0, 1]
  int min_object_cells = 3;         ///< smaller connected S or V regions are noise (cells, ≥ 1)
  /// Longer S or V regions are structure, not an object (m, > 0; an articulated bus is 18.75 m).
  double max_object_length = 20.0;
  /// Larger S or V regions are structure, not an object (m², > 0).
  double max_object_area = 60.0;
  /// S regions at most this wide (m, ≥ 0) and longer than thin_structure_length are walls or fences, not
  /// objects (without a map they are S). Moving regions are exempt.
  double thin_structure_width = 1.0;
  double thin_structure_length = 8.0;  ///< m, > 0; see thin_structure_width
  /**
   * Memory the MapGrid's window may take, MiB (in [1, 1048576]). A window whose cells would need more
   * (bytesPerCell() each: every stored focal-set plane, ζ, BetP, the prior window, the map doubt, the decision and
   * the projection's occupied and clearance masks) is refused by validate(), before anything is allocated.
   */
  double memory_budget_mb = 2048.0;

  /**
   * Step "point occupancy" (not in the paper): when the scan comes with its obstacle returns, occupied evidence
   * goes to the window cell under each return, not to the window cells the resampled scan cell covers. A scan cell
   * in the vehicle lattice straddles up to four window cells; resampling it moves an obstacle's edge by a cell
   * from one sweep to the next as the vehicle moves, and ⊛ reads that free → occupied flicker as motion.
   */
  bool point_occupancy = true;
  /**
   * Step "obstacle clearance" (not in the paper): window cells within this distance of a cell holding an obstacle
   * return (square neighbourhood of round(distance / resolution) cells) get no free evidence from this scan, m
   * in [0, 5]; 0 disables it. At range an azimuth sector is narrower than a cell and a return's footprint wider, so
   * a cell at an obstacle's edge is seen free in one sweep and occupied in the next.
   */
  double obstacle_clearance = 1.0;
  /**
   * Step "motion spreading" (not in the paper): after the step, each connected region (8-connectivity) of cells
   * the scan sees occupied, of at most motion_max_cells cells, in which at least this share of cells has
   * BetP(V) ≥ decision_threshold and BetP(V) − BetP(S) > motion_margin, is one moving object: in each of its cells
   * the occupied mass that still leaves the motion open (focal sets holding V and other classes) goes to {V}. Conflict only marks the cells an object
   * enters; the rest of a mover (the cells it still covers, and all of it when it moves away from the sensor) would
   * otherwise stay undecided. In [0, 1]; 0 disables it. Off by default: with track evidence (TrackerParams) giving a
   * mover's cells its motion, the step added false V on every labelled real sequence and on every simulated drive
   * and lowered the point-level moving IoU pooled over the real sequences (doc/steps.md); kMotionSpreadingShare is
   * the share it was designed with (`evaluate`'s row default_with_motion_spreading).
   */
  double motion_share = 0.0;
  int motion_max_cells = 200;  ///< largest region motion spreading treats as one object, cells (≥ 1)
  /**
   * Step "motion margin" (not in the paper): a cell whose decision would be S or V with |BetP(S) − BetP(V)| below
   * this, or that no class decides although its occupied BetP (1 − BetP(F)) reaches decision_threshold, is decided
   * CellClass::kOccupied, "occupied, motion (or class) not yet known". An object first seen already in place (no
   * earlier free evidence) has its mass on {S, V}; the counter grows at once and specialisation would tip it to S
   * by a hair. In [0, 1]; 0 disables it.
   */
  double motion_margin = 0.1;
  /**
   * Step "map conflict" (not in the paper): a per-cell doubt η in [0, 1] about the map, kept with the window. Each
   * scan, η += map_conflict_gain · (K − A), K = m_PG(B)·m_SG(F) the scan's conflict with a mapped building, A =
   * (m_PG(B) + m_PG(W))·m_SG(O) its agreement, clamped to [0, 1]; the prior is discounted by η before it is
   * combined (m_PG ← (1 − η)·m_PG, the rest to Ω). A building that is mapped but no longer there (or that the pose
   * error moves) stops being called C once the lidar keeps seeing through it. In [0, 1]; 0 disables it.
   */
  double map_conflict_gain = 0.2;
  /**
   * σ of the vehicle's position, metres in [0, 5], by which the prior is softened (prior_uncertainty.hpp) when no
   * pose covariance is configured or received; a received covariance replaces it. 0: the prior as published.
   */
  double position_sigma = 0.0;
  /**
   * Threads of the per-scan update (shift, scan projection, prior window, fusion step with BetP, decisions), in
   * [0, kMaxThreads]; 0: every core. The results are bit-identical for any value (parallel.hpp).
   */
  int threads = 0;
  /**
   * Skip, in the fused step, the blocks of cells the step would leave bit for bit as they are (StepSkip in
   * fusion.hpp): cells the scan does not see whose evidence has reached a fixed point of the prior and the
   * discounting, or is vacuous. Every output is bit-identical either way; off with alpha_per_second (the discounting
   * then changes with each scan's Δt).
   */
  bool skip_unchanged = true;
  /// Bytes one window cell needs in the MapGrid and its per-scan buffers.
  static std::size_t bytesPerCell();
  /// Bytes the window of these parameters needs (cells × bytesPerCell()).
  double bytesNeeded() const;
  /// @throws ParameterError naming the first parameter out of range, or the window size over the budget.
  void validate() const;
};

/**
 * @brief Calls get(name, field) for every parameter of @p p, with the names of config/fusion.yaml: one list
 *        shared by the ROS loader and the YAML loader of the offline tools.
 */
template <class Get>
void forEachParam(MapGridParams& p, Get&& get)
{
  get("size_x", p.size_x, { "m", "MapGrid window length along x (map frame, follows the vehicle)" });
  get("size_y", p.size_y, { "m", "MapGrid window length along y" });
  get("resolution", p.resolution, { "m", "cell side of the MapGrid (the paper: 0.5 m)" });
  get("recentre_distance", p.recentre_distance, { "m", "the window is shifted by whole cells once the vehicle is farther than this from its centre" });
  get("alpha_static", p.fusion.discount.alpha_static, { "", "discount rate α of θ_static = {C, N} per scan (per second with alpha_per_second)" });
  get("alpha_dynamic", p.fusion.discount.alpha_dynamic, { "", "discount rate α of θ_dynamic = {S, V}" });
  get("alpha_free", p.fusion.discount.alpha_free, { "", "discount rate α of θ_free = {F}" });
  get("alpha_per_second", p.rates_per_second, { "", "rates α per second (1 − (1 − α)^Δt) rather than per scan as in the paper" });
  get("delta_inc", p.fusion.counter.delta_inc, { "", "δ_inc: increment of the counter ζ per consistent occupied observation" });
  get("delta_dec", p.fusion.counter.delta_dec, { "", "δ_dec: decrement of ζ per conflicting observation" });
  get("gamma_occupied", p.fusion.counter.gamma_occupied, { "", "γ_O: occupied mass m_MG(O) a cell needs to count as occupied" });
  get("gamma_conflict", p.fusion.counter.gamma_conflict, { "", "γ_∅: conflict ∅_FO + ∅_OF above this is a change" });
  bool literal = p.fusion.counter.mode == SpecialisationMode::kLiteral;
  get("specialise_literal", literal, { "", "specialisation as the paper's matrix reads (ζ·m({V}) to ∅, then normalised); false: to {S}" });
  p.fusion.counter.mode = literal ? SpecialisationMode::kLiteral : SpecialisationMode::kMovingToStopped;
  std::string rule = toString(p.fusion.rule);
  get("combination_rule", rule, { "", "modified_yager (the paper), yager or dempster" });
  p.fusion.rule = parseCombinationRule(rule);
  get("building_conflict", p.fusion.building_conflict, { "", "step: the conflict between {F} and evidence that can only be the mapped building ({C}) goes to Ω, not V" });
  get("moving_expiry", p.fusion.moving_expiry, { "", "step: m({V}) goes to Ω where the scan holds no occupied mass" });
  get("decision_threshold", p.decision_threshold, { "", "BetP a class needs to be a cell's decision" });
  get("min_object_cells", p.min_object_cells, { "cells", "smaller connected S or V regions are noise, not objects" });
  get("max_object_length", p.max_object_length, { "m", "longer S or V regions are structure, not an object" });
  get("max_object_area", p.max_object_area, { "m²", "larger S or V regions are structure, not an object" });
  get("thin_structure_width", p.thin_structure_width, { "m", "S regions at most this wide and longer than thin_structure_length are walls or fences" });
  get("thin_structure_length", p.thin_structure_length, { "m", "see thin_structure_width" });
  get("memory_budget_mb", p.memory_budget_mb, { "MiB", "memory the MapGrid window may take; a larger window is refused before allocation" });
  get("point_occupancy", p.point_occupancy, { "", "step: occupied evidence in the window cell under each obstacle return" });
  get("motion_share", p.motion_share, { "", "step motion spreading: share of V cells that makes a small occupied region one mover; 0: off" });
  get("motion_max_cells", p.motion_max_cells, { "cells", "largest region motion spreading treats as one object" });
  get("motion_margin", p.motion_margin, { "", "step: S or V within this BetP of each other is decided \"occupied, motion not yet known\"; 0: off" });
  get("obstacle_clearance", p.obstacle_clearance, { "m", "step: no free evidence within this distance of an obstacle return; 0: off" });
  get("map_conflict_gain", p.map_conflict_gain, { "", "step: growth of the per-cell map doubt η where the scan contradicts the map; 0: off" });
  get("position_sigma", p.position_sigma, { "m", "σ of the vehicle position that softens the prior when no pose covariance is received" });
  get("threads", p.threads, { "", "threads of the per-scan update; 0: every core (results identical for any value)" });
  get("skip_unchanged", p.skip_unchanged, { "", "skip the cells the step would leave bit for bit as they are (results identical either way)" });
}

/// Wall time of each stage of MapGrid::update(), seconds.
struct StageTimes
{
  double shift = 0.0;
  double project_scan = 0.0;  ///< the projection's plan (ScanProjection::plan); the step samples the scan itself
  double prior_window = 0.0;
  double fusion = 0.0;        ///< the fused step (with the scan's samples, BetP, decisions), then motion spreading
};

/// The motion a tracked object gives one cell (step "track evidence", core/track_evidence.hpp).
struct CellMotion
{
  std::size_t cell = 0;
  CellClass motion = CellClass::kMoving;  ///< kMoving, kStopped, or kOccupied (occupied, motion not yet known)
  float weight = 0.0f;                    ///< β in [0, 1] (kMoving, kStopped)
  /// A cell of the object's box holding none of its returns (seen over, or hidden behind, its near side): only sets
  /// that hold the target class move, so that space seen free stays free.
  bool interior = false;
  /// An interior cell that this scan did not see free (hidden behind the object's near side, or seen over): its free
  /// evidence is older than the object, so sets within {F, the other motion} move too, as in a cell of its returns.
  bool hidden = false;
  /// Sets holding N move too (step "small movers"): a pedestrian on a pavement whose prior is {N, S, V}.
  bool take_n = false;
  /// Sets holding C move too (step movers without a map: without a prior, C is not told from N, S and V).
  bool take_c = false;
  /// Sets within {F, N, S} (within {N, S} in an interior cell seen free) move too, for kMoving (step "small
  /// specialised"): a walker stays in a cell for several scans, and the counter has specialised its pavement's
  /// {N, S, V} to {N, S} before its track is moving.
  bool take_specialised = false;
};

/// An object made of a connected region of moving or stopped cells.
struct GridObject
{
  CellClass cell_class = CellClass::kMoving;  ///< kMoving or kStopped
  Point2 centroid;                            ///< metres, map frame
  double yaw = 0.0;                           ///< orientation of the major axis, radians
  double length = 0.0;                        ///< extent along the major axis, metres (cells included)
  double width = 0.0;                         ///< extent along the minor axis, metres
  int cells = 0;                              ///< number of cells
  double mean_betp = 0.0;                     ///< mean BetP of the object's class over its cells
};

/**
 * @brief The prior masses of @p window, sampled at each window cell's centre from @p prior (nearest
 *        neighbour; an exact copy when the lattices are aligned). Cells outside @p prior are vacuous.
 */
void extractPriorWindow(const PriorWindow& prior, const GridGeometry& window, PriorWindow& out,
                        const Parallel* parallel = nullptr);

/// The step map_conflict's inputs (see applyMapConflict), for extractPriorWindow to apply it row by row.
struct MapConflict
{
  const ScanMassGrid* scan = nullptr;       ///< the scan in the window's cells
  double gain = 0.0;                        ///< MapGridParams::map_conflict_gain
  AlignedVector<float>* doubt = nullptr;    ///< η per window cell, updated
};

/**
 * @brief extractPriorWindow() then applyMapConflict() with @p conflict, in one pass: each row is discounted while
 *        it is still in cache. The result is identical to the two calls.
 */
void extractPriorWindow(const PriorWindow& prior, const GridGeometry& window, PriorWindow& out,
                        const MapConflict& conflict, const Parallel* parallel = nullptr);

/**
 * @brief Where the window's cell (0, 0) is in @p prior (its index) when extractPriorWindow() would copy the window as
 *        consecutive columns and rows of @p prior, all inside it; nullopt otherwise.
 */
std::optional<std::size_t> alignedPriorStart(const GridGeometry& prior, const GridGeometry& window);

/**
 * @brief The navigable-space layer (nav_msgs/OccupancyGrid values) from a decision grid and the prior of the same
 *        cells: free on the road surface (m_PG(R) above m_PG(T) + m_PG(B) + m_PG(W)) → 0; free elsewhere or where
 *        the prior is vacuous → kNavigableOffRoad; occupied (C, N, S, V, or occupied undetermined) → 100;
 *        undecided → −1.
 */
void navigableLayer(const std::vector<std::int8_t>& decision, const PriorWindow& prior, std::vector<std::int8_t>& out);

/// Value of free space off the road surface in the navigable layer.
constexpr std::int8_t kNavigableOffRoad = 50;

/**
 * @brief Step map_conflict (MapGridParams::map_conflict_gain): updates the doubt η of each cell from the scan
 *        @p scan (same geometry) and discounts @p prior by it in place. @p doubt is resized (zeros) when needed.
 */
void applyMapConflict(PriorWindow& prior, const ScanMassGrid& scan, double gain, AlignedVector<float>& doubt,
                      const Parallel* parallel = nullptr);

/**
 * @brief Decision per cell: the class of largest BetP when it reaches @p threshold, kUnknown otherwise or
 *        where the cell is vacuous (m(Ω) ≥ 1 − 1e-3).
 */
void decide(const MapMassGrid& grid, const PignisticPlanes& betp, double threshold, std::vector<std::int8_t>& out,
            const Parallel* parallel = nullptr);

/**
 * @brief The step "motion spreading" on @p grid and its BetP @p betp (both updated in place): see
 *        MapGridParams::motion_share. @p scan is the scan in the grid's cells. A cell counts as V when
 *        BetP(V) ≥ @p threshold and BetP(V) − BetP(S) > @p margin (an open {S, V} is not motion). Returns the number
 *        of regions spread. @p parallel: the threads that look for the moving cells (the result is the same for any
 *        number).
 * @throws std::invalid_argument when @p scan and @p grid have different geometries.
 */
std::size_t spreadMotion(MapMassGrid& grid, PignisticPlanes& betp, const ScanMassGrid& scan, double share,
                         int max_cells, double threshold, double margin, const Parallel* parallel = nullptr);

/// Decision per cell with every decision parameter of @p params: the threshold, then the step "motion margin"
/// (S or V decisions within motion_margin of each other, and occupied cells no class decides, become
/// CellClass::kOccupied).
void decide(const MapMassGrid& grid, const PignisticPlanes& betp, const MapGridParams& params,
            std::vector<std::int8_t>& out, const Parallel* parallel = nullptr);

/**
 * @brief Connected regions (8-connectivity) of kMoving or kStopped decisions that are shaped like objects: at least
 *        min_object_cells cells, at most max_object_length long and max_object_area large, and (stopped) not a thin
 *        structure (width ≤ thin_structure_width and length > thin_structure_length) — the limits of @p params.
 */
std::vector<GridObject> extractObjects(const GridGeometry& geometry, const std::vector<std::int8_t>& decision,
                                       const PignisticPlanes& betp, const MapGridParams& params);

/**
 * @brief The rolling-window MapGrid and the per-scan pipeline of the paper.
 *
 * The window follows the vehicle by whole-cell shifts: stored evidence is moved, never resampled; cells
 * entering the window are vacuous with ζ = 0; cells leaving it are dropped. Window origins are multiples
 * of the resolution, so a prior on the same lattice is copied exactly.
 */
class MapGrid
{
public:
  /// @throws ParameterError when @p params are out of range.
  explicit MapGrid(const MapGridParams& params);

  /// Replaces the parameters between scans (the window is reallocated if its size or resolution changed).
  void setParams(const MapGridParams& params);
  const MapGridParams& params() const { return params_; }

  /// Forgets everything: vacuous cells, ζ = 0, no previous scan.
  void reset();

  /**
   * @brief One scan: recentre the window on the vehicle, map the scan into it, refine, combine with the
   *        prior (Dempster), discount the previous MapGrid, fuse (modified Yager), update ζ, specialise.
   * @param scan   ScanGrid in the vehicle frame
   * @param pose   vehicle pose in the map frame at the scan's time
   * @param stamp  scan time, seconds (used for rates_per_second)
   * @param prior  the whole PriorGrid in the map frame, or nullptr for a vacuous prior
   * @param obstacles  the scan's obstacle returns in the vehicle frame (ScanGridBuilder::obstaclePoints()), used by
   *               the step point_occupancy; nullptr: occupied evidence from the resampled scan cells (the paper)
   */
  FusionStepStats update(const ScanMassGrid& scan, const Pose2& pose, double stamp, const PriorWindow* prior,
                         StageTimes* times = nullptr, const ObstaclePoints* obstacles = nullptr);

  /**
   * @brief Moves the window by whole cells: the cell at (x, y) moves to (x − dx, y − dy) and the origin by
   *        (dx, dy) cells. Masses and ζ are moved bit-exactly; with skip_unchanged, the flags of the skipped blocks
   *        move too, with their BetP, decisions and kept prior, so that the next update still skips what stayed
   *        unchanged. That update computes every other cell and writes its BetP and decision (vacated cells are
   *        vacuous): until then, pignistic() and decisions() hold only for the blocks that stay skipped.
   */
  void shift(int dx, int dy);

  /// Centres the window on @p p by a whole-cell shift (no-op when already centred).
  void recentre(Point2 p);

  /**
   * @brief Moves the window as update() would for a scan taken at @p p: recentre() when @p p is farther than
   *        recentre_distance from the window's centre, nothing before the first scan. An update() at the same @p p
   *        then leaves the window where it is, so that the shift can be made while that scan is still being built
   *        (the fusion node's shift_ahead): the grid after the update is the same, byte for byte.
   * @return whether the window moved
   */
  bool follow(Point2 p);

  const MapMassGrid& masses() const { return grid_; }
  /// The masses to change in place: the next update() computes every cell again (MapGridParams::skip_unchanged).
  /// (A separate name, so that reading masses() never costs the next update its skipped cells.)
  MapMassGrid& mutableMasses()
  {
    forgetStable();
    return grid_;
  }
  /// Share of the last update's cells that skip_unchanged skipped, in [0, 1].
  double skippedShare() const { return skipped_share_; }
  /// Share of the last update's cells the scan observed (FusionStepStats::num_observed; 0 without skip_unchanged), in
  /// [0, 1].
  double observedShare() const { return observed_share_; }
  /// Share of the last update's cells neither skipped nor observed, in [0, 1]: computed under a vacuous scan, their
  /// evidence still decaying towards the prior. NaN when that update did not skip (skip_unchanged off, or
  /// alpha_per_second), since the step then tells no cells apart.
  double changingShare() const { return changing_share_; }
  const GridGeometry& geometry() const { return grid_.geometry(); }
  /// BetP of every cell after the last update (F, C, N, S, V planes), computed in the fusion pass.
  const PignisticPlanes& pignistic() const { return betp_; }

  /**
   * @brief Step "track evidence" (not in the paper): the motion of tracked objects in their cells, after update().
   *
   * kMoving with weight β moves β·m(A) to {V} from every focal set A ⊆ {F, S, V} of the cell with V ∈ A or
   * A ⊆ {F, S} (a mover where space was free or an object stopped, as the paper's ⊛ sends the free-to-occupied
   * conflict to V); kStopped likewise to {S} (S ∈ A or A ⊆ {F, V}). Sets holding C or N are left alone: the static
   * classes stay the prior's and the counter's (measured: moving evidence on them lets false moving tracks on poles
   * and trees take N), except those holding N for CellMotion::take_n and C for CellMotion::take_c. Each transfer keeps
   * the total: the result is a mass function. BetP and decisions of the listed cells are computed again; a kOccupied cell decided S or V is
   * then decided CellClass::kOccupied (an object whose motion is not yet known is neither).
   */
  void applyTrackedMotion(const std::vector<CellMotion>& cells);
  /// The decision of every cell after the last update (decide() with these parameters, written in the fusion pass
  /// and again where motion spreading changed a cell); the same as decide(masses(), pignistic(), params()).
  const std::vector<std::int8_t>& decisions() const { return decision_; }
  /// Number of scans fused since the last reset.
  std::size_t scans() const { return scans_; }
  /// The map doubt η of every window cell (step map_conflict; zeros when it is off).
  const AlignedVector<float>& mapDoubt() const { return map_doubt_; }
  /**
   * @brief The prior of the last update in the window's cells, after the map doubt: @p prior, the PriorGrid given to
   *        that update, sampled at each cell (extractPriorWindow()) and discounted by mapDoubt() as the step was;
   *        vacuous when @p prior is null.
   */
  void priorWindow(const PriorWindow* prior, PriorWindow& out) const;
  /// The threads of this grid's update (MapGridParams::threads), for the decisions of the same cells.
  const Parallel& parallel() const { return *parallel_; }

private:
  MapGridParams params_;
  MapMassGrid grid_;
  ScanProjection projection_;  // the scan of the last update in the window's cells, filled chunk by chunk by the step
  PriorWindow prior_window_;  // the prior sampled at the window's cells, when the step cannot read the prior's rows
  AlignedVector<float> map_doubt_;
  PignisticPlanes betp_;
  std::vector<std::int8_t> decision_;
  std::vector<std::vector<std::size_t>> motion_seeds_;  // the fused step's seeds of motion spreading, per chunk
  std::shared_ptr<const Parallel> parallel_;
  double last_stamp_ = 0.0;
  std::size_t scans_ = 0;
  // MapGridParams::skip_unchanged: StepSkip's flags and kept prior, and the step inputs they hold for (prior, doubt).
  AlignedVector<float> shift_edge_;  ///< the rows a shift's bands read from each other (shift())
  std::vector<std::uint8_t> stable_;
  AlignedVector<float> kept_[4];
  int skip_inputs_ = -1;
  double skipped_share_ = 0.0;
  double observed_share_ = 0.0;
  double changing_share_ = std::numeric_limits<double>::quiet_NaN();

  void forgetStable() { std::fill(stable_.begin(), stable_.end(), std::uint8_t{ 0 }); }
  void forgetStable(const std::vector<std::size_t>& cells);
  /// shift()'s move of the flags and of what a skipped block keeps (kept prior, BetP, decision), before the masses
  /// move; or forgetStable() where the flags cannot follow (no flags, rows of part blocks, a jump past the window).
  void shiftStable(int dx, int dy);
  /// The StepSkip of this update (flags sized, cleared when the inputs' kind changed), or nullptr when it is off.
  const StepSkip* prepareSkip(bool has_prior, bool has_doubt, StepSkip& skip);
};

}  // namespace core
}  // namespace map_aided_fusion

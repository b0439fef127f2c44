// Per-cell kernels on Ω_MG shared by the grid operations. Every index is a compile-time constant
// once the loops are unrolled, so a loop over cells that calls them vectorises across cells.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "map_aided_fusion/core/cell_class.hpp"
#include "map_aided_fusion/core/counter.hpp"
#include "map_aided_fusion/core/discounting.hpp"
#include "map_aided_fusion/core/frame.hpp"
#include "map_aided_fusion/core/mass_grid.hpp"
#include "fusion_kernel.hpp"

#if defined(__GNUC__) && !defined(__clang__)
#define MAF_UNROLL _Pragma("GCC unroll 64")
#else
#define MAF_UNROLL _Pragma("unroll")
#endif
#if defined(__GNUC__)
#define MAF_INLINE inline __attribute__((always_inline))
#define MAF_LAMBDA_INLINE __attribute__((always_inline))
#else
#define MAF_INLINE inline
#define MAF_LAMBDA_INLINE
#endif
// Whole-grid loops get clones chosen at run time by the CPU: AVX2+FMA (x86-64-v3) and AVX-512 (x86-64-v4, whose 32
// vector registers hold twice the live masses of the 16 of AVX2; the vectors stay eight floats wide). The two
// clones give the same bits: both contract the same products into FMAs.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(MAF_NO_TARGET_CLONES)
#define MAF_TARGET_CLONES __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#define MAF_TARGET_CLONES
#endif

namespace map_aided_fusion {
namespace core {
namespace kernels {

constexpr int kSubsets = FrameMG::kNumSubsets;
/// Planes of a MapGrid: the stored subsets, then ζ.
constexpr int kMapPlanes = MapMassGrid::kNumPlanes;

/// Eight floats processed together (GCC/Clang vector extension: AVX registers in the AVX2 clone,
/// pairs of SSE registers otherwise). The kernels below are templates on the lane type T, which is
/// this vector in the grid loops, float for the remainder cells and double for the scalar reference.
using Vec8 = float __attribute__((vector_size(32)));
constexpr std::size_t kLanes = 8;

/// @p v in every lane of T.
template <typename T>
MAF_INLINE T splat(float v)
{
  return T{} + v;
}

/// Per-lane mask ? a : b.
template <typename M, typename T>
MAF_INLINE T select(M mask, T a, T b)
{
  return mask ? a : b;
}

template <typename T>
MAF_INLINE T load(const float* p);
template <>
MAF_INLINE float load<float>(const float* p)
{
  return *p;
}
template <>
MAF_INLINE Vec8 load<Vec8>(const float* p)
{
  Vec8 v;
  __builtin_memcpy(&v, p, sizeof v);
  return v;
}
MAF_INLINE void store(float* p, float v) { *p = v; }
MAF_INLINE void store(float* p, Vec8 v) { __builtin_memcpy(p, &v, sizeof v); }

/// Stores class codes held as floats (small integers) as bytes.
MAF_INLINE void storeClass(std::int8_t* p, float v) { *p = static_cast<std::int8_t>(v); }
MAF_INLINE void storeClass(std::int8_t* p, Vec8 v)
{
  using Vec8i = int __attribute__((vector_size(32)));
  using Vec8b = signed char __attribute__((vector_size(8)));
  const Vec8b b = __builtin_convertvector(__builtin_convertvector(v, Vec8i), Vec8b);
  __builtin_memcpy(p, &b, sizeof b);
}

/// Floats between two slots of one MapGrid cell (the cells of a block are consecutive).
constexpr std::size_t kSlotStride = MapMassGrid::kBlockCells;
static_assert(MapMassGrid::kInterleaved && MapMassGrid::kBlockCells == 8, "one Vec8 per slot of a block");

/// Where cell @p i of the MapGrid whose first float is @p base starts (slot s is kSlotStride · s further): for a
/// Vec8, @p i is a multiple of eight and the block's slots are consecutive vectors.
MAF_INLINE float* cellAt(float* base, std::size_t i) { return base + MapMassGrid::blockOffset(i); }
MAF_INLINE const float* cellAt(const float* base, std::size_t i) { return base + MapMassGrid::blockOffset(i); }
/// ζ of cell @p i.
MAF_INLINE float* zetaAt(float* base, std::size_t i) { return cellAt(base, i) + kMapPlanes * kSlotStride; }

/// m[a] of cell @p i of a MapGrid; a subset the grid does not store is a compile-time zero, so the arithmetic on
/// it folds away where the translation unit allows it.
template <typename T>
MAF_INLINE void loadMasses(const float* base, std::size_t i, T (&m)[kSubsets])
{
  const float* cell = cellAt(base, i);
  MAF_UNROLL
  for (int a = 0; a < kSubsets; ++a)
    m[a] = MapMassGrid::kSlots[a] >= 0 ? load<T>(cell + MapMassGrid::kSlots[a] * kSlotStride) : T{};
}

/// Stores the stored subsets of @p m (the others must be zero: they are not kept).
template <typename T>
MAF_INLINE void storeMasses(float* base, std::size_t i, const T (&m)[kSubsets])
{
  float* cell = cellAt(base, i);
  MAF_UNROLL
  for (int a = 0; a < kSubsets; ++a)
    if (MapMassGrid::kSlots[a] >= 0) store(cell + MapMassGrid::kSlots[a] * kSlotStride, m[a]);
}

/**
 * Masses at or below this are set to 0 by the rounding hygiene (what they held goes to Ω with the rounding drift).
 * Evidence that no new scan supports decays geometrically (discounting, specialisation); without a floor a static
 * scene leaves a few per cent of the masses subnormal after some 300 scans, and float arithmetic on subnormals is
 * slower by tens of times on x86 (the fused step took 18× as long). 1e-20 is far below any decision and far above
 * the subnormal range (1.2e-38), so that the step's products of a mass with the scan's and prior's stay normal.
 */
constexpr float kMassFloor = 1e-20f;

/// v where v > kMassFloor, else 0 (negative rounding residue included). One conditional expression: a compare and
/// an and.
template <typename T>
MAF_INLINE T significantPart(T v)
{
  const T zero{};
  return v > kMassFloor ? v : zero;
}

/// Sum of the lanes.
MAF_INLINE float horizontalSum(float v) { return v; }
MAF_INLINE float horizontalSum(Vec8 v)
{
  float s = 0.0f;
  for (std::size_t l = 0; l < kLanes; ++l) s += v[l];
  return s;
}

/**
 * Runs body(T{}, i) over cells [0, n): with T = Vec8 for whole groups of eight cells (one block of the MapGrid),
 * then T = float for the rest. The MapGrid's blocks are one stream, which the hardware prefetchers follow.
 */
template <class Body>
MAF_INLINE void forEachCell(std::size_t n, Body&& body)
{
  std::size_t i = 0;
  for (; i + kLanes <= n; i += kLanes) body(Vec8{}, i);
  for (; i < n; ++i) body(float{}, i);
}

/// The nine focal sets r(m_SG) ⊕ m_PG can have: intersections of {F, O, Ω} with {B, R, T, W, Ω}.
enum ScanPriorIndex
{
  kSpF,
  kSpC,
  kSpSV,
  kSpNSV,
  kSpCNSV,
  kSpFSV,
  kSpFNSV,
  kSpOmega,
  kSpFC,
  kNumScanPrior
};
constexpr std::array<Subset, kNumScanPrior> kScanPriorSets{
  FrameMG::kF,           FrameMG::kC,      FrameMG::kS | FrameMG::kV, FrameMG::kN | FrameMG::kS | FrameMG::kV,
  FrameMG::kO,           FrameMG::kRoad,   FrameMG::kOther,           FrameMG::kOmega,
  FrameMG::kWall
};

constexpr std::array<int, kSubsets> makeOpenTable()
{
  std::array<int, kSubsets> t{};
  for (int a = 0; a < kSubsets; ++a) t[a] = openContexts(static_cast<Subset>(a));
  return t;
}
constexpr std::array<int, kSubsets> kOpen = makeOpenTable();

constexpr std::array<int, 8> makeUnionTable()
{
  std::array<int, 8> t{};
  for (int s = 0; s < 8; ++s) t[s] = contextUnion(s);
  return t;
}
constexpr std::array<int, 8> kUnion = makeUnionTable();

constexpr bool isOccupiedSet(int a) { return a != 0 && isSubsetOf(static_cast<Subset>(a), FrameMG::kO); }

/// ContextualDiscountWeights splatted to eight lanes, so that each product takes its weight from memory.
struct ContextualDiscountWeights8
{
  Vec8 w[8][8];
  explicit ContextualDiscountWeights8(const ContextualDiscountWeights<float>& f)
  {
    for (int o = 0; o < 8; ++o)
      for (int s = 0; s < 8; ++s) w[o][s] = splat<Vec8>(f.w[o][s]);
  }
};

/// The weights for lane type T: eight-lane weights for Vec8, plain ones otherwise.
template <typename T>
MAF_INLINE const ContextualDiscountWeights8& weightsFor(const ContextualDiscountWeights<float>&,
                                                         const ContextualDiscountWeights8& w8, Vec8)
{
  return w8;
}
template <typename T>
MAF_INLINE const ContextualDiscountWeights<float>& weightsFor(const ContextualDiscountWeights<float>& w,
                                                               const ContextualDiscountWeights8&, float)
{
  return w;
}

/// m ← contextual discount of m (closed form, see ContextualDiscountWeights).
template <typename T, typename Weights>
MAF_INLINE void contextualDiscount(T (&m)[kSubsets], const Weights& w)
{
  T out[kSubsets];
  MAF_UNROLL
  for (int a = 0; a < kSubsets; ++a) out[a] = T{};
  MAF_UNROLL
  for (int a = 0; a < kSubsets; ++a)
  {
    MAF_UNROLL
    for (int s = 0; s < 8; ++s)
      if ((s & ~kOpen[a]) == 0) out[a | kUnion[s]] += m[a] * w.w[kOpen[a]][s];
  }
  MAF_UNROLL
  for (int a = 0; a < kSubsets; ++a) m[a] = out[a];
}

/**
 * r(m_SG) ⊕ m_PG in the nine sets of kScanPriorSets, from m_SG(F), m_SG(O), m_SG(Ω) and the prior
 * masses m_PG(B), m_PG(R), m_PG(T), m_PG(W). Total conflict gives the vacuous mass function. Returns the
 * Dempster conflict K.
 */
template <typename T>
MAF_INLINE T scanWithPrior(T sf, T so, T somega, T pb, T pr, T pt, T pw, T (&sp)[kNumScanPrior],
                           float total_conflict_threshold)
{
  const T one = splat<T>(1.0f), zero = T{};
  const T pomega = one - pb - pr - pt - pw;
  const T k = pb * sf;
  const T norm = one - k;
  const auto total = norm < total_conflict_threshold;
  const T inv = select(total, zero, one / norm);
  sp[kSpF] = sf * (pr + pt + pw + pomega) * inv;
  sp[kSpC] = (pb * (so + somega) + pw * so) * inv;
  sp[kSpFC] = pw * somega * inv;
  sp[kSpSV] = pr * so * inv;
  sp[kSpNSV] = pt * so * inv;
  sp[kSpCNSV] = pomega * so * inv;
  sp[kSpFSV] = pr * somega * inv;
  sp[kSpFNSV] = pt * somega * inv;
  sp[kSpOmega] = select(total, one, pomega * somega * inv);
  return k;
}

/**
 * The step "map conflict" on one cell (see MapGridParams::map_conflict_gain): the doubt @p eta grows by
 * @p gain · (K − A), K = m_PG(B)·m_SG(F), A = (m_PG(B) + m_PG(W))·m_SG(O), clamped to [0, 1], and the prior masses
 * are discounted by it (what they lose goes to Ω). Written so that it vectorises.
 */
template <typename T>
MAF_INLINE void mapConflict(T sf, T so, float gain, T& eta, T& pb, T& pr, T& pt, T& pw)
{
  const T zero{}, one = splat<T>(1.0f);
  const T k = pb * sf;
  const T a = (pb + pw) * so;
  const T raw = eta + gain * (k - a);
  const T low = raw < zero ? zero : raw;
  eta = one < low ? one : low;
  const T keep = one - eta;
  pb *= keep;
  pr *= keep;
  pt *= keep;
  pw *= keep;
}

/// CombinationRule as int, for the kernels.
constexpr int kRuleModifiedYager = 0;
constexpr int kRuleYager = 1;
constexpr int kRuleDempster = 2;

/// Classical discounting: m ← (1 − α) m, m(Ω) += α.
template <typename T>
MAF_INLINE void classicalDiscount(T (&m)[kSubsets], float alpha)
{
  MAF_UNROLL
  for (int a = 0; a < kSubsets; ++a) m[a] *= 1.0f - alpha;
  m[FrameMG::kOmega] += alpha;
}

/// Conflicts met by ⊛ for one cell.
template <typename T>
struct CellConflicts
{
  T free_occupied;
  T occupied_free;
  T other;
};

/**
 * g_out(A) = g_in(A) + g_in(A ∪ {b}) for every A ⊆ S ∖ {b}: turns the marginal of m on the subsets of S
 * (g(A) = Σ_{X ∩ S = A} m(X)) into its marginal on the subsets of S ∖ {b}.
 */
template <int S, int B, typename T>
MAF_INLINE void dropElement(const T (&in)[kSubsets], T (&out)[kSubsets])
{
  MAF_UNROLL
  for (int a = 0; a < kSubsets; ++a)
    if (isSubsetOf(static_cast<Subset>(a), static_cast<Subset>(S & ~B))) out[a] = in[a] + in[a | B];
}

/// c[A] += w · g[A] for every A ⊆ S.
template <int S, typename T>
MAF_INLINE void accumulateOn(const T (&g)[kSubsets], T w, T (&c)[kSubsets])
{
  MAF_UNROLL
  for (int a = 0; a < kSubsets; ++a)
    if (isSubsetOf(static_cast<Subset>(a), static_cast<Subset>(S))) c[a] += w * g[a];
}

/**
 * c = m ∩ sp (unnormalised, c[∅] is the conflict) for sp in the sets of kScanPriorSets, through the
 * marginals of m on each focal set S_k: (m ∩ sp)(A) = Σ_k sp_k · Σ_{X ∩ S_k = A} m(X). The marginals
 * are built one dropped element at a time and shared between nested sets. kWall: sp may hold mass on W.
 */
template <bool kWall, typename T>
MAF_INLINE void conjunctiveWithScanPrior(const T (&m)[kSubsets], const T (&sp)[kNumScanPrior], T (&c)[kSubsets])
{
  constexpr int F = FrameMG::kF, C = FrameMG::kC, N = FrameMG::kN, S = FrameMG::kS, V = FrameMG::kV;
  constexpr int W = FrameMG::kOmega;
  MAF_UNROLL
  for (int a = 0; a < kSubsets; ++a) c[a] = m[a] * sp[kSpOmega];
  T fnsv[kSubsets], fsv[kSubsets], fv[kSubsets], f[kSubsets];
  dropElement<W, C>(m, fnsv);
  accumulateOn<F | N | S | V>(fnsv, sp[kSpFNSV], c);
  dropElement<F | N | S | V, N>(fnsv, fsv);
  accumulateOn<F | S | V>(fsv, sp[kSpFSV], c);
  dropElement<F | S | V, S>(fsv, fv);
  dropElement<F | V, V>(fv, f);
  accumulateOn<F>(f, sp[kSpF], c);
  T cnsv[kSubsets], nsv[kSubsets], sv[kSubsets], csv[kSubsets], cv[kSubsets], cc[kSubsets];
  dropElement<W, F>(m, cnsv);
  accumulateOn<C | N | S | V>(cnsv, sp[kSpCNSV], c);
  dropElement<C | N | S | V, C>(cnsv, nsv);
  accumulateOn<N | S | V>(nsv, sp[kSpNSV], c);
  dropElement<N | S | V, N>(nsv, sv);
  accumulateOn<S | V>(sv, sp[kSpSV], c);
  dropElement<C | N | S | V, N>(cnsv, csv);
  dropElement<C | S | V, S>(csv, cv);
  dropElement<C | V, V>(cv, cc);
  accumulateOn<C>(cc, sp[kSpC], c);
  if (kWall)
  {
    T fcsv[kSubsets], fcv[kSubsets], fc[kSubsets];
    dropElement<W, N>(m, fcsv);
    dropElement<F | C | S | V, S>(fcsv, fcv);
    dropElement<F | C | V, V>(fcv, fc);
    accumulateOn<F | C>(fc, sp[kSpFC], c);
  }
}

/**
 * m ← m ⊛ sp (sp in the sets of kScanPriorSets), the modified Yager rule; returns the conflicts. With
 * @p building_conflict (step building conflict) the part of ∅_FO met by sp({C}) goes to Ω instead of V.
 */
template <bool kWall, typename T>
MAF_INLINE CellConflicts<T> modifiedYager(T (&m)[kSubsets], const T (&sp)[kNumScanPrior], int rule = 0,
                                          bool building_conflict = false)
{
  T c[kSubsets];
  conjunctiveWithScanPrior<kWall>(m, sp, c);
  T map_occupied = T{};
  MAF_UNROLL
  for (int a = 1; a < kSubsets; ++a)
    if (isOccupiedSet(a)) map_occupied += m[a];
  const T scan_occupied = sp[kSpC] + sp[kSpSV] + sp[kSpNSV] + sp[kSpCNSV];
  CellConflicts<T> r;
  r.free_occupied = m[FrameMG::kF] * scan_occupied;
  r.occupied_free = map_occupied * sp[kSpF];
  r.other = c[0] - r.free_occupied - r.occupied_free;
  if (rule == kRuleModifiedYager)
  {
    const T to_v = building_conflict ? m[FrameMG::kF] * (sp[kSpSV] + sp[kSpNSV] + sp[kSpCNSV]) : r.free_occupied;
    c[FrameMG::kV] += to_v;
    c[FrameMG::kOmega] += c[0] - to_v;
  }
  else if (rule == kRuleYager)
  {
    c[FrameMG::kOmega] += c[0];
  }
  else
  {
    const T one = splat<T>(1.0f), zero{};
    const T norm = one - c[0];
    const auto total = norm < splat<T>(1e-12f);
    const T inv = select(total, zero, one / norm);
    MAF_UNROLL
    for (int a = 1; a < kSubsets; ++a) c[a] *= inv;
    c[FrameMG::kOmega] += select(total, one, zero);
  }
  c[0] = T{};
  MAF_UNROLL
  for (int a = 0; a < kSubsets; ++a) m[a] = c[a];
  return r;
}

/// BetP of each element of Ω_MG (F, C, N, S, V); uniform where m(∅) = 1.
template <typename T>
MAF_INLINE void pignistic(const T (&m)[kSubsets], T (&p)[FrameMG::kSize])
{
  MAF_UNROLL
  for (int e = 0; e < FrameMG::kSize; ++e) p[e] = T{};
  MAF_UNROLL
  for (int a = 1; a < kSubsets; ++a)
  {
    const T share = m[a] * (1.0f / cardinality(static_cast<Subset>(a)));
    MAF_UNROLL
    for (int e = 0; e < FrameMG::kSize; ++e)
      if (a & (1 << e)) p[e] += share;
  }
  const T one = splat<T>(1.0f), zero{};
  const T norm = one - m[0];
  const auto none = norm <= zero;
  const T inv = select(none, zero, one / norm);
  const T uniform = select(none, splat<T>(1.0f / FrameMG::kSize), zero);
  MAF_UNROLL
  for (int e = 0; e < FrameMG::kSize; ++e) p[e] = p[e] * inv + uniform;
}

/**
 * Rounding hygiene once per step: negative masses (float rounding, ~1e-8) and masses at or below kMassFloor are
 * set to 0 and what the cell lacks or has in excess of 1 goes to Ω, so that 10^5 steps do not drift from a mass
 * function nor decay into subnormal floats. The drift is rounding (|Σm − 1| ~ 1e-7 per step), so moving it to
 * ignorance changes no decision; it costs a compare, an and and an add per subset. A cell with no ignorance left
 * (m(Ω) would go negative) has its other masses scaled by 1/Σ.
 */
template <typename T>
MAF_INLINE void renormalise(T (&m)[kSubsets])
{
  const T zero{};
  T sum = zero;
  MAF_UNROLL
  for (int a = 0; a < kSubsets; ++a)
  {
    m[a] = significantPart(m[a]);
    sum += m[a];
  }
  const T one = splat<T>(1.0f);
  const T others = sum - m[kSubsets - 1];
  const T omega = m[kSubsets - 1] + (one - sum);
  m[kSubsets - 1] = select(omega > zero, omega, zero);
  // Rounding excess in a cell without ignorance (m(Ω) would go negative, rare): scale the rest down instead.
  if (horizontalSum(select(omega < zero, one, zero)) == 0.0f) return;
  const T scale = select(omega < zero, one / select(others > zero, others, one), one);
  MAF_UNROLL
  for (int a = 0; a < kSubsets - 1; ++a) m[a] *= scale;
}

/// m(Ω) from which a cell counts as vacuous (never observed): no decision.
constexpr float kVacuousTolerance = 1e-3f;

/**
 * The decision of a cell (a CellClass code, as T) from its BetP @p p and m(Ω) (see decide() in map_grid.hpp): the
 * class of largest BetP (the first on ties) when it reaches the threshold and the cell is not vacuous, else kUnknown;
 * with the motion margin, S or V decisions within the margin of each other, and observed cells no class decides but
 * whose occupied BetP reaches the threshold, are kOccupied.
 */
template <typename T>
MAF_INLINE T decideCell(const T (&p)[FrameMG::kSize], T omega, const DecisionRule& rule)
{
  T best_p = p[0];
  T best = T{};
  MAF_UNROLL
  for (int e = 1; e < FrameMG::kSize; ++e)
  {
    const auto better = p[e] > best_p;
    best_p = select(better, p[e], best_p);
    best = select(better, splat<T>(static_cast<float>(e)), best);
  }
  const auto observed = omega < 1.0f - kVacuousTolerance;
  const auto known = observed & (best_p >= rule.threshold);
  const T d = select(known, best, splat<T>(static_cast<float>(CellClass::kUnknown)));
  if (!rule.motion_margin) return d;
  constexpr int kS = FrameMG::kSize - 2, kV = FrameMG::kSize - 1;
  const auto motion = (best == static_cast<float>(CellClass::kStopped)) | (best == static_cast<float>(CellClass::kMoving));
  // |BetP(S) − BetP(V)| < margin, both differences being exact negatives of each other.
  const auto tie = known & motion & (p[kS] - p[kV] < rule.margin) & (p[kV] - p[kS] < rule.margin);
  const auto unclassified = (known == 0) & observed & (1.0f - p[0] >= rule.threshold);
  return select(tie | unclassified, splat<T>(static_cast<float>(CellClass::kOccupied)), d);
}

/// A cell motion spreading counts as moving: BetP(V) @p pv ≥ @p threshold and above BetP(S) @p ps by more than
/// @p margin.
template <typename T>
MAF_INLINE auto isMoving(T pv, T ps, float threshold, float margin)
{
  return (pv >= threshold) & (pv - ps > margin);
}

/// A cell that seeds motion spreading (see spreadMotion()): moving, and the scan sees it occupied (@p so > 0).
template <typename T>
MAF_INLINE auto isMovingSeed(T so, T pv, T ps, float threshold, float margin)
{
  return (so > 0.0f) & isMoving(pv, ps, threshold, margin);
}

/// Mass on the non-empty subsets of {C, N, S, V}.
template <typename T>
MAF_INLINE T occupiedMass(const T (&m)[kSubsets])
{
  T s = T{};
  MAF_UNROLL
  for (int a = 1; a < kSubsets; ++a)
    if (isOccupiedSet(a)) s += m[a];
  return s;
}

/// Equation 3.
template <typename T>
MAF_INLINE T updateCounter(T zeta, T m_occupied, T conflict, float delta_inc, float delta_dec, float gamma_o,
                           float gamma_conflict)
{
  const T one = splat<T>(1.0f), zero = T{};
  const T inc = zeta + delta_inc;
  const T dec = zeta - delta_dec;
  const T up = inc < one ? inc : one;
  const T down = dec > zero ? dec : zero;
  return select(conflict > gamma_conflict, down, select(m_occupied >= gamma_o, up, zeta));
}

/// Step "moving expiry": where the scan holds no occupied mass, m({V}) moves to Ω (no object moves in a cell not
/// seen occupied now).
template <class T>
MAF_INLINE void expireMoving(T (&m)[kSubsets], T scan_occupied)
{
  const T zero{};
  const T expired = select(scan_occupied > zero, zero, m[FrameMG::kV]);
  m[FrameMG::kV] -= expired;
  m[FrameMG::kOmega] += expired;
}

/// Equation 4, in place; @p literal selects SpecialisationMode::kLiteral.
template <typename T>
MAF_INLINE void specialise(T (&m)[kSubsets], T zeta, bool literal)
{
  T moved_empty = T{};
  MAF_UNROLL
  for (int a = 0; a < kSubsets; ++a)
  {
    if (!(a & FrameMG::kV)) continue;
    const T t = zeta * m[a];
    m[a] -= t;
    if (a == FrameMG::kV)
    {
      if (literal)
        moved_empty = t;
      else
        m[FrameMG::kS] += t;
    }
    else
    {
      m[a & ~FrameMG::kV] += t;
    }
  }
  if (literal)
  {
    const T one = splat<T>(1.0f), zero = T{};
    const T norm = one - moved_empty;
    const auto total = norm <= zero;
    const T inv = select(total, zero, one / norm);
    MAF_UNROLL
    for (int a = 0; a < kSubsets; ++a) m[a] *= inv;
    m[FrameMG::kOmega] += select(total, one, zero);
  }
}

}  // namespace kernels
}  // namespace core
}  // namespace map_aided_fusion

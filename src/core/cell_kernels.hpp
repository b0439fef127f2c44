// Per-cell kernels on Ω_MG shared by the grid operations. Every index is a compile-time constant
// once the loops are unrolled, so a loop over cells that calls them vectorises across cells.
#pragma once

#include <array>

#include "map_aided_fusion/core/counter.hpp"
#include "map_aided_fusion/core/discounting.hpp"
#include "map_aided_fusion/core/frame.hpp"

#if defined(__GNUC__) && !defined(__clang__)
#define MAF_UNROLL _Pragma("GCC unroll 64")
#else
#define MAF_UNROLL _Pragma("unroll")
#endif
#if defined(__GNUC__)
#define MAF_INLINE inline __attribute__((always_inline))
#else
#define MAF_INLINE inline
#endif
// Whole-grid loops get an AVX2+FMA clone chosen at run time where the CPU has it.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(MAF_NO_TARGET_CLONES)
#define MAF_TARGET_CLONES __attribute__((target_clones("arch=x86-64-v3", "default")))
#else
#define MAF_TARGET_CLONES
#endif

namespace map_aided_fusion {
namespace core {
namespace kernels {

constexpr int kSubsets = FrameMG::kNumSubsets;

/// The eight focal sets r(m_SG) ⊕ m_PG can have: intersections of {F, O, Ω} with {B, R, T, Ω}.
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
  kNumScanPrior
};
constexpr std::array<Subset, kNumScanPrior> kScanPriorSets{
  FrameMG::kF,           FrameMG::kC,      FrameMG::kS | FrameMG::kV, FrameMG::kN | FrameMG::kS | FrameMG::kV,
  FrameMG::kO,           FrameMG::kRoad,   FrameMG::kOther,           FrameMG::kOmega
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

/// m ← contextual discount of m (closed form, see ContextualDiscountWeights).
template <typename T>
MAF_INLINE void contextualDiscount(T (&m)[kSubsets], const ContextualDiscountWeights<T>& w)
{
  T out[kSubsets];
  MAF_UNROLL
  for (int a = 0; a < kSubsets; ++a) out[a] = T(0);
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
 * r(m_SG) ⊕ m_PG in the eight sets of kScanPriorSets, from m_SG(F), m_SG(O), m_SG(Ω) and the prior
 * masses m_PG(B), m_PG(R), m_PG(T). Total conflict gives the vacuous mass function. Returns the
 * Dempster conflict K.
 */
template <typename T>
MAF_INLINE T scanWithPrior(T sf, T so, T somega, T pb, T pr, T pt, T (&sp)[kNumScanPrior], T total_conflict_threshold)
{
  const T pomega = T(1) - pb - pr - pt;
  const T k = pb * sf;
  const T norm = T(1) - k;
  const bool total = norm < total_conflict_threshold;
  const T inv = total ? T(0) : T(1) / norm;
  sp[kSpF] = sf * (pr + pt + pomega) * inv;
  sp[kSpC] = pb * (so + somega) * inv;
  sp[kSpSV] = pr * so * inv;
  sp[kSpNSV] = pt * so * inv;
  sp[kSpCNSV] = pomega * so * inv;
  sp[kSpFSV] = pr * somega * inv;
  sp[kSpFNSV] = pt * somega * inv;
  sp[kSpOmega] = total ? T(1) : pomega * somega * inv;
  return k;
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
 * m ← m ⊛ sp (sp in the sets of kScanPriorSets), the modified Yager rule; returns the conflicts.
 */
template <typename T>
MAF_INLINE CellConflicts<T> modifiedYager(T (&m)[kSubsets], const T (&sp)[kNumScanPrior])
{
  T c[kSubsets];
  MAF_UNROLL
  for (int a = 0; a < kSubsets; ++a) c[a] = T(0);
  MAF_UNROLL
  for (int a = 0; a < kSubsets; ++a)
  {
    MAF_UNROLL
    for (int k = 0; k < kNumScanPrior; ++k) c[a & kScanPriorSets[k]] += m[a] * sp[k];
  }
  T map_occupied = T(0);
  MAF_UNROLL
  for (int a = 1; a < kSubsets; ++a)
    if (isOccupiedSet(a)) map_occupied += m[a];
  const T scan_occupied = sp[kSpC] + sp[kSpSV] + sp[kSpNSV] + sp[kSpCNSV];
  CellConflicts<T> r;
  r.free_occupied = m[FrameMG::kF] * scan_occupied;
  r.occupied_free = map_occupied * sp[kSpF];
  r.other = c[0] - r.free_occupied - r.occupied_free;
  c[FrameMG::kV] += r.free_occupied;
  c[FrameMG::kOmega] += c[0] - r.free_occupied;
  c[0] = T(0);
  MAF_UNROLL
  for (int a = 0; a < kSubsets; ++a) m[a] = c[a];
  return r;
}

/// Mass on the non-empty subsets of {C, N, S, V}.
template <typename T>
MAF_INLINE T occupiedMass(const T (&m)[kSubsets])
{
  T s = T(0);
  MAF_UNROLL
  for (int a = 1; a < kSubsets; ++a)
    if (isOccupiedSet(a)) s += m[a];
  return s;
}

/// Equation 3.
template <typename T>
MAF_INLINE T updateCounter(T zeta, T m_occupied, T conflict, T delta_inc, T delta_dec, T gamma_o, T gamma_conflict)
{
  const T inc = zeta + delta_inc;
  const T dec = zeta - delta_dec;
  const T up = inc < T(1) ? inc : T(1);
  const T down = dec > T(0) ? dec : T(0);
  return conflict > gamma_conflict ? down : (m_occupied >= gamma_o ? up : zeta);
}

/// Equation 4, in place; @p literal selects SpecialisationMode::kLiteral.
template <typename T>
MAF_INLINE void specialise(T (&m)[kSubsets], T zeta, bool literal)
{
  T moved_empty = T(0);
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
    const T norm = T(1) - moved_empty;
    const bool total = norm <= T(0);
    const T inv = total ? T(0) : T(1) / norm;
    MAF_UNROLL
    for (int a = 0; a < kSubsets; ++a) m[a] *= inv;
    m[FrameMG::kOmega] += total ? T(1) : T(0);
  }
}

}  // namespace kernels
}  // namespace core
}  // namespace map_aided_fusion

#include "map_aided_fusion/core/grid_ops.hpp"

#include <stdexcept>

#include "cell_kernels.hpp"
#include "map_aided_fusion/core/rules.hpp"

namespace map_aided_fusion {
namespace core {

using kernels::kSubsets;

namespace {

void requireSameGeometry(const GridGeometry& a, const GridGeometry& b, const char* what)
{
  if (a != b) throw std::invalid_argument(std::string(what) + ": grids of different geometry");
}

}  // namespace

MAF_TARGET_CLONES
void refineGrid(const ScanMassGrid& scan, MapMassGrid& out)
{
  if (out.geometry() != scan.geometry()) out.reset(scan.geometry());
  const std::size_t n = scan.numCells();
  const float* __restrict f = scan.plane(FrameSG::kF);
  const float* __restrict o = scan.plane(FrameSG::kO);
  const float* __restrict w = scan.plane(FrameSG::kOmega);
  // m_SG(∅) has no slot in a MapGrid; the fusion never reads it.
  float* __restrict base = out.planes();
  kernels::forEachCell(n, [&](auto lane, std::size_t i) MAF_LAMBDA_INLINE {
    using T = decltype(lane);
    using kernels::load;
    T m[kSubsets] = {};
    m[FrameMG::kF] = load<T>(f + i);
    m[FrameMG::kO] = load<T>(o + i);
    m[FrameMG::kOmega] = load<T>(w + i);
    kernels::storeMasses(base, i, m);
    kernels::store(kernels::zetaAt(base, i), T{});
  });
}

MAF_TARGET_CLONES
void combineWithPriorGrid(MapMassGrid& grid, const PriorWindow& prior)
{
  requireSameGeometry(grid.geometry(), prior.geometry, "combineWithPriorGrid");
  const std::size_t n = grid.numCells();
  float* __restrict base = grid.planes();
  const float* __restrict pb = prior.building.data();
  const float* __restrict pr = prior.road.data();
  const float* __restrict pt = prior.other.data();
  const float* __restrict pw = prior.wall.data();
  const float threshold = static_cast<float>(kTotalConflictThreshold);
  kernels::forEachCell(n, [&](auto lane, std::size_t i) MAF_LAMBDA_INLINE {
    using T = decltype(lane);
    using kernels::load;
    T m[kSubsets];
    kernels::loadMasses(base, i, m);
    const T b = load<T>(pb + i), r = load<T>(pr + i), t = load<T>(pt + i), wl = load<T>(pw + i);
    const T one = kernels::splat<T>(1.0f), zero{};
    const T u = one - b - r - t - wl;
    T c[kSubsets];
    MAF_UNROLL
    for (int a = 0; a < kSubsets; ++a) c[a] = u * m[a];
    MAF_UNROLL
    for (int a = 0; a < kSubsets; ++a)
    {
      c[a & FrameMG::kBuilding] += b * m[a];
      c[a & FrameMG::kRoad] += r * m[a];
      c[a & FrameMG::kOther] += t * m[a];
      c[a & FrameMG::kWall] += wl * m[a];
    }
    const T norm = one - c[0];
    const auto total = norm < threshold;
    const T inv = kernels::select(total, zero, one / norm);
    c[0] = zero;
    MAF_UNROLL
    for (int a = 0; a < kSubsets; ++a) c[a] *= inv;
    c[FrameMG::kOmega] += kernels::select(total, one, zero);
    kernels::storeMasses(base, i, c);
  });
}

MAF_TARGET_CLONES
void contextualDiscountGrid(MapMassGrid& grid, const ContextualRates& rates)
{
  const ContextualDiscountWeights<float> w(rates);
  const std::size_t n = grid.numCells();
  float* __restrict base = grid.planes();
  const kernels::ContextualDiscountWeights8 w8(w);
  kernels::forEachCell(n, [&](auto lane, std::size_t i) MAF_LAMBDA_INLINE {
    using T = decltype(lane);
    T m[kSubsets];
    kernels::loadMasses(base, i, m);
    kernels::contextualDiscount(m, kernels::weightsFor<T>(w, w8, lane));
    kernels::storeMasses(base, i, m);
  });
}

MAF_TARGET_CLONES
void modifiedYagerGrid(const MapMassGrid& map, const MapMassGrid& scan, MapMassGrid& out,
                       float* conflict_free_occupied, float* conflict_occupied_free)
{
  requireSameGeometry(map.geometry(), scan.geometry(), "modifiedYagerGrid");
  if (&out != &map && out.geometry() != map.geometry()) out.reset(map.geometry());
  const std::size_t n = map.numCells();
  const float* mb = map.planes();
  const float* sb = scan.planes();
  float* ob = out.planes();
  if (&out != &map)
    for (std::size_t i = 0; i < n; ++i) out.zeta(i) = map.zeta(i);
  kernels::forEachCell(n, [&](auto lane, std::size_t i) MAF_LAMBDA_INLINE {
    using T = decltype(lane);
    using kernels::load;
    T m1[kSubsets], m2[kSubsets], c[kSubsets];
    kernels::loadMasses(mb, i, m1);
    kernels::loadMasses(sb, i, m2);
    MAF_UNROLL
    for (int a = 0; a < kSubsets; ++a) c[a] = T{};
    MAF_UNROLL
    for (int a = 0; a < kSubsets; ++a)
    {
      MAF_UNROLL
      for (int b = 0; b < kSubsets; ++b) c[a & b] += m1[a] * m2[b];
    }
    const T fo = m1[FrameMG::kF] * kernels::occupiedMass(m2);
    const T of = kernels::occupiedMass(m1) * m2[FrameMG::kF];
    c[FrameMG::kV] += fo;
    c[FrameMG::kOmega] += c[0] - fo;
    c[0] = T{};
    kernels::storeMasses(ob, i, c);
    if (conflict_free_occupied) kernels::store(conflict_free_occupied + i, fo);
    if (conflict_occupied_free) kernels::store(conflict_occupied_free + i, of);
  });
}

MAF_TARGET_CLONES
void updateCounterAndSpecialiseGrid(MapMassGrid& grid, const float* conflict_free_occupied,
                                    const float* conflict_occupied_free, const CounterParams& params)
{
  params.validate();
  const std::size_t n = grid.numCells();
  float* __restrict base = grid.planes();
  const float di = static_cast<float>(params.delta_inc), dd = static_cast<float>(params.delta_dec);
  const float go = static_cast<float>(params.gamma_occupied), gc = static_cast<float>(params.gamma_conflict);
  const bool literal = params.mode == SpecialisationMode::kLiteral;
  kernels::forEachCell(n, [&](auto lane, std::size_t i) MAF_LAMBDA_INLINE {
    using T = decltype(lane);
    using kernels::load;
    T m[kSubsets];
    kernels::loadMasses(base, i, m);
    const T conflict = load<T>(conflict_free_occupied + i) + load<T>(conflict_occupied_free + i);
    float* const zeta = kernels::zetaAt(base, i);
    const T z = kernels::updateCounter(load<T>(zeta), kernels::occupiedMass(m), conflict, di, dd, go, gc);
    kernels::store(zeta, z);
    kernels::specialise(m, z, literal);
    kernels::storeMasses(base, i, m);
  });
}

MAF_TARGET_CLONES
void pignisticGrid(const MapMassGrid& grid, PignisticPlanes& out)
{
  const std::size_t n = grid.numCells();
  for (auto& p : out.p) p.resize(n);
  const float* __restrict base = grid.planes();
  float* __restrict p0 = out.p[0].data();
  float* __restrict p1 = out.p[1].data();
  float* __restrict p2 = out.p[2].data();
  float* __restrict p3 = out.p[3].data();
  float* __restrict p4 = out.p[4].data();
  kernels::forEachCell(n, [&](auto lane, std::size_t i) MAF_LAMBDA_INLINE {
    using T = decltype(lane);
    T m[kSubsets];
    kernels::loadMasses(base, i, m);
    T p[FrameMG::kSize];
    kernels::pignistic(m, p);
    kernels::store(p0 + i, p[0]);
    kernels::store(p1 + i, p[1]);
    kernels::store(p2 + i, p[2]);
    kernels::store(p3 + i, p[3]);
    kernels::store(p4 + i, p[4]);
  });
}

}  // namespace core
}  // namespace map_aided_fusion

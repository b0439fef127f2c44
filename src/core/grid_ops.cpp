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
  for (int a = 1; a < kSubsets; ++a)  // m_SG(∅) has no plane in a MapGrid; the fusion never reads it
  {
    if (!MapMassGrid::stored(static_cast<Subset>(a))) continue;
    float* __restrict dst = out.plane(static_cast<Subset>(a));
    const float* src = a == FrameMG::kF ? f : a == FrameMG::kO ? o : a == FrameMG::kOmega ? w : nullptr;
    if (src)
      std::copy(src, src + n, dst);
    else
      std::fill(dst, dst + n, 0.0f);
  }
  std::fill(out.counter(), out.counter() + n, 0.0f);
}

MAF_TARGET_CLONES
void combineWithPriorGrid(MapMassGrid& grid, const PriorWindow& prior)
{
  requireSameGeometry(grid.geometry(), prior.geometry, "combineWithPriorGrid");
  const std::size_t n = grid.numCells();
  const std::size_t stride = grid.stride();
  float* __restrict base = grid.planes();
  const float* __restrict pb = prior.building.data();
  const float* __restrict pr = prior.road.data();
  const float* __restrict pt = prior.other.data();
  const float* __restrict pw = prior.wall.data();
  const float threshold = static_cast<float>(kTotalConflictThreshold);
  kernels::forEachCell(n, base, stride, kernels::kMapPlanes, [&](auto lane, std::size_t i) MAF_LAMBDA_INLINE {
    using T = decltype(lane);
    using kernels::load;
    T m[kSubsets];
    kernels::loadMasses(base, stride, i, m);
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
    kernels::storeMasses(base, stride, i, c);
  });
}

MAF_TARGET_CLONES
void contextualDiscountGrid(MapMassGrid& grid, const ContextualRates& rates)
{
  const ContextualDiscountWeights<float> w(rates);
  const std::size_t n = grid.numCells();
  const std::size_t stride = grid.stride();
  float* __restrict base = grid.planes();
  const kernels::ContextualDiscountWeights8 w8(w);
  kernels::forEachCell(n, base, stride, kernels::kMapPlanes, [&](auto lane, std::size_t i) MAF_LAMBDA_INLINE {
    using T = decltype(lane);
    T m[kSubsets];
    kernels::loadMasses(base, stride, i, m);
    kernels::contextualDiscount(m, kernels::weightsFor<T>(w, w8, lane));
    kernels::storeMasses(base, stride, i, m);
  });
}

MAF_TARGET_CLONES
void modifiedYagerGrid(const MapMassGrid& map, const MapMassGrid& scan, MapMassGrid& out,
                       float* conflict_free_occupied, float* conflict_occupied_free)
{
  requireSameGeometry(map.geometry(), scan.geometry(), "modifiedYagerGrid");
  if (&out != &map && out.geometry() != map.geometry()) out.reset(map.geometry());
  const std::size_t n = map.numCells();
  const std::size_t stride = map.stride();
  const float* mb = map.planes();
  const float* sb = scan.planes();
  float* ob = out.planes();
  if (&out != &map) std::copy(map.counter(), map.counter() + n, out.counter());
  kernels::forEachCell(n, nullptr, stride, 0, [&](auto lane, std::size_t i) MAF_LAMBDA_INLINE {
    using T = decltype(lane);
    using kernels::load;
    T m1[kSubsets], m2[kSubsets], c[kSubsets];
    kernels::loadMasses(mb, stride, i, m1);
    kernels::loadMasses(sb, stride, i, m2);
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
    kernels::storeMasses(ob, stride, i, c);
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
  const std::size_t stride = grid.stride();
  float* __restrict base = grid.planes();
  float* __restrict zeta = grid.counter();
  const float di = static_cast<float>(params.delta_inc), dd = static_cast<float>(params.delta_dec);
  const float go = static_cast<float>(params.gamma_occupied), gc = static_cast<float>(params.gamma_conflict);
  const bool literal = params.mode == SpecialisationMode::kLiteral;
  kernels::forEachCell(n, base, stride, kernels::kMapPlanes + 1, [&](auto lane, std::size_t i) MAF_LAMBDA_INLINE {
    using T = decltype(lane);
    using kernels::load;
    T m[kSubsets];
    kernels::loadMasses(base, stride, i, m);
    const T conflict = load<T>(conflict_free_occupied + i) + load<T>(conflict_occupied_free + i);
    const T z = kernels::updateCounter(load<T>(zeta + i), kernels::occupiedMass(m), conflict, di, dd, go, gc);
    kernels::store(zeta + i, z);
    kernels::specialise(m, z, literal);
    kernels::storeMasses(base, stride, i, m);
  });
}

MAF_TARGET_CLONES
void pignisticGrid(const MapMassGrid& grid, PignisticPlanes& out)
{
  const std::size_t n = grid.numCells();
  const std::size_t stride = grid.stride();
  for (auto& p : out.p) p.resize(n);
  const float* __restrict base = grid.planes();
  float* __restrict p0 = out.p[0].data();
  float* __restrict p1 = out.p[1].data();
  float* __restrict p2 = out.p[2].data();
  float* __restrict p3 = out.p[3].data();
  float* __restrict p4 = out.p[4].data();
  kernels::forEachCell(n, base, stride, kernels::kMapPlanes, [&](auto lane, std::size_t i) MAF_LAMBDA_INLINE {
    using T = decltype(lane);
    T m[kSubsets];
    kernels::loadMasses(base, stride, i, m);
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

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "map_aided_fusion/core/fusion.hpp"
#include "map_aided_fusion/core/grid_ops.hpp"
#include "map_aided_fusion/core/pignistic.hpp"
#include "test_util.hpp"

using namespace map_aided_fusion::core;
using maf_test::isValidMass;
using maf_test::massNear;
using maf_test::randomMass;

namespace {

constexpr double kFloatTolerance = 2e-5;

/// An odd-sized geometry so that vector loops have a remainder.
GridGeometry testGeometry() { return GridGeometry{ 0.5, 37, 23, -3.0, 4.5 }; }

MapMassGrid randomMapGrid(std::mt19937& rng, const GridGeometry& g, bool with_counter = true)
{
  MapMassGrid grid(g);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (std::size_t i = 0; i < grid.numCells(); ++i)
  {
    grid.setCell(i, randomMass<FrameMG>(rng, 8, false, true));
    if (with_counter) grid.zeta(i) = static_cast<float>(u(rng));
  }
  return grid;
}

ScanMassGrid randomScanGrid(std::mt19937& rng, const GridGeometry& g)
{
  ScanMassGrid grid(g);
  for (std::size_t i = 0; i < grid.numCells(); ++i)
  {
    auto m = randomMass<FrameSG>(rng, 3);
    if (i % 7 == 0) m = MassSG{ { FrameSG::kF, 1.0 } };  // certain free: total conflict on buildings
    grid.setCell(i, m);
  }
  return grid;
}

/// Equation 1's classes at random and, with @p walls, outline cells m({F, C}) = β_B and mixed cells (coverage).
PriorWindow randomPrior(std::mt19937& rng, const GridGeometry& g, const PriorConfidence& beta, bool walls = true)
{
  PriorWindow p(g);
  std::uniform_int_distribution<int> cls(0, kNumPriorClasses + (walls ? 1 : -1));
  std::uniform_real_distribution<float> share(0.0f, 1.0f);
  for (std::size_t i = 0; i < g.numCells(); ++i)
  {
    const int k = cls(rng);
    if (k == kNumPriorClasses)
    {
      p.wall[i] = static_cast<float>(beta.beta_building);
      continue;
    }
    if (k == kNumPriorClasses + 1)
    {
      const float a = share(rng);
      p.road[i] = static_cast<float>(beta.beta_road) * a;
      p.other[i] = static_cast<float>(beta.beta_other) * (1.0f - a);
      continue;
    }
    const auto c = static_cast<PriorClass>(k);
    const auto m = priorMass(c, beta);
    p.building[i] = static_cast<float>(m[FrameMG::kBuilding]);
    p.road[i] = static_cast<float>(m[FrameMG::kRoad]);
    p.other[i] = static_cast<float>(m[FrameMG::kOther]);
  }
  return p;
}

}  // namespace

TEST(GridGeometry, WorldCellRoundTripAndRowMajorIndex)
{
  const GridGeometry g{ 0.25, 40, 20, -5.0, -2.5 };
  EXPECT_NO_THROW(g.validate());
  CellIndex c;
  ASSERT_TRUE(g.worldToCell(Point2{ -5.0, -2.5 }, c));
  EXPECT_EQ(c, (CellIndex{ 0, 0 }));
  ASSERT_TRUE(g.worldToCell(Point2{ 4.99, 2.49 }, c));
  EXPECT_EQ(c, (CellIndex{ 39, 19 }));
  EXPECT_FALSE(g.worldToCell(Point2{ 5.0, 0.0 }, c));
  EXPECT_FALSE(g.worldToCell(Point2{ -5.01, 0.0 }, c));
  EXPECT_FALSE(g.worldToCell(Point2{ std::nan(""), 0.0 }, c));
  for (int y = 0; y < g.height; ++y)
    for (int x = 0; x < g.width; ++x)
    {
      const auto p = g.cellCentre(CellIndex{ x, y });
      ASSERT_TRUE(g.worldToCell(p, c));
      EXPECT_EQ(c, (CellIndex{ x, y }));
      EXPECT_EQ(g.index(c), static_cast<std::size_t>(y * g.width + x));
      EXPECT_EQ(g.cellOf(g.index(c)), c);
    }
  const auto centred = GridGeometry::centred(100.0, 100.0, 0.5);
  EXPECT_EQ(centred.width, 200);
  EXPECT_DOUBLE_EQ(centred.origin_x, -50.0);
  EXPECT_THROW((GridGeometry{ 0.0, 10, 10, 0, 0 }.validate()), ParameterError);
  EXPECT_THROW((GridGeometry{ 0.5, 0, 10, 0, 0 }.validate()), ParameterError);
}

TEST(MassGrid, MapGridBlocksInterleaveEverySlotAndStartVacuous)
{
  MapMassGrid grid(testGeometry());
  EXPECT_EQ(MapMassGrid::kNumPlanes, 29) << "the reachable focal sets (ReachableFocalSets)";
  EXPECT_EQ(ScanMassGrid::kNumPlanes, 4);
  EXPECT_EQ(MapMassGrid::kBlockCells, 8u);
  EXPECT_EQ(MapMassGrid::kBlockFloats, 8u * 30u) << "29 masses and zeta per cell";
  EXPECT_EQ(grid.stride(), 8u);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(grid.planes()) % 64, 0u);
  EXPECT_EQ(MapMassGrid::kBlockFloats * sizeof(float) % 64, 0u) << "every block starts on a cache line";
  const std::size_t n = grid.numCells();
  EXPECT_EQ(grid.bytes(), (n + 7) / 8 * 240 * sizeof(float)) << "whole blocks: the last one padded";
  int slots = 0;
  for (int a = 0; a < 32; ++a)
  {
    if (!MapMassGrid::stored(static_cast<Subset>(a)))
    {
      EXPECT_THROW(grid.at(static_cast<Subset>(a), 0), std::out_of_range) << a;
      continue;
    }
    const int s = slots++;
    EXPECT_EQ(MapMassGrid::slot(static_cast<Subset>(a)), s);
    for (std::size_t i : { std::size_t{ 0 }, std::size_t{ 7 }, std::size_t{ 8 }, std::size_t{ 13 }, n - 1 })
      EXPECT_EQ(&grid.at(static_cast<Subset>(a), i), grid.planes() + (i / 8) * 240 + s * 8 + i % 8) << a << " " << i;
  }
  for (std::size_t i : { std::size_t{ 0 }, std::size_t{ 9 }, n - 1 })
    EXPECT_EQ(&grid.zeta(i), grid.planes() + (i / 8) * 240 + 29 * 8 + i % 8) << i;
  EXPECT_FALSE(MapMassGrid::stored(0));
  EXPECT_FALSE(MapMassGrid::stored(FrameMG::kC | FrameMG::kV));
  EXPECT_FALSE(MapMassGrid::stored(FrameMG::kF | FrameMG::kC | FrameMG::kV));
  EXPECT_THROW(grid.setCell(0, MassMG{ { FrameMG::kC | FrameMG::kV, 0.5 }, { FrameMG::kOmega, 0.5 } }),
               std::invalid_argument);
  for (std::size_t i = 0; i < n; ++i)
  {
    EXPECT_TRUE(massNear(grid.cell(i), MassMG::vacuous(), 0.0));
    EXPECT_EQ(grid.zeta(i), 0.0f);
  }
  // A ScanGrid stays planar: one aligned plane per subset.
  ScanMassGrid scan(testGeometry());
  for (int a = 0; a < 4; ++a)
  {
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(scan.plane(static_cast<Subset>(a))) % 64, 0u);
    EXPECT_EQ(&scan.at(static_cast<Subset>(a), 5), scan.plane(static_cast<Subset>(a)) + 5);
  }
}

TEST(GridOps, RefineMatchesScalar)
{
  std::mt19937 rng(1);
  const auto scan = randomScanGrid(rng, testGeometry());
  MapMassGrid out;
  refineGrid(scan, out);
  for (std::size_t i = 0; i < scan.numCells(); ++i) ASSERT_TRUE(massNear(out.cell(i), refine(scan.cell(i)), 1e-7));
}

TEST(GridOps, PriorDempsterMatchesScalar)
{
  std::mt19937 rng(2);
  const PriorConfidence beta{ 1.0, 0.85, 0.7 };  // β_B = 1: total conflict with certain free cells
  const auto scan = randomScanGrid(rng, testGeometry());
  const auto prior = randomPrior(rng, testGeometry(), beta);
  MapMassGrid grid;
  refineGrid(scan, grid);
  combineWithPriorGrid(grid, prior);
  for (std::size_t i = 0; i < grid.numCells(); ++i)
  {
    const auto expected = dempster(refine(scan.cell(i)), prior.cell(i));
    ASSERT_TRUE(massNear(grid.cell(i), expected, kFloatTolerance)) << "cell " << i;
    ASSERT_TRUE(isValidMass(grid.cell(i), kFloatTolerance));
  }
}

TEST(GridOps, ContextualDiscountMatchesScalar)
{
  std::mt19937 rng(3);
  auto grid = randomMapGrid(rng, testGeometry());
  const auto before = grid;
  const ContextualRates rates{ 0.05, 0.3, 0.15 };
  contextualDiscountGrid(grid, rates);
  for (std::size_t i = 0; i < grid.numCells(); ++i)
    ASSERT_TRUE(massNear(grid.cell(i), contextualDiscount(before.cell(i), rates), kFloatTolerance));
}

TEST(GridOps, ModifiedYagerMatchesScalar)
{
  std::mt19937 rng(4);
  const auto a = randomMapGrid(rng, testGeometry());
  // The second operand of ⊛ in the pipeline: r(m_SG) ⊕ m_PG (two arbitrary masses could meet in {C, V}, a set the
  // MapGrid does not store).
  MapMassGrid b;
  refineGrid(randomScanGrid(rng, testGeometry()), b);
  combineWithPriorGrid(b, randomPrior(rng, testGeometry(), PriorConfidence{ 1.0, 0.85, 0.7 }));
  MapMassGrid out;
  std::vector<float> fo(a.numCells()), of(a.numCells());
  modifiedYagerGrid(a, b, out, fo.data(), of.data());
  for (std::size_t i = 0; i < a.numCells(); ++i)
  {
    ConflictMasses c;
    const auto expected = modifiedYager(a.cell(i), b.cell(i), &c);
    ASSERT_TRUE(massNear(out.cell(i), expected, kFloatTolerance)) << "cell " << i;
    EXPECT_NEAR(fo[i], c.free_occupied, kFloatTolerance);
    EXPECT_NEAR(of[i], c.occupied_free, kFloatTolerance);
  }
}

TEST(GridOps, CounterAndSpecialisationMatchScalar)
{
  for (auto mode : { SpecialisationMode::kMovingToStopped, SpecialisationMode::kLiteral })
  {
    std::mt19937 rng(5);
    auto grid = randomMapGrid(rng, testGeometry());
    const auto before = grid;
    std::uniform_real_distribution<float> u(0.0f, 0.2f);
    std::vector<float> fo(grid.numCells()), of(grid.numCells());
    for (auto& v : fo) v = u(rng);
    for (auto& v : of) v = u(rng);
    CounterParams p;
    p.mode = mode;
    p.delta_inc = 0.2;
    p.gamma_occupied = 0.3;
    updateCounterAndSpecialiseGrid(grid, fo.data(), of.data(), p);
    for (std::size_t i = 0; i < grid.numCells(); ++i)
    {
      const auto m = before.cell(i);
      const double zeta =
          updateCounter(before.zeta(i), m.massInside(FrameMG::kO), ConflictMasses{ fo[i], of[i], 0.0 }, p);
      ASSERT_NEAR(grid.zeta(i), zeta, 1e-6) << "cell " << i;
      ASSERT_TRUE(massNear(grid.cell(i), specialise(m, zeta, mode), kFloatTolerance)) << "cell " << i;
    }
  }
}

TEST(GridOps, PignisticMatchesScalar)
{
  std::mt19937 rng(6);
  const auto grid = randomMapGrid(rng, testGeometry());
  PignisticPlanes p;
  pignisticGrid(grid, p);
  for (std::size_t i = 0; i < grid.numCells(); ++i)
  {
    const auto expected = pignistic(grid.cell(i));
    for (int e = 0; e < 5; ++e) ASSERT_NEAR(p[e][i], expected[e], kFloatTolerance);
  }
}

TEST(FusionStep, MatchesScalarReferenceAndTheSequenceOfGridOps)
{
  for (auto mode : { SpecialisationMode::kMovingToStopped, SpecialisationMode::kLiteral })
    for (int with_prior : { 2, 1, 0 })  // 2: with outline cells, 1: equation 1 only, 0: none
    {
      std::mt19937 rng(8);
      const auto g = testGeometry();
      const PriorConfidence beta{ 1.0, 0.85, 0.7 };
      auto map = randomMapGrid(rng, g);
      const auto before = map;
      const auto scan = randomScanGrid(rng, g);
      const auto prior = randomPrior(rng, g, beta, with_prior == 2);
      ASSERT_EQ(prior.hasWall(), with_prior == 2);
      FusionParams params;
      params.moving_expiry = false;  // the paper's sequence of grid ops; the step is tested in test_motion_steps
      params.building_conflict = false;  // the paper's ⊛; the step is tested in test_rules and below
      params.counter.mode = mode;
      params.counter.gamma_conflict = 0.3;
      params.counter.gamma_occupied = 0.4;
      FusionStepStats stats;
      fusionStep(map, scan, with_prior ? &prior : nullptr, params, &stats);

      // The same, one stage at a time.
      MapMassGrid staged_scan;
      refineGrid(scan, staged_scan);
      if (with_prior) combineWithPriorGrid(staged_scan, prior);
      auto staged = before;
      contextualDiscountGrid(staged, params.discount);
      std::vector<float> fo(g.numCells()), of(g.numCells());
      modifiedYagerGrid(staged, staged_scan, staged, fo.data(), of.data());
      updateCounterAndSpecialiseGrid(staged, fo.data(), of.data(), params.counter);

      double sum_fo = 0, sum_of = 0, sum_other = 0;
      for (std::size_t i = 0; i < map.numCells(); ++i)
      {
        const auto ref = fuseCell(before.cell(i), before.zeta(i), scan.cell(i),
                                  with_prior ? prior.cell(i) : MassMG::vacuous(), params);
        ASSERT_TRUE(massNear(map.cell(i), ref.mass, kFloatTolerance)) << "cell " << i;
        ASSERT_NEAR(map.zeta(i), ref.zeta, 1e-6) << "cell " << i;
        ASSERT_TRUE(isValidMass(map.cell(i), kFloatTolerance));
        ASSERT_TRUE(massNear(staged.cell(i), map.cell(i), kFloatTolerance)) << "cell " << i;
        ASSERT_NEAR(staged.zeta(i), map.zeta(i), 1e-6);
        sum_fo += ref.conflicts.free_occupied;
        sum_of += ref.conflicts.occupied_free;
        sum_other += ref.conflicts.other;
      }
      EXPECT_EQ(stats.num_cells, map.numCells());
      EXPECT_NEAR(stats.sum_conflict_free_occupied, sum_fo, 1e-3);
      EXPECT_NEAR(stats.sum_conflict_occupied_free, sum_of, 1e-3);
      EXPECT_NEAR(stats.sum_conflict_other, sum_other, 1e-3);
    }
}

TEST(FusionStep, AblationVariantsMatchTheScalarReference)
{
  struct Variant
  {
    CombinationRule rule;
    bool contextual;
    bool counter;
    bool building_conflict = false;
  };
  // The fused kernel compiles the paper's rule, the wall and step building conflict in: every dispatch is compared,
  // with outline cells (2), equation 1 only (1) and without a prior (0).
  for (const Variant v : { Variant{ CombinationRule::kYager, true, true }, Variant{ CombinationRule::kDempster, true, true },
                           Variant{ CombinationRule::kModifiedYager, false, true },
                           Variant{ CombinationRule::kModifiedYager, true, false },
                           Variant{ CombinationRule::kModifiedYager, true, true, true },
                           Variant{ CombinationRule::kModifiedYager, false, true, true } })
    for (int with_prior : { 2, 1, 0 })
    {
      std::mt19937 rng(9);
      const auto g = testGeometry();
      auto map = randomMapGrid(rng, g);
      const auto before = map;
      const auto scan = randomScanGrid(rng, g);
      const auto prior = randomPrior(rng, g, PriorConfidence{ 1.0, 0.85, 0.7 }, with_prior == 2);
      FusionParams params;
      params.rule = v.rule;
      params.contextual_discounting = v.contextual;
      params.alpha_single = 0.15;
      params.use_counter = v.counter;
      params.building_conflict = v.building_conflict;
      fusionStep(map, scan, with_prior ? &prior : nullptr, params);
      for (std::size_t i = 0; i < map.numCells(); ++i)
      {
        const auto ref = fuseCell(before.cell(i), before.zeta(i), scan.cell(i),
                                  with_prior ? prior.cell(i) : MassMG::vacuous(), params);
        ASSERT_TRUE(massNear(map.cell(i), ref.mass, kFloatTolerance)) << "cell " << i << ", prior " << with_prior;
        ASSERT_NEAR(map.zeta(i), ref.zeta, 1e-6);
        ASSERT_TRUE(isValidMass(map.cell(i), kFloatTolerance));
      }
    }
}

TEST(FusionStep, RejectsMismatchedGeometries)
{
  MapMassGrid map(testGeometry());
  auto other = testGeometry();
  other.width += 1;
  ScanMassGrid scan(other);
  EXPECT_THROW(fusionStep(map, scan, nullptr, FusionParams{}), std::invalid_argument);
  FusionParams bad;
  bad.discount.alpha_free = 3.0;
  ScanMassGrid ok(testGeometry());
  EXPECT_THROW(fusionStep(map, ok, nullptr, bad), ParameterError);
}

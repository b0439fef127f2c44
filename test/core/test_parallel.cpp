// Threads of the per-scan update: every chunk runs once, errors reach the caller, the `threads` parameter is checked,
// and a whole MapGrid drive gives bit-identical masses, ζ, BetP, map doubt and decisions for 1, 2 and 4 threads.
// Also: the focal sets the pipeline can ever reach (the closure of the scan, the prior, discounting, ⊛ and its
// variants, the counter, specialisation, moving expiry and motion spreading), computed with the scalar reference.
#include <gtest/gtest.h>

#include <atomic>
#include <iostream>
#include <cstring>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "map_aided_fusion/core/fusion.hpp"
#include "map_aided_fusion/core/grid_ops.hpp"
#include "map_aided_fusion/core/map_grid.hpp"
#include "map_aided_fusion/core/parallel.hpp"
#include "map_aided_fusion/core/prior.hpp"

using namespace map_aided_fusion::core;

TEST(Parallel, EveryChunkRunsOnceAndErrorsReachTheCaller)
{
  for (int threads : { 1, 2, 4 })
  {
    const Parallel par(threads);
    EXPECT_EQ(par.threads(), resolveThreads(threads));
    EXPECT_LE(par.threads(), threads);
    std::vector<std::atomic<int>> runs(1000);
    par.forChunks(runs.size(), [&](std::size_t c) { ++runs[c]; });
    for (const auto& r : runs) EXPECT_EQ(r.load(), 1);
    std::vector<int> covered(10007, 0);
    par.forRange(covered.size(), 64, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) ++covered[i];
    });
    for (int c : covered) EXPECT_EQ(c, 1);
    EXPECT_THROW(par.forChunks(16, [](std::size_t c) {
      if (c == 7) throw std::runtime_error("chunk 7");
    }),
                 std::runtime_error);
  }
  EXPECT_GE(Parallel(0).threads(), 1) << "0: every core";
  EXPECT_EQ(chunkCount(0, 16), 0u);
  EXPECT_EQ(chunkCount(33, 16), 3u);
}

TEST(Parallel, ThreadsParameterIsValidatedByName)
{
  MapGridParams p;
  for (int bad : { -1, kMaxThreads + 1 })
  {
    p.threads = bad;
    try
    {
      p.validate();
      FAIL() << bad;
    }
    catch (const ParameterError& e)
    {
      EXPECT_EQ(e.parameter(), "threads");
    }
  }
  p.threads = 0;
  EXPECT_NO_THROW(p.validate());
  p.threads = kMaxThreads;
  EXPECT_NO_THROW(p.validate());
}

namespace {

/// Everything one MapGrid holds after a scripted drive, as raw bytes.
struct DriveResult
{
  std::vector<float> planes, betp, doubt;
  std::vector<std::int8_t> decision;
  std::vector<double> conflicts;
};

DriveResult drive(int threads)
{
  MapGridParams params;
  params.size_x = params.size_y = 64.0;
  params.resolution = 0.2;  // 320 x 320 cells: several chunks of every pass
  params.recentre_distance = 1.0;
  params.threads = threads;
  MapGrid grid(params);
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> kind(0, 99);
  std::uniform_real_distribution<double> u(0.05, 0.9);
  const GridGeometry sg = GridGeometry::centred(64.0, 64.0, 0.2);
  PriorWindow prior(GridGeometry::centred(200.0, 200.0, 0.2));
  for (std::size_t i = 0; i < prior.building.size(); ++i)
  {
    const int k = kind(rng);
    (k < 30 ? prior.road : k < 60 ? prior.other : k < 75 ? prior.building : prior.wall)[i] = 0.85f;
  }
  DriveResult r;
  Pose2 pose;
  for (int step = 0; step < 12; ++step)
  {
    ScanMassGrid scan(sg);
    std::vector<float> xy;
    for (std::size_t i = 0; i < scan.numCells(); ++i)
    {
      const int k = kind(rng);
      if (k < 55)
      {
        const double f = u(rng);
        scan.setCell(i, MassSG{ { FrameSG::kF, f }, { FrameSG::kOmega, 1.0 - f } });
      }
      else if (k < 60)
      {
        const double o = u(rng);
        scan.setCell(i, MassSG{ { FrameSG::kO, o }, { FrameSG::kOmega, 1.0 - o } });
        const Point2 c = sg.cellCentre(sg.cellOf(i));
        xy.push_back(static_cast<float>(c.x));
        xy.push_back(static_cast<float>(c.y));
      }
    }
    const ObstaclePoints obstacles{ xy.data(), xy.size() / 2 };
    pose.x += 1.3;
    pose.y += 0.4;
    pose.yaw += 0.07;
    const FusionStepStats s = grid.update(scan, pose, 0.1 * step, &prior, nullptr, step % 2 ? &obstacles : nullptr);
    r.conflicts.push_back(s.sum_conflict_free_occupied);
    r.conflicts.push_back(s.sum_conflict_occupied_free);
    r.conflicts.push_back(s.sum_conflict_other);
  }
  const MapMassGrid& m = grid.masses();
  r.planes.assign(m.planes(), m.planes() + m.bytes() / sizeof(float));  // every slot of every cell, and ζ
  for (int e = 0; e < FrameMG::kSize; ++e)
    r.betp.insert(r.betp.end(), grid.pignistic()[e].begin(), grid.pignistic()[e].end());
  r.doubt.assign(grid.mapDoubt().begin(), grid.mapDoubt().end());
  decide(m, grid.pignistic(), grid.params(), r.decision, &grid.parallel());
  EXPECT_EQ(grid.decisions(), r.decision) << "the update's decisions are decide() on its result";
  return r;
}

template <class T>
bool sameBytes(const std::vector<T>& a, const std::vector<T>& b)
{
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

}  // namespace

TEST(Parallel, MapGridDriveIsBitIdenticalForAnyThreadCount)
{
  const DriveResult one = drive(1);
  std::size_t occupied = 0, moving = 0;
  for (std::int8_t d : one.decision)
  {
    occupied += d != static_cast<std::int8_t>(CellClass::kUnknown) && d != static_cast<std::int8_t>(CellClass::kFree);
    moving += d == static_cast<std::int8_t>(CellClass::kMoving);
  }
  ASSERT_GT(occupied, 100u) << "the drive must exercise the occupied paths";
  for (int threads : { 2, 4 })
  {
    const DriveResult other = drive(threads);
    EXPECT_TRUE(sameBytes(one.planes, other.planes)) << threads << " threads: masses or zeta differ";
    EXPECT_TRUE(sameBytes(one.betp, other.betp)) << threads;
    EXPECT_TRUE(sameBytes(one.doubt, other.doubt)) << threads;
    EXPECT_TRUE(sameBytes(one.decision, other.decision)) << threads;
    EXPECT_TRUE(sameBytes(one.conflicts, other.conflicts)) << threads;
  }
}

TEST(Parallel, MotionSpreadingOverManyChunksIsBitIdenticalForAnyThreadCount)
{
  // 1600 separate 4-cell objects (one V cell, three open {C, N, S, V}): 6400 cells to spread, many chunks of the
  // spreading's cell pass, on the workers too.
  const GridGeometry geo{ 0.5, 200, 120, 0.0, 0.0 };
  MapMassGrid start(geo);
  ScanMassGrid scan(geo);
  std::size_t objects = 0;
  for (int y = 0; y < geo.height; y += 3)
    for (int x = 0; x + 4 <= geo.width; x += 5, ++objects)
      for (int k = 0; k < 4; ++k)
      {
        const std::size_t i = geo.index(x + k, y);
        start.at(k == 0 ? FrameMG::kV : FrameMG::kO, i) = 0.8f;
        start.at(FrameMG::kOmega, i) = 0.2f;
        scan.at(FrameSG::kO, i) = 0.8f;
        scan.at(FrameSG::kOmega, i) = 0.2f;
      }
  std::vector<float> first_planes, first_betp;
  for (int threads : { 1, 2, 4 })
  {
    const Parallel parallel(threads);
    MapMassGrid g = start;
    PignisticPlanes betp;
    pignisticGrid(g, betp);
    EXPECT_EQ(spreadMotion(g, betp, scan, 0.2, 200, 0.4, 0.1, &parallel), objects) << threads;
    EXPECT_FLOAT_EQ(g.at(FrameMG::kV, geo.index(3, 0)), 0.8f) << "an open cell became V, " << threads;
    std::vector<float> planes(g.planes(), g.planes() + g.bytes() / sizeof(float)), p;
    for (int e = 0; e < FrameMG::kSize; ++e) p.insert(p.end(), betp[e].begin(), betp[e].end());
    if (threads == 1)
    {
      first_planes = planes;
      first_betp = p;
      continue;
    }
    EXPECT_TRUE(sameBytes(planes, first_planes)) << threads << " threads: masses differ";
    EXPECT_TRUE(sameBytes(p, first_betp)) << threads << " threads: BetP differs";
  }
}

namespace {

/// The focal sets with mass after fuseCell() of a map cell {A, Ω}, for every scan and prior focal set and ζ.
std::set<Subset> closure(const std::vector<FusionParams>& variants)
{
  std::vector<MassSG> scans{ MassSG{ { FrameSG::kF, 0.6 }, { FrameSG::kOmega, 0.4 } },
                             MassSG{ { FrameSG::kO, 0.6 }, { FrameSG::kOmega, 0.4 } },
                             MassSG{ { FrameSG::kF, 0.3 }, { FrameSG::kO, 0.3 }, { FrameSG::kOmega, 0.4 } },
                             MassSG() };
  // The prior's focal sets B, R, T, W and Ω, alone and pooled (softening mixes them).
  std::vector<MassMG> priors{ MassMG() };
  for (Subset s : { FrameMG::kBuilding, FrameMG::kRoad, FrameMG::kOther, FrameMG::kWall })
    priors.push_back(MassMG{ { s, 0.8 }, { FrameMG::kOmega, 0.2 } });
  priors.push_back(MassMG{ { FrameMG::kBuilding, 0.2 }, { FrameMG::kRoad, 0.2 }, { FrameMG::kOther, 0.2 },
                           { FrameMG::kWall, 0.2 }, { FrameMG::kOmega, 0.2 } });
  std::set<Subset> reached{ FrameMG::kOmega };
  for (bool grew = true; grew;)
  {
    grew = false;
    const std::set<Subset> now = reached;
    for (Subset a : now)
      for (const FusionParams& p : variants)
        for (double zeta : { 0.0, 0.5, 1.0 })
          for (const MassSG& s : scans)
            for (const MassMG& q : priors)
            {
              const MassMG map = a == FrameMG::kOmega ? MassMG() : MassMG{ { a, 0.5 }, { FrameMG::kOmega, 0.5 } };
              const CellFusionResult r = fuseCell(map, zeta, s, q, p);
              for (int b = 0; b < FrameMG::kNumSubsets; ++b)
                if (r.mass[static_cast<Subset>(b)] > 1e-12) grew |= reached.insert(static_cast<Subset>(b)).second;
            }
    // Motion spreading moves open motion (sets holding V and other classes) to {V}.
    for (Subset a : std::set<Subset>(reached))
      if ((a & FrameMG::kV) && a != FrameMG::kV) grew |= reached.insert(FrameMG::kV).second;
  }
  return reached;
}

}  // namespace

TEST(ReachableFocalSets, ClosureOfThePipelineFromTheScanAndThePrior)
{
  FusionParams paper;
  paper.moving_expiry = false;
  paper.building_conflict = false;
  FusionParams added = paper;
  added.moving_expiry = true;
  added.building_conflict = true;
  const std::set<Subset> paper_sets = closure({ paper });
  const std::set<Subset> default_sets = closure({ added });
  // r(m_SG) ⊕ m_PG has nine focal sets ({F}, {C}, {S,V}, {N,S,V}, {C,N,S,V}, {F,S,V}, {F,N,S,V}, {F,C}, Ω);
  // discounting adds contexts ({C,N}, {S,V}, {F}) to a set, ⊛ intersects (∅_FO to {V}), specialisation takes V out
  // of a set holding V and another class ({V} becomes {S}): the closure is what these reach from Ω.
  EXPECT_TRUE(paper_sets.count(FrameMG::kV)) << "⊛ sends the F→O conflict to {V}";
  EXPECT_TRUE(paper_sets.count(FrameMG::kS)) << "specialisation of {V}";
  EXPECT_TRUE(paper_sets.count(FrameMG::kOmega));
  EXPECT_FALSE(paper_sets.count(0)) << "∅ never holds mass after a step";
  EXPECT_EQ(paper_sets, default_sets) << "moving expiry, building conflict and spreading reach no new set";
  // Contexts add {C, N} or {S, V} whole, and every scan-prior set holding C holds N, S and V or neither V nor S:
  // C never meets V without N or S. So {C, V} and {F, C, V} are never reached, nor ∅: 29 of the 32 sets.
  EXPECT_FALSE(paper_sets.count(FrameMG::kC | FrameMG::kV));
  EXPECT_FALSE(paper_sets.count(FrameMG::kF | FrameMG::kC | FrameMG::kV));
  EXPECT_EQ(paper_sets.size(), static_cast<std::size_t>(FrameMG::kNumSubsets - 3));
  // The ablation rules and the literal specialisation stay inside the same closure or a subset of it.
  FusionParams yager = paper, dempster = paper, literal = paper, no_counter = paper, single = paper;
  yager.rule = CombinationRule::kYager;
  dempster.rule = CombinationRule::kDempster;
  literal.counter.mode = SpecialisationMode::kLiteral;
  no_counter.use_counter = false;
  single.contextual_discounting = false;
  const std::set<Subset> all = closure({ paper, added, yager, dempster, literal, no_counter, single });
  for (Subset a : all) EXPECT_TRUE(paper_sets.count(a) || a == FrameMG::kOmega) << "ablation reaches " << subsetName<FrameMG>(a);
  std::string names;
  for (Subset a : paper_sets) names += subsetName<FrameMG>(a) + " ";
  RecordProperty("reachable_focal_sets", names);
  RecordProperty("reachable_count", static_cast<int>(paper_sets.size()));
  std::cout << "reachable focal sets (" << paper_sets.size() << " of " << FrameMG::kNumSubsets << "): " << names << "\n";
}

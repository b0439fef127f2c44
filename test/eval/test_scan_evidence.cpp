// What one scan gave each window cell (eval::scanEvidence), on a scripted ScanGrid with a known answer.
#include <gtest/gtest.h>

#include <vector>

#include "map_aided_fusion/core/map_grid.hpp"
#include "map_aided_fusion/eval/scan_evidence.hpp"

using namespace map_aided_fusion;
using eval::ScanEvidence;

TEST(ScanEvidence, FreeOccupiedClearedAndUnreachedCellsOfAScan)
{
  // A 10 m window at 0.5 m on the vehicle at the origin, and a ScanGrid on the same lattice: row y ∈ [0, 0.5) free
  // from x = 0 to 5 m but for an occupied cell at x ∈ [2, 2.5) (column 4 from the vehicle); the rest vacuous.
  core::MapGridParams params;
  params.size_x = params.size_y = 10.0;
  params.resolution = 0.5;
  params.point_occupancy = false;
  params.obstacle_clearance = 1.0;  // two cells around an occupied one: no free evidence
  core::MapGrid grid(params);
  core::ScanMassGrid scan(core::GridGeometry::centred(10.0, 10.0, 0.5));
  const core::GridGeometry& sg = scan.geometry();
  for (int x = 10; x < 20; ++x)
  {
    const std::size_t i = sg.index(x, 10);
    if (x == 14)
      scan.setCell(i, core::MassSG{ { core::FrameSG::kO, 0.8 }, { core::FrameSG::kOmega, 0.2 } });
    else
      scan.setCell(i, core::MassSG{ { core::FrameSG::kF, 0.7 }, { core::FrameSG::kOmega, 0.3 } });
  }
  const core::Pose2 pose{ 0.0, 0.0, 0.0 };
  grid.update(scan, pose, 0.0, nullptr);
  const eval::EvidenceGrid e = eval::scanEvidence(scan, pose, grid, nullptr);
  ASSERT_EQ(e.geometry, grid.geometry());
  ASSERT_EQ(e.cells.size(), grid.geometry().numCells());
  const auto at = [&](double x, double y) {
    core::CellIndex c;
    EXPECT_TRUE(e.geometry.worldToCell(core::Point2{ x, y }, c));
    return e.cells[e.geometry.index(c)];
  };
  EXPECT_EQ(at(2.25, 0.25), ScanEvidence::kOccupied);
  for (const double x : { 1.25, 1.75, 2.75, 3.25 }) EXPECT_EQ(at(x, 0.25), ScanEvidence::kCleared) << x;
  for (const double x : { 0.25, 0.75, 3.75, 4.75 }) EXPECT_EQ(at(x, 0.25), ScanEvidence::kFree) << x;
  EXPECT_EQ(at(-2.0, 3.0), ScanEvidence::kUnreached) << "vacuous in the ScanGrid";
  // What the projection fused is what the MapGrid saw: the free cells' decisions are F after this one update.
  EXPECT_EQ(grid.decisions()[e.geometry.index(e.geometry.cellAt(core::Point2{ 0.25, 0.25 }))],
            static_cast<std::int8_t>(core::CellClass::kFree));
}

// Scores of labelled real sweeps (eval/point_labels.hpp) on scripted scenes whose answers follow from the
// definitions: ground cells decided F, obstacle cells decided F, point-level moving IoU, point-level ground
// segmentation, and the counts that pool sequences.
#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

#include "map_aided_fusion/eval/point_labels.hpp"

using namespace map_aided_fusion;
using eval::LabelledPoint;
using eval::LabelState;

namespace {

constexpr std::int8_t kF = static_cast<std::int8_t>(core::CellClass::kFree);
constexpr std::int8_t kV = static_cast<std::int8_t>(core::CellClass::kMoving);
constexpr std::int8_t kS = static_cast<std::int8_t>(core::CellClass::kStopped);
constexpr std::int8_t kUnknown = static_cast<std::int8_t>(core::CellClass::kUnknown);

/// A 4 × 1 row of 1 m cells from the origin, decided F, F, V, unknown (cells 0 … 3), or as given.
eval::ClassGrid row(std::vector<std::int8_t> cells = { kF, kF, kV, kUnknown })
{
  eval::ClassGrid g;
  g.geometry.resolution = 1.0;
  g.geometry.width = static_cast<int>(cells.size());
  g.geometry.height = 1;
  g.cells = std::move(cells);
  return g;
}

LabelledPoint point(double x, LabelState state, bool ground, bool obstacle, bool vegetation = false)
{
  LabelledPoint p;
  p.p = core::Point2{ x, 0.5 };
  p.state = state;
  p.ground = ground;
  p.obstacle = obstacle;
  p.vegetation = vegetation;
  p.instance = state == LabelState::kMoving ? 7 : 0;
  return p;
}

LabelledPoint ground(double x) { return point(x, LabelState::kStatic, true, false); }
LabelledPoint obstacle(double x) { return point(x, LabelState::kStatic, false, true); }
LabelledPoint mover(double x) { return point(x, LabelState::kMoving, false, true); }

}  // namespace

TEST(PointLabels, GroundCellsHoldGroundPointsAndNoOtherLabelledPoint)
{
  eval::PointLabelScorer s(1.0);
  // Cell 0 (F): ground only. Cell 1 (F): ground and a static obstacle. Cell 3 (unknown): ground only, and an
  // unlabelled point, which does not count as another class. A ground point off the grid is no cell.
  std::vector<LabelledPoint> pts{ ground(0.5), ground(1.5), obstacle(1.6), ground(3.5),
                                  point(3.6, LabelState::kUnlabelled, false, false), ground(9.0) };
  s.add(0.0, row(), pts, true);
  const auto& w = s.sweeps().back();
  EXPECT_EQ(w.ground_cells, 2u);
  EXPECT_EQ(w.ground_f_cells, 1u);
  EXPECT_EQ(w.obstacle_cells, 1u);
  EXPECT_EQ(w.obstacle_f_cells, 1u) << "cell 1 holds an obstacle and is decided F: false free";
  const auto m = s.summary();
  EXPECT_DOUBLE_EQ(m.at("ground_cells_f_recall"), 0.5);
  EXPECT_DOUBLE_EQ(m.at("obstacle_cells_false_free"), 1.0);
  EXPECT_DOUBLE_EQ(m.at("counts.ground_cells"), 2.0);
  EXPECT_DOUBLE_EQ(m.at("counts.obstacle_f_cells"), 1.0);
}

TEST(PointLabels, VegetationIsAnObstacleButScoredApartAndMoversCellsSAreCounted)
{
  eval::PointLabelScorer s(1.0);
  // Cell 0 (F): vegetation only. Cell 1 (F): a static obstacle. Cell 2 (V): a mover. Cell 3 (S): a mover.
  std::vector<LabelledPoint> pts{ point(0.5, LabelState::kStatic, false, true, true), obstacle(1.5), mover(2.5),
                                  mover(3.5) };
  s.add(0.0, row({ kF, kF, kV, kS }), pts, true);
  const auto& w = s.sweeps().back();
  EXPECT_EQ(w.obstacle_cells, 4u);
  EXPECT_EQ(w.obstacle_f_cells, 2u);
  EXPECT_EQ(w.rigid_cells, 3u);
  EXPECT_EQ(w.rigid_f_cells, 1u);
  EXPECT_EQ(w.mover_cells, 2u);
  EXPECT_EQ(w.mover_s_cells, 1u);
  const auto m = s.summary();
  EXPECT_DOUBLE_EQ(m.at("obstacle_cells_false_free"), 0.5);
  EXPECT_DOUBLE_EQ(m.at("rigid_cells_false_free"), 1.0 / 3.0);
  EXPECT_DOUBLE_EQ(m.at("mover_cells_s_share"), 0.5);
  EXPECT_DOUBLE_EQ(m.at("counts.mover_s_cells"), 1.0);
}

TEST(PointLabels, MovingIoUCountsPointsByTheirCellsDecision)
{
  eval::PointLabelScorer s(1.0);
  // Cell 2 is V: two moving points there (TP), one static obstacle point there (FP); a ground point there is left
  // out (the ground under a mover shares its cells); one moving point in cell 0 (FN), one off the grid (FN); an
  // unlabelled point in cell 2 is left out.
  std::vector<LabelledPoint> pts{ mover(2.2), mover(2.8), obstacle(2.5), ground(2.4), mover(0.5), mover(-3.0),
                                  point(2.6, LabelState::kUnlabelled, false, false) };
  s.add(0.0, row(), pts, true);
  const auto& w = s.sweeps().back();
  EXPECT_EQ(w.moving_tp, 2u);
  EXPECT_EQ(w.moving_fp, 1u);
  EXPECT_EQ(w.moving_fn, 2u);
  EXPECT_DOUBLE_EQ(s.summary().at("moving_point_iou"), 2.0 / 5.0);
}

TEST(PointLabels, NothingToScoreReadsMinusOne)
{
  eval::PointLabelScorer s(1.0);
  s.add(0.0, row(), {}, true);
  const auto m = s.summary();
  EXPECT_EQ(m.at("ground_cells_f_recall"), -1.0);
  EXPECT_EQ(m.at("obstacle_cells_false_free"), -1.0);
  EXPECT_EQ(m.at("moving_point_iou"), -1.0);
  EXPECT_EQ(m.count("ground_segmentation.f1"), 0u) << "no segmentation was scored";
}

TEST(PointLabels, SettledGroundCountsFromTheSettleTimeOn)
{
  eval::PointLabelScorer s(1.0, 0.5);
  const std::vector<LabelledPoint> pts{ ground(0.5), ground(1.5), ground(3.5) };
  s.add(10.0, row({ kUnknown, kUnknown, kUnknown, kUnknown }), pts, true);  // t = 0: nothing decided yet
  s.add(10.1, row({ kF, kUnknown, kUnknown, kUnknown }), {}, false);       // an unlabelled sweep
  s.add(10.5, row({ kF, kF, kS, kUnknown }), pts, true);                   // t = 0.5: settled
  const auto m = s.summary();
  EXPECT_DOUBLE_EQ(m.at("ground_cells_f_recall"), 2.0 / 6.0);
  EXPECT_DOUBLE_EQ(m.at("ground_cells_f_recall_settled"), 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(m.at("counts.ground_cells_settled"), 3.0);
  EXPECT_DOUBLE_EQ(m.at("counts.ground_f_cells_settled"), 2.0);
}

TEST(PointLabels, GroundSegmentationLeavesOutVegetationUnlabelledAndRejectedReturns)
{
  using R = core::ReturnClass;
  eval::PointLabelScorer s(1.0);
  const std::vector<LabelledPoint> pts{
    ground(0.5),                                         // called ground: TP
    ground(0.6),                                         // called obstacle: FN, ground called obstacle
    ground(0.7),                                         // in the height gap: FN
    obstacle(1.5),                                       // called ground: FP
    obstacle(1.6),                                       // called obstacle: TN
    point(1.7, LabelState::kStatic, false, false),       // a canopy above the clearance: TN
    point(2.5, LabelState::kStatic, false, true, true),  // vegetation: left out
    point(2.6, LabelState::kUnlabelled, true, false),    // unlabelled: left out
    ground(2.7),                                         // rejected by the sensor model: left out
  };
  const std::vector<R> classes{ R::kGround,   R::kObstacle,       R::kHeightGap, R::kGround,  R::kObstacle,
                                R::kAboveClearance, R::kGround, R::kGround,    R::kRejected };
  s.addSegmentation(pts, classes);
  s.addSegmentation(pts, classes);  // counts add up sweep after sweep
  const auto& c = s.segmentation();
  EXPECT_EQ(c.tp, 2u);
  EXPECT_EQ(c.fn, 4u);
  EXPECT_EQ(c.fp, 2u);
  EXPECT_EQ(c.tn, 4u);
  EXPECT_EQ(c.ground_as_obstacle, 2u);
  const auto m = s.summary();
  EXPECT_DOUBLE_EQ(m.at("ground_segmentation.precision"), 0.5);
  EXPECT_DOUBLE_EQ(m.at("ground_segmentation.recall"), 2.0 / 6.0);
  EXPECT_DOUBLE_EQ(m.at("ground_segmentation.f1"), 4.0 / 10.0);
  EXPECT_DOUBLE_EQ(m.at("ground_segmentation.ground_as_obstacle"), 2.0 / 6.0);
  EXPECT_THROW(s.addSegmentation(pts, std::vector<R>(3, R::kGround)), std::invalid_argument);
}

TEST(PointLabels, PooledCountsGiveThePooledRatioNotTheMeanOfRatios)
{
  // Two sequences: 1 of 1 ground cells F, then 1 of 3. Pooled 2 / 4, where the mean of the ratios is 2 / 3.
  eval::PointLabelScorer a(1.0), b(1.0);
  a.add(0.0, row(), { ground(0.5) }, true);
  b.add(0.0, row(), { ground(0.5), ground(2.5), ground(3.5) }, true);
  const auto ma = a.summary(), mb = b.summary();
  const double pooled = (ma.at("counts.ground_f_cells") + mb.at("counts.ground_f_cells")) /
                        (ma.at("counts.ground_cells") + mb.at("counts.ground_cells"));
  EXPECT_DOUBLE_EQ(pooled, 0.5);
  EXPECT_DOUBLE_EQ(ma.at("ground_cells_f_recall"), 1.0);
  EXPECT_DOUBLE_EQ(mb.at("ground_cells_f_recall"), 1.0 / 3.0);
}

TEST(PointLabels, RatiosOfCounts)
{
  EXPECT_EQ(eval::countRatio(1.0, 0.0), -1.0);
  EXPECT_DOUBLE_EQ(eval::countRatio(1.0, 4.0), 0.25);
  EXPECT_DOUBLE_EQ(eval::f1Score(3.0, 1.0, 2.0), 6.0 / 9.0);
  EXPECT_EQ(eval::f1Score(0.0, 0.0, 0.0), -1.0);
}

TEST(PointLabels, GroundCellsNotDecidedFreeAreCountedByWhatTheScanGaveThem)
{
  using eval::ScanEvidence;
  constexpr std::int8_t kOccupied = static_cast<std::int8_t>(core::CellClass::kOccupied);
  eval::PointLabelScorer s(1.0);
  // Five ground cells: 0 decided F, the others not. The scan gave 0 free, 1 free mass cleared away, 2 occupied mass,
  // 3 and 4 no mass; cell 4 holds a return in the height gap, so it is ambiguous, cell 3 unreached.
  const eval::ClassGrid decision = row({ kF, kUnknown, kOccupied, kUnknown, kUnknown });
  eval::EvidenceGrid evidence{ decision.geometry,
                               { ScanEvidence::kFree, ScanEvidence::kCleared, ScanEvidence::kOccupied,
                                 ScanEvidence::kUnreached, ScanEvidence::kUnreached } };
  const std::vector<LabelledPoint> pts{ ground(0.5), ground(1.5), ground(2.5), ground(3.5), ground(4.4), ground(4.6) };
  std::vector<core::ReturnClass> classes(pts.size(), core::ReturnClass::kGround);
  classes[5] = core::ReturnClass::kHeightGap;
  classes[3] = core::ReturnClass::kBelowGround;  // below the ground band: not ambiguous, cell 3 stays unreached
  eval::refineAmbiguous(evidence, pts, classes);
  EXPECT_EQ(evidence.cells[3], ScanEvidence::kUnreached);
  EXPECT_EQ(evidence.cells[4], ScanEvidence::kAmbiguous);
  EXPECT_EQ(evidence.cells[1], ScanEvidence::kCleared) << "only cells without mass become ambiguous";
  s.add(0.0, decision, pts, true, &evidence);
  // A sweep without evidence counts its ground cells for the recall, not for the shares.
  s.add(0.1, decision, pts, true);
  const auto m = s.summary();
  EXPECT_DOUBLE_EQ(m.at("ground_cells_f_recall"), 0.2);
  EXPECT_DOUBLE_EQ(m.at("counts.ground_cells_with_evidence"), 5.0);
  EXPECT_DOUBLE_EQ(m.at("ground_cells_not_f.free"), 0.0);
  for (const char* e : { "cleared", "occupied", "unreached", "ambiguous" })
    EXPECT_DOUBLE_EQ(m.at(std::string("ground_cells_not_f.") + e), 0.2) << e;
  // The recall and the shares of the sweeps with evidence add up to one.
  double sum = m.at("ground_cells_f_recall");
  for (const auto& name : eval::kScanEvidenceNames) sum += m.at("ground_cells_not_f." + std::string(name));
  EXPECT_DOUBLE_EQ(sum, 1.0);
  // Evidence on another geometry is not counted.
  eval::PointLabelScorer other(1.0);
  eval::EvidenceGrid shifted = evidence;
  shifted.geometry.origin_x = 1.0;
  other.add(0.0, decision, pts, true, &shifted);
  EXPECT_EQ(other.summary().count("ground_cells_not_f.free"), 0u);
  EXPECT_THROW(eval::refineAmbiguous(evidence, pts, {}), std::invalid_argument);
}

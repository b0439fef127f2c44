#include <gtest/gtest.h>

#include "map_aided_fusion/eval/metrics.hpp"

using namespace map_aided_fusion;
using namespace map_aided_fusion::eval;
using core::CellClass;

namespace {

ClassGrid grid(int w, int h, std::int8_t fill, double res = 1.0)
{
  ClassGrid g;
  g.geometry = core::GridGeometry{ res, w, h, 0.0, 0.0 };
  g.cells.assign(static_cast<std::size_t>(w * h), fill);
  return g;
}

}  // namespace

TEST(ConfusionMatrix, HandComputedScores)
{
  ConfusionMatrix m;
  // truth F: 8 decided F, 1 decided V, 1 unknown; truth V: 3 decided V, 1 decided S.
  m.add(0, 0, 8);
  m.add(0, 4, 1);
  m.add(0, -1, 1);
  m.add(4, 4, 3);
  m.add(4, 3, 1);
  EXPECT_EQ(m.support(0), 10u);
  EXPECT_EQ(m.count(0, ConfusionMatrix::kUnknownColumn), 1u);
  EXPECT_DOUBLE_EQ(m.recall(0), 0.8);
  EXPECT_DOUBLE_EQ(m.precision(0), 1.0);
  EXPECT_DOUBLE_EQ(m.recall(4), 0.75);
  EXPECT_DOUBLE_EQ(m.precision(4), 0.75);
  EXPECT_DOUBLE_EQ(m.iou(4), 3.0 / 5.0);  // decided V 4, truly V 4, both 3
  EXPECT_DOUBLE_EQ(m.iou(0), 8.0 / 10.0);
  EXPECT_DOUBLE_EQ(m.coverage(), 13.0 / 14.0);
  EXPECT_DOUBLE_EQ(m.accuracy(), 11.0 / 13.0);
  EXPECT_DOUBLE_EQ(m.meanIou(), (0.8 + 0.6) / 2.0);
  EXPECT_DOUBLE_EQ(m.precision(1), 0.0);
}

TEST(Accumulate, ComparesObservedCellsAtTheSameWorldPosition)
{
  auto truth = grid(4, 2, -1);
  truth.cells = { 0, 0, 4, -1, 1, 1, 3, -1 };
  // The decision grid is finer and shifted: each truth cell centre falls in one decision cell.
  auto decision = grid(8, 4, 0, 0.5);
  decision.cells[decision.geometry.index(4, 0)] = 4;  // truth cell (2, 0) centre (2.5, 0.5) → (5, 1)
  decision.cells[decision.geometry.index(5, 1)] = 4;
  ConfusionMatrix m;
  EXPECT_EQ(accumulate(truth, decision, m), 6u);
  EXPECT_EQ(m.count(4, 4), 1u);
  EXPECT_EQ(m.count(1, 0), 2u);
  EXPECT_EQ(m.count(3, 0), 1u);
  EXPECT_EQ(m.count(0, 0), 2u);
}

TEST(ObjectScorer, DetectionDelayStoppedAndTrails)
{
  ObjectScorer s(3, 1.0);
  TruthObject car;
  car.id = 7;
  car.cell_class = CellClass::kMoving;
  car.centre = core::Point2{ 2.0, 1.0 };
  car.length = 4.0;
  car.width = 2.0;
  TruthObject bus = car;
  bus.id = 8;
  bus.cell_class = CellClass::kStopped;
  bus.centre = core::Point2{ 7.0, 1.0 };
  auto truth = grid(10, 2, 0);
  for (int x = 0; x < 4; ++x)
    for (int y = 0; y < 2; ++y) truth.cells[truth.geometry.index(x, y)] = 4;
  for (int x = 5; x < 9; ++x)
    for (int y = 0; y < 2; ++y) truth.cells[truth.geometry.index(x, y)] = 3;
  auto undecided = grid(10, 2, -1);
  s.add(0.0, truth, { car, bus }, undecided);
  auto decided = grid(10, 2, 0);
  for (int x = 0; x < 4; ++x)
    for (int y = 0; y < 2; ++y) decided.cells[decided.geometry.index(x, y)] = 4;
  for (int x = 5; x < 9; ++x)
    for (int y = 0; y < 2; ++y) decided.cells[decided.geometry.index(x, y)] = 3;
  decided.cells[decided.geometry.index(9, 0)] = 4;  // a V cell on free ground: trail
  s.add(0.5, truth, { car, bus }, decided);
  EXPECT_EQ(s.movingVisible(), 1);
  EXPECT_EQ(s.movingDetected(), 1);
  EXPECT_DOUBLE_EQ(s.meanDetectionDelay(), 0.5);
  EXPECT_DOUBLE_EQ(s.stoppedRecognised(), 0.5);
  EXPECT_DOUBLE_EQ(s.stoppedCalledMoving(), 0.0);
  EXPECT_DOUBLE_EQ(s.trailCellsPerScan(), 0.5);
  EXPECT_DOUBLE_EQ(s.trailFraction(), 1.0 / 8.0);
}

TEST(ObjectScorer, StoppedObjectKeptWhileHidden)
{
  ObjectScorer s(3, 1.0, 3.0);
  TruthObject bus;
  bus.id = 3;
  bus.cell_class = CellClass::kStopped;
  bus.centre = core::Point2{ 2.0, 1.0 };
  bus.length = 4.0;
  bus.width = 2.0;
  auto seen = grid(10, 2, 0);
  for (int x = 0; x < 4; ++x)
    for (int y = 0; y < 2; ++y) seen.cells[seen.geometry.index(x, y)] = 3;
  auto hidden = grid(10, 2, -1);  // nothing observed: the bus is occluded
  auto decided = grid(10, 2, 0);
  for (int x = 0; x < 4; ++x)
    for (int y = 0; y < 2; ++y) decided.cells[decided.geometry.index(x, y)] = 3;
  const auto forgotten = grid(10, 2, -1);
  s.add(0.0, hidden, { bus }, decided);     // never seen yet: not counted
  s.add(1.0, seen, { bus }, decided);       // visible
  s.add(2.0, hidden, { bus }, decided);     // hidden 1 s later, still S: kept
  s.add(3.0, hidden, { bus }, forgotten);   // hidden 2 s later, forgotten
  s.add(5.0, hidden, { bus }, decided);     // hidden 4 s later: beyond the window, not counted
  EXPECT_EQ(s.stoppedHiddenPairs(), 2u);
  EXPECT_DOUBLE_EQ(s.stoppedKeptWhileHidden(), 0.5);
}

TEST(Reports, JsonAndMarkdownCarryTheNamedMetrics)
{
  VariantScores v;
  v.name = "full";
  v.description = "the paper's method";
  v.confusion.add(4, 4, 3);
  v.confusion.add(4, 0, 1);
  const auto flat = flatten(v);
  EXPECT_DOUBLE_EQ(flat.at("moving.recall"), 0.75);
  EXPECT_DOUBLE_EQ(flat.at("moving.precision"), 1.0);
  const auto json = toJson({ v }, { { "scenario", "test" } });
  EXPECT_NE(json.find("\"moving.recall\": 0.75"), std::string::npos) << json;
  EXPECT_NE(json.find("\"scenario\": \"test\""), std::string::npos);
  EXPECT_EQ(json.find("tracks_objects"), std::string::npos) << "no tracks scored";
  // With tracks: each judged object's record, its velocity error (|3.5 − 5|) and its share of the squared error.
  MotObject o;
  o.id = 7;
  o.has_velocity = true;
  o.velocity = core::Point2{ 5.0, 0.0 };
  MotHypothesis h;
  h.id = 3;
  h.has_velocity = true;
  h.velocity = core::Point2{ 3.5, 0.0 };
  v.tracks.addFrame({ o }, { h });
  const auto with_tracks = toJson({ v }, {});
  EXPECT_NE(with_tracks.find("\"tracks_objects\": [{\"id\": 7, \"frames\": 1, \"tracked_frames\": 1, "
                             "\"identity_share\": 1, \"id_switches\": 0, \"fragmentations\": 0, "
                             "\"velocity_pairs\": 1, \"velocity_rmse_mps\": 1.5, \"velocity_median_mps\": 1.5, "
                             "\"velocity_error_share\": 1}]"),
            std::string::npos)
      << with_tracks;
  v.confusion.add(0, 4, 6);  // free cells decided V
  v.confusion.add(1, 3, 1);  // a facade cell decided S
  v.confusion.add(1, 1, 3);
  v.scans = 2;
  const auto md = toMarkdown({ v });
  EXPECT_NE(md.find("| full |"), std::string::npos) << md;
  // False V per scan: 6 free cells over 2 scans; 1 of 4 facade cells decided S or V.
  EXPECT_NE(md.find("| full | 3.00 | 0.00 | 0.00 | 0.00 | 3.00 | 25.0 % |"), std::string::npos) << md;
}

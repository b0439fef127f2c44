#include "map_aided_fusion/eval/point_labels.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <unordered_map>
#include <unordered_set>

namespace map_aided_fusion {
namespace eval {

namespace {

constexpr int kThirdSweep = 2;  // index of an instance's third labelled sweep
constexpr int kUnknownSlot = kNumCellClasses;
constexpr double kSettleSlack = 1e-6;  // s: a sweep stamped at the settle time (to rounding) counts as settled

int slotOf(std::int8_t code)
{
  return code >= 0 && code < kNumCellClasses ? code : kUnknownSlot;
}

}  // namespace

GroundSegmentationCounts& GroundSegmentationCounts::operator+=(const GroundSegmentationCounts& o)
{
  tp += o.tp;
  fp += o.fp;
  fn += o.fn;
  tn += o.tn;
  ground_as_obstacle += o.ground_as_obstacle;
  return *this;
}

double countRatio(double a, double b) { return b > 0.0 ? a / b : -1.0; }

double f1Score(double tp, double fp, double fn) { return countRatio(2.0 * tp, 2.0 * tp + fp + fn); }

PointLabelScorer::PointLabelScorer(double match_radius, double settle_time)
  : radius_(match_radius), settle_(settle_time)
{
}

void PointLabelScorer::addSegmentation(const std::vector<LabelledPoint>& points,
                                       const std::vector<core::ReturnClass>& classes)
{
  if (points.size() != classes.size())
    throw std::invalid_argument("addSegmentation: " + std::to_string(classes.size()) + " return classes for " +
                                std::to_string(points.size()) + " labelled points");
  GroundSegmentationCounts c;
  for (std::size_t k = 0; k < points.size(); ++k)
  {
    const LabelledPoint& p = points[k];
    const core::ReturnClass r = classes[k];
    if (p.state == LabelState::kUnlabelled || p.vegetation || r == core::ReturnClass::kRejected) continue;
    const bool called_ground = r == core::ReturnClass::kGround;
    if (p.ground)
    {
      (called_ground ? c.tp : c.fn) += 1;
      c.ground_as_obstacle += r == core::ReturnClass::kObstacle;
    }
    else
      (called_ground ? c.fp : c.tn) += 1;
  }
  segmentation_ += c;
  ++segmented_sweeps_;
}

namespace {

/// The labelled-cell and point counts of one sweep that add() did not count before this issue: ground and obstacle
/// cells by decision, moving points by their cell's decision.
void scoreCellsAndPoints(const ClassGrid& decision, const std::vector<LabelledPoint>& points, PointScanScore& s,
                         const EvidenceGrid* evidence)
{
  const core::GridGeometry& g = decision.geometry;
  const auto moving = static_cast<std::int8_t>(core::CellClass::kMoving);
  const auto free = static_cast<std::int8_t>(core::CellClass::kFree);
  std::unordered_set<std::size_t> ground, other, obstacle, rigid;
  for (const LabelledPoint& lp : points)
  {
    if (lp.state == LabelState::kUnlabelled) continue;
    core::CellIndex c;
    const bool inside = g.worldToCell(lp.p, c);
    const bool in_v = inside && decision.cells[g.index(c)] == moving;
    if (lp.state == LabelState::kMoving)
      (in_v ? s.moving_tp : s.moving_fn) += 1;
    else if (!lp.ground)  // the ground under a mover shares its cells: a 2-D grid cannot tell them apart
      s.moving_fp += in_v;
    if (!inside) continue;
    const std::size_t i = g.index(c);
    (lp.ground ? ground : other).insert(i);
    if (lp.obstacle) obstacle.insert(i);
    if (lp.obstacle && !lp.vegetation) rigid.insert(i);
  }
  s.has_evidence = evidence && evidence->geometry == g && evidence->cells.size() == decision.cells.size();
  for (std::size_t i : ground)
    if (!other.count(i))
    {
      ++s.ground_cells;
      s.ground_f_cells += decision.cells[i] == free;
      if (s.has_evidence && decision.cells[i] != free)
        ++s.ground_not_f[static_cast<std::size_t>(evidence->cells[i])];
    }
  for (std::size_t i : obstacle)
  {
    ++s.obstacle_cells;
    s.obstacle_f_cells += decision.cells[i] == free;
  }
  for (std::size_t i : rigid)
  {
    ++s.rigid_cells;
    s.rigid_f_cells += decision.cells[i] == free;
  }
}

}  // namespace

void PointLabelScorer::add(double stamp, const ClassGrid& decision, const std::vector<LabelledPoint>& points,
                           bool labelled)
{
  add(stamp, decision, points, labelled, nullptr);
}

void PointLabelScorer::add(double stamp, const ClassGrid& decision, const std::vector<LabelledPoint>& points,
                           bool labelled, const EvidenceGrid* evidence)
{
  PointScanScore s;
  s.stamp = stamp;
  s.labelled = labelled;
  if (first_stamp_ < 0.0) first_stamp_ = stamp;
  const core::GridGeometry& g = decision.geometry;
  const auto moving = static_cast<std::int8_t>(core::CellClass::kMoving);
  for (std::int8_t d : decision.cells) s.v_cells += d == moving;
  if (!labelled)
  {
    sweeps_.push_back(s);
    return;
  }
  const int reach = static_cast<int>(std::ceil(radius_ / g.resolution - 1e-9));
  std::unordered_set<std::size_t> near_moving, static_cells, moving_cells;
  std::unordered_map<std::uint32_t, std::unordered_set<std::size_t>> instance_cells;
  for (const LabelledPoint& lp : points)
  {
    core::CellIndex c;
    if (!g.worldToCell(lp.p, c)) continue;
    const std::size_t i = g.index(c);
    if (lp.state == LabelState::kMoving)
    {
      for (int dy = -reach; dy <= reach; ++dy)
        for (int dx = -reach; dx <= reach; ++dx)
        {
          const core::CellIndex n{ c.x + dx, c.y + dy };
          if (g.contains(n)) near_moving.insert(g.index(n));
        }
      if (lp.obstacle)
      {
        moving_cells.insert(i);
        instance_cells[lp.instance].insert(i);
      }
    }
    else if (lp.state == LabelState::kStatic && lp.obstacle)
      static_cells.insert(i);
  }
  for (std::size_t i = 0; i < decision.cells.size(); ++i)
  {
    if (decision.cells[i] != moving) continue;
    if (!near_moving.count(i)) ++s.false_v;
    if (static_cells.count(i) && !moving_cells.count(i)) ++s.v_on_static;
  }
  const auto stopped = static_cast<std::int8_t>(core::CellClass::kStopped);
  for (std::size_t i : moving_cells)
  {
    ++s.mover_cells;
    s.mover_v_cells += decision.cells[i] == moving;
    s.mover_s_cells += decision.cells[i] == stopped;
  }
  for (std::size_t i : static_cells)
    if (!moving_cells.count(i)) ++s.static_cells[static_cast<std::size_t>(slotOf(decision.cells[i]))];
  scoreCellsAndPoints(decision, points, s, evidence);
  for (const auto& [id, cells] : instance_cells)
  {
    MovingInstance& m = instances_[id];
    m.id = id;
    if (m.first_seen < 0.0) m.first_seen = stamp;
    std::size_t v = 0;
    for (std::size_t i : cells) v += decision.cells[i] == moving;
    if (v > 0 && m.first_v < 0.0) m.first_v = stamp;
    ++m.sweeps;
    m.v_share.push_back(static_cast<double>(v) / static_cast<double>(cells.size()));
  }
  sweeps_.push_back(s);
}

std::map<std::string, double> PointLabelScorer::summary() const
{
  std::map<std::string, double> m;
  double sweeps = 0, labelled = 0, v = 0, v_unlabelled = 0, false_v = 0, v_static = 0, mover = 0, mover_v = 0;
  std::array<double, kNumCellClasses + 1> st{};
  for (const PointScanScore& s : sweeps_)
  {
    ++sweeps;
    v += static_cast<double>(s.v_cells);
    if (!s.labelled)
    {
      v_unlabelled += static_cast<double>(s.v_cells);
      continue;
    }
    ++labelled;
    false_v += static_cast<double>(s.false_v);
    v_static += static_cast<double>(s.v_on_static);
    mover += static_cast<double>(s.mover_cells);
    mover_v += static_cast<double>(s.mover_v_cells);
    for (std::size_t k = 0; k < st.size(); ++k) st[k] += static_cast<double>(s.static_cells[k]);
  }
  auto ratio = [](double a, double b) { return b > 0 ? a / b : 0.0; };
  m["sweeps"] = sweeps;
  m["labelled_sweeps"] = labelled;
  m["v_cells_per_sweep"] = ratio(v, sweeps);
  m["v_cells_per_unlabelled_sweep"] = ratio(v_unlabelled, sweeps - labelled);
  m["false_v_per_labelled_sweep"] = ratio(false_v, labelled);
  m["v_on_static_per_labelled_sweep"] = ratio(v_static, labelled);
  m["mover_cells_v_share"] = ratio(mover_v, mover);
  double min_share = -1.0, delay = 0.0;
  int detected = 0, never = 0;
  for (const auto& [id, inst] : instances_)
  {
    for (std::size_t k = kThirdSweep; k < inst.v_share.size(); ++k)
      min_share = min_share < 0.0 ? inst.v_share[k] : std::min(min_share, inst.v_share[k]);
    if (inst.first_v >= 0.0)
    {
      delay += inst.first_v - inst.first_seen;
      ++detected;
    }
    else
      ++never;
  }
  m["mover_min_v_share_from_third_sweep"] = min_share;
  m["mover_first_v_delay_s"] = detected ? delay / detected : -1.0;
  m["movers"] = static_cast<double>(instances_.size());
  m["movers_never_v"] = never;
  double total_static = 0;
  for (double x : st) total_static += x;
  for (int c = 0; c < kNumCellClasses; ++c)
    m["static_cells." + std::string(core::kCellClassNames[static_cast<std::size_t>(c)])] = ratio(st[c], total_static);
  m["static_cells.unknown"] = ratio(st[kUnknownSlot], total_static);
  addCellAndPointScores(m);
  addGroundLossScores(m);
  return m;
}

void PointLabelScorer::addGroundLossScores(std::map<std::string, double>& m) const
{
  double ground = 0;
  std::array<double, kNumScanEvidence> not_f{};
  bool any = false;
  for (const PointScanScore& s : sweeps_)
  {
    if (!s.labelled || !s.has_evidence) continue;
    any = true;
    ground += static_cast<double>(s.ground_cells);
    for (std::size_t e = 0; e < not_f.size(); ++e) not_f[e] += static_cast<double>(s.ground_not_f[e]);
  }
  if (!any) return;
  m["counts.ground_cells_with_evidence"] = ground;
  for (std::size_t e = 0; e < not_f.size(); ++e)
  {
    const std::string name(kScanEvidenceNames[e]);
    m["ground_cells_not_f." + name] = countRatio(not_f[e], ground);
    m["counts.ground_not_f_" + name] = not_f[e];
  }
}

void PointLabelScorer::addCellAndPointScores(std::map<std::string, double>& m) const
{
  double ground = 0, ground_f = 0, ground_settled = 0, ground_f_settled = 0, obstacle = 0, obstacle_f = 0;
  double rigid = 0, rigid_f = 0, tp = 0, fp = 0, fn = 0, false_v = 0, mover = 0, mover_v = 0, mover_s = 0;
  for (const PointScanScore& s : sweeps_)
  {
    if (!s.labelled) continue;
    ground += static_cast<double>(s.ground_cells);
    ground_f += static_cast<double>(s.ground_f_cells);
    if (s.stamp - first_stamp_ >= settle_ - kSettleSlack)
    {
      ground_settled += static_cast<double>(s.ground_cells);
      ground_f_settled += static_cast<double>(s.ground_f_cells);
    }
    obstacle += static_cast<double>(s.obstacle_cells);
    obstacle_f += static_cast<double>(s.obstacle_f_cells);
    rigid += static_cast<double>(s.rigid_cells);
    rigid_f += static_cast<double>(s.rigid_f_cells);
    mover_s += static_cast<double>(s.mover_s_cells);
    tp += static_cast<double>(s.moving_tp);
    fp += static_cast<double>(s.moving_fp);
    fn += static_cast<double>(s.moving_fn);
    false_v += static_cast<double>(s.false_v);
    mover += static_cast<double>(s.mover_cells);
    mover_v += static_cast<double>(s.mover_v_cells);
  }
  m["ground_cells_f_recall"] = countRatio(ground_f, ground);
  m["ground_cells_f_recall_settled"] = countRatio(ground_f_settled, ground_settled);
  m["obstacle_cells_false_free"] = countRatio(obstacle_f, obstacle);
  m["rigid_cells_false_free"] = countRatio(rigid_f, rigid);
  m["mover_cells_s_share"] = countRatio(mover_s, mover);
  m["moving_point_iou"] = countRatio(tp, tp + fp + fn);
  const std::map<std::string, double> counts{
    { "ground_cells", ground },       { "ground_f_cells", ground_f },     { "ground_cells_settled", ground_settled },
    { "ground_f_cells_settled", ground_f_settled }, { "obstacle_cells", obstacle }, { "obstacle_f_cells", obstacle_f },
    { "moving_tp", tp },              { "moving_fp", fp },                { "moving_fn", fn },
    { "false_v", false_v },           { "mover_cells", mover },           { "mover_v_cells", mover_v },
    { "mover_s_cells", mover_s },     { "rigid_cells", rigid },           { "rigid_f_cells", rigid_f },
  };
  for (const auto& [k, v] : counts) m["counts." + k] = v;
  if (!scoresSegmentation()) return;
  const GroundSegmentationCounts& c = segmentation_;
  const auto d = [](std::uint64_t x) { return static_cast<double>(x); };
  m["ground_segmentation.precision"] = countRatio(d(c.tp), d(c.tp + c.fp));
  m["ground_segmentation.recall"] = countRatio(d(c.tp), d(c.tp + c.fn));
  m["ground_segmentation.f1"] = f1Score(d(c.tp), d(c.fp), d(c.fn));
  m["ground_segmentation.ground_as_obstacle"] = countRatio(d(c.ground_as_obstacle), d(c.tp + c.fn));
  m["counts.segmentation_tp"] = d(c.tp);
  m["counts.segmentation_fp"] = d(c.fp);
  m["counts.segmentation_fn"] = d(c.fn);
  m["counts.segmentation_tn"] = d(c.tn);
  m["counts.ground_as_obstacle"] = d(c.ground_as_obstacle);
}

std::string pointLabelMarkdown(const std::vector<std::pair<std::string, const PointLabelScorer*>>& rows)
{
  std::ostringstream out;
  out << std::fixed;
  out << "| variant | sweeps (labelled) | V cells / sweep | false V / labelled sweep | V on static / labelled sweep "
         "| mover cells decided V | mover min V share (3rd sweep on) | first V delay (s) | static obstacle cells "
         "F / C / N / S / V / undecided |\n";
  out << "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- |\n";
  for (const auto& [name, scorer] : rows)
  {
    const auto m = scorer->summary();
    auto f = [&](const std::string& k, int digits) {
      std::ostringstream s;
      s << std::fixed << std::setprecision(digits) << m.at(k);
      return s.str();
    };
    out << "| " << name << " | " << f("sweeps", 0) << " (" << f("labelled_sweeps", 0) << ") | "
        << f("v_cells_per_sweep", 1) << " | " << f("false_v_per_labelled_sweep", 1) << " | "
        << f("v_on_static_per_labelled_sweep", 1) << " | " << f("mover_cells_v_share", 2) << " | "
        << (m.at("mover_min_v_share_from_third_sweep") < 0 ? std::string("n/a") : f("mover_min_v_share_from_third_sweep", 2))
        << " | " << (m.at("mover_first_v_delay_s") < 0 ? std::string("never") : f("mover_first_v_delay_s", 2)) << " | "
        << f("static_cells.F", 2) << " / " << f("static_cells.C", 2) << " / " << f("static_cells.N", 2) << " / "
        << f("static_cells.S", 2) << " / " << f("static_cells.V", 2) << " / " << f("static_cells.unknown", 2) << " |\n";
  }
  out << "\nFree space, ground and moving points (doc/evaluation.md, \"Labelled real sweeps\"): labelled-ground cells "
         "decided F (all labelled sweeps; from "
      << std::setprecision(1) << (rows.empty() ? PointLabelScorer::kDefaultSettleTime : rows.front().second->settleTime())
      << " s on), labelled-obstacle cells decided F, the ScanGrid's point-level ground segmentation, point-level "
         "moving IoU.\n\n";
  out << "| variant | ground cells F | ground cells F (settled) | obstacle cells F | obstacle cells F, vegetation left "
         "out | ground precision | ground recall | ground F1 | ground returns called obstacle | moving IoU (points) | "
         "mover cells S |\n";
  out << "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
  for (const auto& [name, scorer] : rows)
  {
    const auto m = scorer->summary();
    auto f = [&](const std::string& k, int digits) {
      const auto i = m.find(k);
      if (i == m.end() || i->second < 0.0) return std::string("–");
      std::ostringstream s;
      s << std::fixed << std::setprecision(digits) << i->second;
      return s.str();
    };
    out << "| " << name << " | " << f("ground_cells_f_recall", 3) << " | " << f("ground_cells_f_recall_settled", 3)
        << " | " << f("obstacle_cells_false_free", 4) << " | " << f("rigid_cells_false_free", 4) << " | "
        << f("ground_segmentation.precision", 3) << " | " << f("ground_segmentation.recall", 3) << " | "
        << f("ground_segmentation.f1", 3) << " | " << f("ground_segmentation.ground_as_obstacle", 3) << " | "
        << f("moving_point_iou", 3) << " | " << f("mover_cells_s_share", 3) << " |\n";
  }
  return out.str();
}

}  // namespace eval
}  // namespace map_aided_fusion

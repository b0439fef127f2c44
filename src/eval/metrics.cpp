#include "map_aided_fusion/eval/metrics.hpp"

#include <cmath>
#include <cstdio>
#include <set>
#include <sstream>

namespace map_aided_fusion {
namespace eval {

using core::CellClass;

namespace {

constexpr int kMoving = static_cast<int>(CellClass::kMoving);
constexpr int kStopped = static_cast<int>(CellClass::kStopped);
constexpr int kFree = static_cast<int>(CellClass::kFree);

double ratio(double a, double b) { return b > 0.0 ? a / b : 0.0; }

std::string number(double v)
{
  if (!std::isfinite(v)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

/// Per judged object of the tracks' CLEAR-MOT (ClearMot::records()), a JSON array.
std::string trackObjectsJson(const ClearMot& tracks)
{
  std::ostringstream out;
  out << "[";
  bool first = true;
  for (const MotObjectRecord& r : tracks.records())
  {
    out << (first ? "" : ", ") << "{\"id\": " << r.id << ", \"frames\": " << r.frames
        << ", \"tracked_frames\": " << r.tracked_frames << ", \"identity_share\": " << number(r.identity_share)
        << ", \"id_switches\": " << r.id_switches << ", \"fragmentations\": " << r.fragmentations
        << ", \"velocity_pairs\": " << r.velocity_pairs << ", \"velocity_rmse_mps\": " << number(r.velocity_rmse)
        << ", \"velocity_median_mps\": " << number(r.velocity_median)
        << ", \"velocity_error_share\": " << number(r.velocity_error_share) << "}";
    first = false;
  }
  out << "]";
  return out.str();
}

std::string escape(const std::string& s)
{
  std::string out;
  for (char c : s)
  {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out;
}

void metaJson(std::ostringstream& out, const std::map<std::string, std::string>& meta);

}  // namespace

std::int8_t ClassGrid::at(core::Point2 p) const
{
  core::CellIndex c;
  if (!geometry.worldToCell(p, c)) return static_cast<std::int8_t>(CellClass::kUnknown);
  return cells[geometry.index(c)];
}

void ConfusionMatrix::add(int truth, int decision, std::uint64_t count)
{
  if (truth < 0 || truth >= kNumCellClasses) return;
  const int col = decision >= 0 && decision < kNumCellClasses ? decision : kUnknownColumn;
  counts_[truth][col] += count;
}

void ConfusionMatrix::add(const ConfusionMatrix& other)
{
  for (int t = 0; t < kNumCellClasses; ++t)
    for (int d = 0; d <= kNumCellClasses; ++d) counts_[t][d] += other.counts_[t][d];
}

double ConfusionMatrix::precision(int c) const
{
  double decided = 0;
  for (int t = 0; t < kNumCellClasses; ++t) decided += counts_[t][c];
  return ratio(counts_[c][c], decided);
}

double ConfusionMatrix::recall(int c) const { return ratio(counts_[c][c], support(c)); }

double ConfusionMatrix::iou(int c) const
{
  double decided = 0;
  for (int t = 0; t < kNumCellClasses; ++t) decided += counts_[t][c];
  const double tp = counts_[c][c];
  return ratio(tp, decided + support(c) - tp);
}

std::uint64_t ConfusionMatrix::support(int c) const
{
  std::uint64_t s = 0;
  for (int d = 0; d <= kNumCellClasses; ++d) s += counts_[c][d];
  return s;
}

double ConfusionMatrix::coverage() const
{
  double all = 0, unknown = 0;
  for (int t = 0; t < kNumCellClasses; ++t)
  {
    all += support(t);
    unknown += counts_[t][kUnknownColumn];
  }
  return ratio(all - unknown, all);
}

double ConfusionMatrix::accuracy() const
{
  double decided = 0, right = 0;
  for (int t = 0; t < kNumCellClasses; ++t)
  {
    right += counts_[t][t];
    for (int d = 0; d < kNumCellClasses; ++d) decided += counts_[t][d];
  }
  return ratio(right, decided);
}

double ConfusionMatrix::meanIou() const
{
  double s = 0;
  int n = 0;
  for (int c = 0; c < kNumCellClasses; ++c)
    if (support(c) > 0)
    {
      s += iou(c);
      ++n;
    }
  return ratio(s, n);
}

std::uint64_t accumulate(const ClassGrid& truth, const ClassGrid& decision, ConfusionMatrix& m)
{
  std::uint64_t compared = 0;
  const auto& g = truth.geometry;
  for (std::size_t i = 0; i < truth.cells.size(); ++i)
  {
    const int t = truth.cells[i];
    if (t < 0 || t >= kNumCellClasses) continue;
    m.add(t, decision.at(g.cellCentre(g.cellOf(i))));
    ++compared;
  }
  return compared;
}

bool TruthObject::contains(core::Point2 p, double margin) const
{
  const double dx = p.x - centre.x, dy = p.y - centre.y;
  const double c = std::cos(yaw), s = std::sin(yaw);
  const double u = c * dx + s * dy, v = -s * dx + c * dy;
  return std::abs(u) <= 0.5 * length + margin && std::abs(v) <= 0.5 * width + margin;
}

ObjectScorer::ObjectScorer(int min_visible_cells, double detection_window, double hidden_window)
  : min_visible_(min_visible_cells), window_(detection_window), hidden_window_(hidden_window)
{
}

void ObjectScorer::add(double stamp, const ClassGrid& truth, const std::vector<TruthObject>& objects,
                       const ClassGrid& decision)
{
  ++scans_;
  const auto& g = truth.geometry;
  for (std::size_t i = 0; i < truth.cells.size(); ++i)
  {
    if (truth.cells[i] != kFree) continue;
    ++free_cells_;
    trail_cells_ += decision.at(g.cellCentre(g.cellOf(i))) == kMoving;
  }
  for (const auto& o : objects)
  {
    const int cls = static_cast<int>(o.cell_class);
    if (cls != kMoving && cls != kStopped) continue;
    // Footprint cells of the object observed with its class.
    const double r = 0.5 * std::hypot(o.length, o.width);
    const core::CellIndex lo = g.cellAt(core::Point2{ o.centre.x - r, o.centre.y - r });
    const core::CellIndex hi = g.cellAt(core::Point2{ o.centre.x + r, o.centre.y + r });
    int visible = 0, as_moving = 0, as_stopped = 0, footprint = 0, footprint_stopped = 0;
    for (int y = std::max(0, lo.y); y <= std::min(g.height - 1, hi.y); ++y)
      for (int x = std::max(0, lo.x); x <= std::min(g.width - 1, hi.x); ++x)
      {
        const core::Point2 p = g.cellCentre(core::CellIndex{ x, y });
        if (!o.contains(p)) continue;
        const int d = decision.at(p);
        ++footprint;
        footprint_stopped += d == kStopped;
        if (truth.cells[g.index(x, y)] != cls) continue;
        ++visible;
        as_moving += d == kMoving;
        as_stopped += d == kStopped;
      }
    if (visible < min_visible_)
    {
      auto last = stopped_last_visible_.find(o.id);
      if (cls == kStopped && footprint > 0 && last != stopped_last_visible_.end() &&
          stamp - last->second <= hidden_window_)
      {
        ++hidden_pairs_;
        hidden_kept_ += 2 * footprint_stopped > footprint;
      }
      continue;
    }
    if (cls == kStopped) stopped_last_visible_[o.id] = stamp;
    if (cls == kMoving)
    {
      Track& t = moving_[o.id];
      if (t.first_visible < 0.0) t.first_visible = stamp;
      if (t.first_detected < 0.0 && 2 * as_moving > visible) t.first_detected = stamp;
    }
    else
    {
      ++stopped_pairs_;
      stopped_moving_ += 2 * as_moving > visible;
      stopped_stopped_ += 2 * as_stopped > visible;
    }
  }
}

int ObjectScorer::movingVisible() const { return static_cast<int>(moving_.size()); }

int ObjectScorer::movingDetected() const
{
  int n = 0;
  for (const auto& [id, t] : moving_) n += t.first_detected >= 0.0 && t.first_detected - t.first_visible <= window_;
  return n;
}

double ObjectScorer::meanDetectionDelay() const
{
  double s = 0;
  int n = 0;
  for (const auto& [id, t] : moving_)
    if (t.first_detected >= 0.0)
    {
      s += t.first_detected - t.first_visible;
      ++n;
    }
  return n ? s / n : std::nan("");
}

double ObjectScorer::stoppedCalledMoving() const { return ratio(stopped_moving_, stopped_pairs_); }
double ObjectScorer::stoppedRecognised() const { return ratio(stopped_stopped_, stopped_pairs_); }
double ObjectScorer::stoppedKeptWhileHidden() const { return ratio(hidden_kept_, hidden_pairs_); }
double ObjectScorer::trailCellsPerScan() const { return ratio(trail_cells_, scans_); }
double ObjectScorer::trailFraction() const { return ratio(trail_cells_, free_cells_); }

std::map<std::string, double> flatten(const VariantScores& v)
{
  std::map<std::string, double> m;
  for (int c = 0; c < kNumCellClasses; ++c)
  {
    const std::string name(core::kCellClassLongNames[c]);
    m[name + ".precision"] = v.confusion.precision(c);
    m[name + ".recall"] = v.confusion.recall(c);
    m[name + ".iou"] = v.confusion.iou(c);
    m[name + ".support_cells"] = static_cast<double>(v.confusion.support(c));
  }
  m["cells.mean_iou"] = v.confusion.meanIou();
  m["cells.accuracy"] = v.confusion.accuracy();
  m["cells.coverage"] = v.confusion.coverage();
  m["objects.moving.visible"] = v.objects.movingVisible();
  m["objects.moving.detected_within_1s"] = v.objects.movingDetected();
  m["objects.moving.detection_rate"] = ratio(v.objects.movingDetected(), v.objects.movingVisible());
  m["objects.moving.mean_detection_delay_s"] = v.objects.meanDetectionDelay();
  m["objects.stopped.called_moving_rate"] = v.objects.stoppedCalledMoving();
  m["objects.stopped.recognised_rate"] = v.objects.stoppedRecognised();
  m["objects.stopped.hidden_scans"] = static_cast<double>(v.objects.stoppedHiddenPairs());
  m["objects.stopped.kept_while_hidden_rate"] = v.objects.stoppedKeptWhileHidden();
  m["moving.trail_cells_per_scan"] = v.objects.trailCellsPerScan();
  m["moving.trail_fraction_of_free"] = v.objects.trailFraction();
  m["scans"] = static_cast<double>(v.scans);
  if (!v.movers.stamps().empty())
    for (const auto& [k, x] : v.movers.summary()) m[k] = x;
  if (v.tracks.frames() > 0)
    for (const auto& [k, x] : v.tracks.summary()) m["tracks." + k] = x;
  return m;
}

std::string toJson(const std::vector<VariantScores>& variants, const std::map<std::string, std::string>& meta)
{
  std::ostringstream out;
  metaJson(out, meta);
  for (std::size_t i = 0; i < variants.size(); ++i)
  {
    const auto& v = variants[i];
    out << (i ? ",\n" : "\n") << "    \"" << escape(v.name) << "\": {\n      \"description\": \"" << escape(v.description)
        << "\"";
    for (const auto& [k, x] : flatten(v)) out << ",\n      \"" << k << "\": " << number(x);
    out << ",\n      \"confusion\": {\"rows_truth\": [\"F\", \"C\", \"N\", \"S\", \"V\"], "
           "\"columns_decision\": [\"F\", \"C\", \"N\", \"S\", \"V\", \"unknown\"], \"counts\": [";
    for (int t = 0; t < kNumCellClasses; ++t)
    {
      out << (t ? ", [" : "[");
      for (int d = 0; d <= kNumCellClasses; ++d) out << (d ? ", " : "") << v.confusion.count(t, d);
      out << "]";
    }
    out << "]}";
    if (!v.movers.stamps().empty()) out << ",\n      \"movers_objects\": " << moverObjectsJson(v.movers);
    if (v.tracks.frames() > 0) out << ",\n      \"tracks_objects\": " << trackObjectsJson(v.tracks);
    out << "\n    }";
  }
  out << "\n  }\n}\n";
  return out.str();
}

namespace {

void metaJson(std::ostringstream& out, const std::map<std::string, std::string>& meta)
{
  out << "{\n  \"meta\": {";
  bool first = true;
  for (const auto& [k, v] : meta)
  {
    out << (first ? "\n" : ",\n") << "    \"" << escape(k) << "\": \"" << escape(v) << "\"";
    first = false;
  }
  out << "\n  },\n  \"variants\": {";
}

}  // namespace

std::string moversJson(const std::vector<VariantScores>& variants, const std::map<std::string, std::string>& meta)
{
  std::ostringstream out;
  metaJson(out, meta);
  for (std::size_t i = 0; i < variants.size(); ++i)
  {
    const auto& v = variants[i];
    out << (i ? ",\n" : "\n") << "    \"" << escape(v.name) << "\": {\n      \"description\": \"" << escape(v.description)
        << "\",\n      \"scans\": " << v.scans;
    for (const auto& [k, x] : v.movers.summary()) out << ",\n      \"" << k << "\": " << number(x);
    if (v.tracks.frames() > 0)
      for (const auto& [k, x] : v.tracks.summary()) out << ",\n      \"tracks." << k << "\": " << number(x);
    out << ",\n      \"movers_objects\": " << moverObjectsJson(v.movers);
    if (v.tracks.frames() > 0) out << ",\n      \"tracks_objects\": " << trackObjectsJson(v.tracks);
    out << "\n    }";
  }
  out << "\n  }\n}\n";
  return out.str();
}

std::vector<MotObject> motObjects(const std::vector<TruthObject>& objects, const std::vector<ObjectSighting>& sightings,
                                  const MoverScorer& scorer)
{
  std::set<std::uint32_t> seen;
  for (const ObjectSighting& s : sightings)
    if (s.motion == MotionTruth::kMoving && scorer.seen(s)) seen.insert(s.id);
  std::vector<MotObject> out;
  out.reserve(objects.size());
  for (const TruthObject& o : objects)
  {
    if (o.cell_class != CellClass::kMoving && o.cell_class != CellClass::kStopped &&
        o.cell_class != CellClass::kUnknown)
      continue;
    MotObject m;
    m.id = o.id;
    m.position = o.centre;
    m.judged = o.cell_class == CellClass::kMoving && seen.count(o.id);
    m.has_velocity = true;
    m.velocity = core::Point2{ o.vx, o.vy };
    m.length = o.length;
    m.width = o.width;
    m.yaw = o.yaw;
    out.push_back(m);
  }
  return out;
}

std::string tracksMarkdown(const std::vector<VariantScores>& variants)
{
  std::ostringstream out;
  char buf[64];
  auto f = [&buf](double v, int digits) {
    if (!std::isfinite(v)) return std::string("–");
    std::snprintf(buf, sizeof buf, "%.*f", digits, v);
    return std::string(buf);
  };
  bool any = false;
  for (const auto& v : variants) any = any || v.tracks.frames() > 0;
  if (!any) return "";
  out << "| variant | MOTA | MOTP (m) | movers × sweeps | matched | misses | false positives | id switches | "
         "fragmentations | velocity RMSE (m/s) | velocity median (m/s) |\n";
  out << "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
  for (const auto& v : variants)
  {
    const ClearMot& t = v.tracks;
    if (t.frames() == 0) continue;
    out << "| " << v.name << " | " << f(t.mota(), 3) << " | " << f(t.motp(), 2) << " | " << t.objects() << " | "
        << t.matches() << " | " << t.misses() << " | " << t.falsePositives() << " | " << t.idSwitches() << " | "
        << t.fragmentations() << " | " << f(t.velocityRmse(), 2) << " | " << f(t.velocityMedian(), 2) << " |\n";
  }
  for (const auto& v : variants)
  {
    if (v.tracks.frames() == 0 || (v.name != "default" && v.name.rfind("live", 0) != 0)) continue;
    out << "\nPer mover, tracks of `" << v.name << "` (velocity errors over its pairs with a velocity; share: of the "
           "squared velocity error of all movers):\n\n| id | sweeps moving | tracked as moving | identity share | "
           "id switches | fragmentations | velocity pairs | velocity RMSE (m/s) | velocity median (m/s) | share of "
           "the squared velocity error |\n| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
    for (const MotObjectRecord& r : v.tracks.records())
      out << "| " << r.id << " | " << r.frames << " | " << r.tracked_frames << " | " << f(r.identity_share, 2) << " | "
          << r.id_switches << " | " << r.fragmentations << " | " << r.velocity_pairs << " | " << f(r.velocity_rmse, 2)
          << " | " << f(r.velocity_median, 2) << " | " << f(r.velocity_error_share, 2) << " |\n";
  }
  return out.str();
}

std::string toMarkdown(const std::vector<VariantScores>& variants)
{
  std::ostringstream out;
  out << "| variant | IoU F | IoU C | IoU N | IoU S | IoU V | mean IoU | V recall | V precision | moving objects "
         "detected ≤ 1 s | stopped called moving | V trail (cells/scan) | coverage |\n";
  out << "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
  char buf[64];
  auto f = [&buf](double v) {
    std::snprintf(buf, sizeof buf, "%.3f", v);
    return std::string(buf);
  };
  for (const auto& v : variants)
  {
    out << "| " << v.name;
    for (int c = 0; c < kNumCellClasses; ++c) out << " | " << f(v.confusion.iou(c));
    out << " | " << f(v.confusion.meanIou()) << " | " << f(v.confusion.recall(kMoving)) << " | "
        << f(v.confusion.precision(kMoving)) << " | " << v.objects.movingDetected() << "/" << v.objects.movingVisible()
        << " | " << f(v.objects.stoppedCalledMoving()) << " | ";
    std::snprintf(buf, sizeof buf, "%.1f", v.objects.trailCellsPerScan());
    out << buf << " | " << f(v.confusion.coverage()) << " |\n";
  }
  out << "\n";
  for (const auto& v : variants) out << "- **" << v.name << "**: " << v.description << "\n";

  // Where V goes wrong: cells decided V whose truth is another class, per scan, and facades decided S or V.
  out << "\nFalse V (cells decided V whose truth is another class) per scan, by true class; facade (truth C) cells "
         "decided S or V:\n\n";
  out << "| variant | on F (road, free ground) | on C (facades) | on N | on S | total | facade S or V |\n";
  out << "| --- | ---: | ---: | ---: | ---: | ---: | ---: |\n";
  constexpr int kBuildingClass = static_cast<int>(CellClass::kBuilding);
  for (const auto& v : variants)
  {
    const double scans = static_cast<double>(std::max<std::uint64_t>(1, v.scans));
    out << "| " << v.name;
    std::uint64_t total = 0;
    for (const int c : { kFree, kBuildingClass, static_cast<int>(CellClass::kInfrastructure), kStopped })
    {
      total += v.confusion.count(c, kMoving);
      std::snprintf(buf, sizeof buf, "%.2f", static_cast<double>(v.confusion.count(c, kMoving)) / scans);
      out << " | " << buf;
    }
    std::snprintf(buf, sizeof buf, "%.2f", static_cast<double>(total) / scans);
    out << " | " << buf;
    const std::uint64_t facade = v.confusion.support(kBuildingClass);
    std::snprintf(buf, sizeof buf, "%.1f %%",
                  facade ? 100.0 * static_cast<double>(v.confusion.count(kBuildingClass, kStopped) +
                                                       v.confusion.count(kBuildingClass, kMoving)) /
                               static_cast<double>(facade) :
                           0.0);
    out << " | " << buf << " |\n";
  }
  return out.str();
}

}  // namespace eval
}  // namespace map_aided_fusion

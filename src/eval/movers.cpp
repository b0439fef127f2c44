#include "map_aided_fusion/eval/movers.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <sstream>
#include <unordered_set>

namespace map_aided_fusion {
namespace eval {

using core::CellClass;

namespace {

constexpr int kUnknownSlot = kNumCellClasses + 1;
constexpr double kWindowHalf = 0.5;   // s: "detected within 0.5 s"
constexpr double kWindowOne = 1.0;    // s: "detected within 1 s"
constexpr double kStampSlack = 1e-6;  // s, stamps are rounded to ns
constexpr const char* kAll = "all";

int slotOf(std::int8_t code)
{
  return code >= 0 && code <= static_cast<int>(CellClass::kOccupied) ? code : kUnknownSlot;
}

std::string lower(std::string s)
{
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

/// The cells of @p g whose centre lies in the footprint of @p o.
template <typename F>
void forFootprintCells(const core::GridGeometry& g, const TruthObject& o, F&& f)
{
  const double r = 0.5 * std::hypot(o.length, o.width);
  const core::CellIndex lo = g.cellAt(core::Point2{ o.centre.x - r, o.centre.y - r });
  const core::CellIndex hi = g.cellAt(core::Point2{ o.centre.x + r, o.centre.y + r });
  for (int y = std::max(0, lo.y); y <= std::min(g.height - 1, hi.y); ++y)
    for (int x = std::max(0, lo.x); x <= std::min(g.width - 1, hi.x); ++x)
      if (o.contains(g.cellCentre(core::CellIndex{ x, y }))) f(g.index(x, y));
}

ObjectSighting baseSighting(const TruthObject& o, MotionTruth motion)
{
  ObjectSighting s;
  s.id = o.id;
  s.kind = o.kind;
  s.motion = motion;
  s.speed = o.speed;
  return s;
}

std::string fixed(double v, int digits)
{
  if (!std::isfinite(v)) return "–";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

std::string jsonNumber(double v)
{
  if (!std::isfinite(v)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

double medianDelay(std::vector<double> delays)
{
  // Never detected counts as +infinity.
  if (delays.empty()) return std::nan("");
  std::sort(delays.begin(), delays.end());
  const std::size_t n = delays.size();
  const double m = n % 2 ? delays[n / 2] : 0.5 * (delays[n / 2 - 1] + delays[n / 2]);
  return std::isfinite(m) ? m : std::nan("");
}

}  // namespace

const char* groupName(ObjectGroup g)
{
  switch (g)
  {
    case ObjectGroup::kVehicle: return "vehicle";
    case ObjectGroup::kCyclist: return "cyclist";
    case ObjectGroup::kPedestrian: return "pedestrian";
    case ObjectGroup::kOther: break;
  }
  return "other";
}

ObjectGroup groupOf(const std::string& kind)
{
  const std::string k = lower(kind);
  if (k == "car" || k == "van" || k == "bus" || k == "truck" || k == "tram") return ObjectGroup::kVehicle;
  if (k == "cyclist" || k == "bicycle" || k == "motorcyclist") return ObjectGroup::kCyclist;
  if (k == "pedestrian" || k == "person_sitting" || k == "person") return ObjectGroup::kPedestrian;
  return ObjectGroup::kOther;
}

bool motionOf(CellClass cell_class, MotionTruth& motion)
{
  switch (cell_class)
  {
    case CellClass::kMoving: motion = MotionTruth::kMoving; return true;
    case CellClass::kStopped: motion = MotionTruth::kParked; return true;
    case CellClass::kUnknown: motion = MotionTruth::kAmbiguous; return true;
    default: return false;
  }
}

std::uint32_t ObjectSighting::decidedAs(CellClass c) const
{
  return decided[static_cast<std::size_t>(slotOf(static_cast<std::int8_t>(c)))];
}

std::uint32_t SightingRule::needed(std::uint32_t footprint_cells) const
{
  const double share = std::ceil(min_share * static_cast<double>(footprint_cells) - 1e-9);
  const auto n = static_cast<std::uint32_t>(std::max(1.0, std::min(static_cast<double>(min_cells), share)));
  return n;
}

std::vector<ObjectSighting> sightingsFromClassGrid(const ClassGrid& truth, const std::vector<TruthObject>& objects,
                                                   const ClassGrid& decision)
{
  std::vector<ObjectSighting> out;
  const core::GridGeometry& g = decision.geometry;
  for (const TruthObject& o : objects)
  {
    MotionTruth motion;
    if (o.cell_class == CellClass::kUnknown || !motionOf(o.cell_class, motion)) continue;
    ObjectSighting s = baseSighting(o, motion);
    const auto cls = static_cast<std::int8_t>(o.cell_class);
    forFootprintCells(g, o, [&](std::size_t i) {
      ++s.footprint_cells;
      const core::Point2 p = g.cellCentre(g.cellOf(i));
      if (truth.at(p) != cls) return;
      ++s.occupied_cells;
      ++s.decided[static_cast<std::size_t>(slotOf(decision.cells[i]))];
    });
    out.push_back(s);
  }
  return out;
}

std::vector<ObjectReturns> collectObjectReturns(const core::PointCloudView& cloud, const Eigen::Isometry3d& map_sensor,
                                                const Eigen::Isometry3d& base_sensor,
                                                const std::vector<TruthObject>& objects, const ReturnsInBoxes& rule)
{
  std::vector<ObjectReturns> out(objects.size());
  std::vector<double> reach(objects.size());
  for (std::size_t j = 0; j < objects.size(); ++j)
  {
    out[j].object = objects[j];
    reach[j] = 0.5 * std::hypot(objects[j].length, objects[j].width) + rule.margin;
  }
  if (objects.empty() || !cloud.data) return out;
  for (std::size_t r = 0; r < cloud.height; ++r)
    for (std::size_t c = 0; c < cloud.width; ++c)
    {
      const std::uint8_t* p = cloud.data + r * cloud.row_step + c * cloud.point_step;
      float xyz[3];
      std::memcpy(&xyz[0], p + cloud.x_offset, sizeof(float));
      std::memcpy(&xyz[1], p + cloud.y_offset, sizeof(float));
      std::memcpy(&xyz[2], p + cloud.z_offset, sizeof(float));
      if (!std::isfinite(xyz[0]) || !std::isfinite(xyz[1]) || !std::isfinite(xyz[2])) continue;
      const Eigen::Vector3d v(xyz[0], xyz[1], xyz[2]);
      const double z = (base_sensor * v).z();
      if (z < rule.obstacle_low || z > rule.obstacle_high) continue;
      const Eigen::Vector3d m = map_sensor * v;
      const core::Point2 q{ m.x(), m.y() };
      for (std::size_t j = 0; j < objects.size(); ++j)
      {
        const TruthObject& o = objects[j];
        if (std::abs(q.x - o.centre.x) > reach[j] || std::abs(q.y - o.centre.y) > reach[j]) continue;
        if (o.height > 0.0 && std::abs(m.z() - o.z) > 0.5 * o.height + rule.margin) continue;
        if (o.contains(q, rule.margin)) out[j].returns.push_back(q);
      }
    }
  return out;
}

std::vector<ObjectSighting> sightingsFromReturns(const std::vector<ObjectReturns>& objects, const ClassGrid& decision)
{
  std::vector<ObjectSighting> out;
  const core::GridGeometry& g = decision.geometry;
  std::unordered_set<std::size_t> cells;
  for (const ObjectReturns& r : objects)
  {
    MotionTruth motion;
    if (!motionOf(r.object.cell_class, motion)) continue;
    ObjectSighting s = baseSighting(r.object, motion);
    forFootprintCells(g, r.object, [&](std::size_t) { ++s.footprint_cells; });
    cells.clear();
    for (const core::Point2& p : r.returns)
    {
      core::CellIndex c;
      if (g.worldToCell(p, c)) cells.insert(g.index(c));
    }
    for (std::size_t i : cells)
    {
      ++s.occupied_cells;
      ++s.decided[static_cast<std::size_t>(slotOf(decision.cells[i]))];
    }
    out.push_back(s);
  }
  return out;
}

std::uint64_t countFalseV(const ClassGrid& decision, const ClassGrid* valid, const std::vector<TruthObject>& objects,
                          double radius)
{
  const auto moving = static_cast<std::int8_t>(CellClass::kMoving);
  const core::GridGeometry& g = decision.geometry;
  std::uint64_t n = 0;
  for (std::size_t i = 0; i < decision.cells.size(); ++i)
  {
    if (decision.cells[i] != moving) continue;
    const core::Point2 p = g.cellCentre(g.cellOf(i));
    if (valid && valid->at(p) <= 0) continue;
    bool near = false;
    for (const TruthObject& o : objects)
      if ((o.cell_class == CellClass::kMoving || o.cell_class == CellClass::kUnknown) && o.contains(p, radius))
      {
        near = true;
        break;
      }
    n += !near;
  }
  return n;
}

MoverScorer::MoverScorer(SightingRule rule) : rule_(rule) {}

void MoverScorer::add(double stamp, const std::vector<ObjectSighting>& sightings, std::uint64_t false_v)
{
  const std::size_t scan = stamps_.size();
  stamps_.push_back(stamp);
  false_v_ += false_v;
  for (const ObjectSighting& s : sightings)
  {
    MoverRecord& r = records_[s.id];
    r.id = s.id;
    if (r.kind.empty())
    {
      r.kind = s.kind;
      r.group = groupOf(s.kind);
    }
    r.max_speed = std::max(r.max_speed, s.speed);
    const bool seen = this->seen(s);
    const std::uint32_t v = s.decidedAs(CellClass::kMoving), st = s.decidedAs(CellClass::kStopped);
    if (s.motion == MotionTruth::kMoving)
    {
      ++r.moving_scans;
      SightingState state = SightingState::kUnseen;
      if (seen)
      {
        ++r.seen_moving;
        const bool is_v = 2 * v > s.occupied_cells;
        state = is_v ? SightingState::kV : 2 * st > s.occupied_cells ? SightingState::kS : SightingState::kOther;
        r.v_scans += is_v;
        r.occupied += s.occupied_cells;
        r.occupied_v += v;
        r.occupied_s += st;
        if (r.first_seen < 0.0) r.first_seen = stamp;
        if (is_v && r.first_detected < 0.0) r.first_detected = stamp;
      }
      r.timeline.emplace_back(scan, state);
    }
    else if (s.motion == MotionTruth::kParked && seen)
    {
      ++r.parked_seen;
      r.parked_occupied += s.occupied_cells;
      r.parked_v += v;
    }
  }
}

double MoverScorer::falseVPerScan() const
{
  return stamps_.empty() ? 0.0 : static_cast<double>(false_v_) / static_cast<double>(stamps_.size());
}

std::map<std::string, double> MoverScorer::summary() const
{
  std::map<std::string, double> m;
  auto group = [&](const std::string& name, auto&& in_group) {
    int labelled = 0, seen = 0, half = 0, one = 0, never = 0, parked = 0;
    double v_share = 0.0;
    std::uint64_t occupied = 0, occupied_s = 0, parked_cells = 0, parked_v = 0;
    std::vector<double> delays;
    for (const auto& [id, r] : records_)
    {
      if (!in_group(r)) continue;
      if (r.parked_seen > 0)
      {
        ++parked;
        parked_cells += r.parked_occupied;
        parked_v += r.parked_v;
      }
      if (!r.isMover()) continue;
      ++labelled;
      if (r.seen_moving == 0) continue;
      ++seen;
      const double d = r.delay();
      if (d < 0.0)
      {
        ++never;
        delays.push_back(std::numeric_limits<double>::infinity());
      }
      else
      {
        half += d <= kWindowHalf + kStampSlack;
        one += d <= kWindowOne + kStampSlack;
        delays.push_back(d);
      }
      v_share += r.vShare();
      occupied += r.occupied;
      occupied_s += r.occupied_s;
    }
    const std::string p = "movers." + name + ".";
    m[p + "labelled"] = labelled;
    m[p + "seen"] = seen;
    m[p + "detected_within_0_5s"] = half;
    m[p + "detected_within_1s"] = one;
    m[p + "never_detected"] = never;
    m[p + "median_delay_s"] = medianDelay(delays);
    m[p + "mean_v_share"] = seen ? v_share / seen : 0.0;
    m[p + "s_share"] = occupied ? static_cast<double>(occupied_s) / static_cast<double>(occupied) : 0.0;
    m["parked." + name + ".objects"] = parked;
    m["parked." + name + ".v_share"] =
        parked_cells ? static_cast<double>(parked_v) / static_cast<double>(parked_cells) : 0.0;
  };
  group(kAll, [](const MoverRecord&) { return true; });
  for (int g = 0; g < kNumObjectGroups; ++g)
    group(groupName(static_cast<ObjectGroup>(g)),
          [g](const MoverRecord& r) { return r.group == static_cast<ObjectGroup>(g); });
  m["movers.false_v_per_scan"] = falseVPerScan();
  m["movers.scans"] = static_cast<double>(stamps_.size());
  return m;
}

std::string moversMarkdown(const std::vector<std::pair<std::string, const MoverScorer*>>& rows, bool per_kind)
{
  std::ostringstream out;
  out << "| variant | kind | movers seen | detected ≤ 0.5 s | detected ≤ 1 s | never V | median delay (s) | "
         "mean V share | S share (cells) | parked objects | parked V share (cells) | false V / scan |\n";
  out << "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
  for (const auto& [name, scorer] : rows)
  {
    const auto s = scorer->summary();
    std::vector<std::string> groups{ kAll };
    for (int g = 0; per_kind && g < kNumObjectGroups; ++g)
    {
      const std::string gn = groupName(static_cast<ObjectGroup>(g));
      if (s.at("movers." + gn + ".seen") > 0 || s.at("parked." + gn + ".objects") > 0) groups.push_back(gn);
    }
    for (const std::string& g : groups)
    {
      const std::string p = "movers." + g + ".", q = "parked." + g + ".";
      const int seen = static_cast<int>(s.at(p + "seen"));
      out << "| " << name << " | " << g << " | " << seen << " | " << static_cast<int>(s.at(p + "detected_within_0_5s"))
          << "/" << seen << " | " << static_cast<int>(s.at(p + "detected_within_1s")) << "/" << seen << " | "
          << static_cast<int>(s.at(p + "never_detected")) << " | "
          << (seen ? (std::isfinite(s.at(p + "median_delay_s")) ? fixed(s.at(p + "median_delay_s"), 1) : "never")
                   : "–")
          << " | " << (seen ? fixed(s.at(p + "mean_v_share"), 2) : "–") << " | "
          << (seen ? fixed(s.at(p + "s_share"), 2) : "–") << " | " << static_cast<int>(s.at(q + "objects")) << " | "
          << (s.at(q + "objects") > 0 ? fixed(s.at(q + "v_share"), 3) : "–") << " | "
          << (g == kAll ? fixed(s.at("movers.false_v_per_scan"), 2) : "") << " |\n";
    }
  }
  return out.str();
}

std::string moverObjectsMarkdown(const MoverScorer& scorer)
{
  std::ostringstream out;
  out << "| id | kind | max speed (m/s) | scans moving | seen | first seen (s) | first V (s) | delay (s) | V share | "
         "V share (cells) | S share (cells) |\n";
  out << "| ---: | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
  const double t0 = scorer.stamps().empty() ? 0.0 : scorer.stamps().front();
  for (const auto& [id, r] : scorer.records())
  {
    if (!r.isMover()) continue;
    const bool seen = r.seen_moving > 0;
    out << "| " << id << " | " << r.kind << " | " << fixed(r.max_speed, 1) << " | " << r.moving_scans << " | "
        << r.seen_moving << " | " << (seen ? fixed(r.first_seen - t0, 1) : "never") << " | "
        << (r.first_detected >= 0.0 ? fixed(r.first_detected - t0, 1) : "never") << " | "
        << (r.delay() >= 0.0 ? fixed(r.delay(), 1) : "–") << " | " << (seen ? fixed(r.vShare(), 2) : "–") << " | "
        << (seen ? fixed(r.vCellShare(), 2) : "–") << " | " << (seen ? fixed(r.sShare(), 2) : "–") << " |\n";
  }
  return out.str();
}

std::string moverObjectsJson(const MoverScorer& scorer)
{
  std::ostringstream out;
  const double t0 = scorer.stamps().empty() ? 0.0 : scorer.stamps().front();
  out << "{\"stamps\": [";
  for (std::size_t k = 0; k < scorer.stamps().size(); ++k) out << (k ? ", " : "") << jsonNumber(scorer.stamps()[k] - t0);
  out << "], \"objects\": [";
  bool first = true;
  for (const auto& [id, r] : scorer.records())
  {
    out << (first ? "" : ", ") << "{\"id\": " << id << ", \"kind\": \"" << r.kind << "\", \"group\": \""
        << groupName(r.group) << "\", \"mover\": " << (r.isMover() ? "true" : "false")
        << ", \"max_speed\": " << jsonNumber(r.max_speed)
        << ", \"first_seen_s\": " << (r.first_seen >= 0.0 ? jsonNumber(r.first_seen - t0) : "null")
        << ", \"first_detected_s\": " << (r.first_detected >= 0.0 ? jsonNumber(r.first_detected - t0) : "null")
        << ", \"delay_s\": " << (r.delay() >= 0.0 ? jsonNumber(r.delay()) : "null")
        << ", \"seen_scans\": " << r.seen_moving << ", \"occupied_cells\": " << r.occupied
        << ", \"v_share\": " << jsonNumber(r.vShare()) << ", \"v_cell_share\": " << jsonNumber(r.vCellShare())
        << ", \"s_share\": " << jsonNumber(r.sShare()) << ", \"parked_v_share\": "
        << (r.parked_occupied ? jsonNumber(static_cast<double>(r.parked_v) / static_cast<double>(r.parked_occupied))
                              : "null")
        << ", \"timeline\": [";
    for (std::size_t k = 0; k < r.timeline.size(); ++k)
      out << (k ? ", " : "") << "[" << r.timeline[k].first << ", " << static_cast<int>(r.timeline[k].second) << "]";
    out << "]}";
    first = false;
  }
  out << "]}";
  return out.str();
}

}  // namespace eval
}  // namespace map_aided_fusion

#include "map_aided_fusion/eval/clear_mot.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

#include "map_aided_fusion/core/assignment.hpp"

namespace map_aided_fusion {
namespace eval {

namespace {

double distance(core::Point2 a, core::Point2 b) { return std::hypot(a.x - b.x, a.y - b.y); }

/// Distance from @p p to the footprint of @p o (0 inside it).
double distanceToFootprint(const MotObject& o, core::Point2 p)
{
  const double dx = p.x - o.position.x, dy = p.y - o.position.y;
  const double c = std::cos(o.yaw), s = std::sin(o.yaw);
  const double u = std::max(0.0, std::abs(c * dx + s * dy) - 0.5 * std::max(0.0, o.length));
  const double v = std::max(0.0, std::abs(-s * dx + c * dy) - 0.5 * std::max(0.0, o.width));
  return std::hypot(u, v);
}

double sumOfSquares(const std::vector<double>& v)
{
  double s = 0.0;
  for (double e : v) s += e * e;
  return s;
}

double rms(const std::vector<double>& v)
{
  return v.empty() ? std::nan("") : std::sqrt(sumOfSquares(v) / static_cast<double>(v.size()));
}

double median(std::vector<double> v)
{
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

ClearMot::ClearMot(double match_distance) : threshold_(match_distance)
{
  if (!(match_distance > 0.0) || !std::isfinite(match_distance))
    throw std::invalid_argument("ClearMot: match_distance must be a finite distance > 0 m");
}

void ClearMot::addFrame(const std::vector<MotObject>& objects, const std::vector<MotHypothesis>& hypotheses)
{
  ++frames_;
  std::vector<int> judged, ignored;
  for (int i = 0; i < static_cast<int>(objects.size()); ++i) (objects[i].judged ? judged : ignored).push_back(i);
  std::map<std::uint32_t, int> hyp_index;
  for (int j = 0; j < static_cast<int>(hypotheses.size()); ++j) hyp_index[hypotheses[j].id] = j;

  std::vector<int> object_to_hyp(objects.size(), -1);
  std::vector<char> hyp_used(hypotheses.size(), 0);
  // 1. Keep last frame's pairs that are still within the match distance.
  for (int i : judged)
  {
    const auto prev = previous_.find(objects[i].id);
    if (prev == previous_.end()) continue;
    const auto h = hyp_index.find(prev->second);
    if (h == hyp_index.end() || hyp_used[h->second]) continue;
    if (distance(objects[i].position, hypotheses[h->second].position) > threshold_) continue;
    object_to_hyp[i] = h->second;
    hyp_used[h->second] = 1;
  }
  // 2. Pair the rest by a gated global assignment.
  std::vector<int> free_objects, free_hyps;
  for (int i : judged)
    if (object_to_hyp[i] < 0) free_objects.push_back(i);
  for (int j = 0; j < static_cast<int>(hypotheses.size()); ++j)
    if (!hyp_used[j]) free_hyps.push_back(j);
  core::CostMatrix cost(static_cast<int>(free_objects.size()), static_cast<int>(free_hyps.size()));
  for (int r = 0; r < cost.rows; ++r)
    for (int c = 0; c < cost.cols; ++c)
    {
      const double d = distance(objects[free_objects[r]].position, hypotheses[free_hyps[c]].position);
      if (d <= threshold_) cost.at(r, c) = d;
    }
  const std::vector<int> pairs = core::solveAssignment(cost);
  for (int r = 0; r < cost.rows; ++r)
    if (pairs[r] >= 0)
    {
      object_to_hyp[free_objects[r]] = free_hyps[pairs[r]];
      hyp_used[free_hyps[pairs[r]]] = 1;
    }
  // 3. Hypotheses on (within the match distance of the footprint of) objects that are not judged are left out.
  if (!ignored.empty())
  {
    std::vector<int> rest;
    for (int j = 0; j < static_cast<int>(hypotheses.size()); ++j)
      if (!hyp_used[j]) rest.push_back(j);
    for (int j : rest)
      for (int i : ignored)
        if (distanceToFootprint(objects[i], hypotheses[j].position) <= threshold_)
        {
          hyp_used[j] = 2;
          break;
        }
  }
  // 4. Counts.
  std::map<std::uint32_t, std::uint32_t> now;
  std::set<std::uint32_t> present;
  for (int i : judged)
  {
    const MotObject& o = objects[i];
    present.insert(o.id);
    History& h = history_[o.id];
    ++objects_;
    ++h.frames;
    const int j = object_to_hyp[i];
    if (j < 0)
    {
      ++misses_;
      if (h.tracked_now) ++h.pending_gaps;
      h.tracked_now = false;
      continue;
    }
    const MotHypothesis& hyp = hypotheses[j];
    ++matches_;
    ++h.tracked;
    ++h.paired_with[hyp.id];
    distance_sum_ += distance(o.position, hyp.position);
    if (h.last_hypothesis >= 0 && static_cast<std::uint32_t>(h.last_hypothesis) != hyp.id)
    {
      ++id_switches_;
      ++h.switches;
    }
    h.last_hypothesis = hyp.id;
    h.fragmentations += h.pending_gaps;
    h.pending_gaps = 0;
    h.tracked_now = true;
    h.ever_tracked = true;
    now[o.id] = hyp.id;
    if (o.has_velocity && hyp.has_velocity)
    {
      velocity_errors_.push_back(distance(o.velocity, hyp.velocity));
      h.velocity_errors.push_back(velocity_errors_.back());
    }
  }
  // An object absent from this frame is not tracked in it: a later pair after the gap resumes it.
  for (auto& [id, h] : history_)
    if (!present.count(id) && h.tracked_now)
    {
      ++h.pending_gaps;
      h.tracked_now = false;
    }
  for (char u : hyp_used) false_positives_ += u == 0;
  previous_ = std::move(now);
}

std::uint64_t ClearMot::fragmentations() const
{
  std::uint64_t n = 0;
  for (const auto& [id, h] : history_) n += h.fragmentations;
  return n;
}

double ClearMot::mota() const
{
  const double errors = static_cast<double>(misses_ + false_positives_ + id_switches_);
  if (objects_ == 0) return 1.0 - errors;
  return 1.0 - errors / static_cast<double>(objects_);
}

double ClearMot::motp() const { return matches_ ? distance_sum_ / static_cast<double>(matches_) : std::nan(""); }

double ClearMot::velocityRmse() const { return rms(velocity_errors_); }

double ClearMot::velocityMedian() const { return median(velocity_errors_); }

std::vector<MotObjectRecord> ClearMot::records() const
{
  const double all = sumOfSquares(velocity_errors_);
  std::vector<MotObjectRecord> out;
  for (const auto& [id, h] : history_)
  {
    MotObjectRecord r;
    r.id = id;
    r.frames = h.frames;
    r.tracked_frames = h.tracked;
    r.fragmentations = h.fragmentations;
    r.id_switches = h.switches;
    std::uint64_t best = 0;
    for (const auto& [hyp, n] : h.paired_with) best = std::max(best, n);
    r.identity_share = h.frames ? static_cast<double>(best) / static_cast<double>(h.frames) : 0.0;
    r.velocity_pairs = h.velocity_errors.size();
    r.velocity_rmse = rms(h.velocity_errors);
    r.velocity_median = median(h.velocity_errors);
    r.velocity_error_share = all > 0.0 ? sumOfSquares(h.velocity_errors) / all : 0.0;
    out.push_back(r);
  }
  return out;
}

std::map<std::string, double> ClearMot::summary() const
{
  return { { "frames", static_cast<double>(frames_) },
           { "objects", static_cast<double>(objects_) },
           { "matches", static_cast<double>(matches_) },
           { "misses", static_cast<double>(misses_) },
           { "false_positives", static_cast<double>(false_positives_) },
           { "id_switches", static_cast<double>(id_switches_) },
           { "fragmentations", static_cast<double>(fragmentations()) },
           { "mota", mota() },
           { "motp_m", motp() },
           { "velocity_pairs", static_cast<double>(velocityPairs()) },
           { "velocity_rmse_mps", velocityRmse() },
           { "velocity_median_mps", velocityMedian() } };
}

}  // namespace eval
}  // namespace map_aided_fusion

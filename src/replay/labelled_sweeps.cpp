#include "map_aided_fusion/replay/labelled_sweeps.hpp"

namespace map_aided_fusion {
namespace replay {

std::optional<LabelledSweep> LabelledSweeps::take(std::int64_t stamp_ns)
{
  const auto v = variants_.find(stamp_ns);
  const auto p = points_.find(stamp_ns);
  if (v == variants_.end() || p == points_.end()) return std::nullopt;
  LabelledSweep sweep{ std::move(v->second), std::move(p->second) };
  variants_.erase(v);
  points_.erase(p);
  return sweep;
}

std::size_t LabelledSweeps::waiting() const
{
  std::size_t n = variants_.size();
  for (const auto& [stamp, points] : points_) n += variants_.count(stamp) == 0;
  return n;
}

void scoreSweep(double stamp, VariantSweep& sweep, const std::vector<eval::LabelledPoint>& points,
                eval::PointLabelScorer& scorer)
{
  if (sweep.classes.size() == points.size()) eval::refineAmbiguous(sweep.evidence, points, sweep.classes);
  scorer.add(stamp, sweep.decision, points, true, &sweep.evidence);
  scorer.addSegmentation(points, sweep.classes);
}

}  // namespace replay
}  // namespace map_aided_fusion

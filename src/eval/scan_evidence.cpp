#include "map_aided_fusion/eval/scan_evidence.hpp"

#include <cmath>
#include <stdexcept>

#include "map_aided_fusion/core/map_grid.hpp"
#include "map_aided_fusion/core/scan_projection.hpp"
#include "map_aided_fusion/eval/point_labels.hpp"

namespace map_aided_fusion {
namespace eval {

EvidenceGrid scanEvidence(const core::ScanMassGrid& scan, const core::Pose2& pose, const core::MapGrid& grid,
                          const core::ObstaclePoints* obstacles)
{
  EvidenceGrid out;
  out.geometry = grid.geometry();
  const std::size_t n = out.geometry.numCells();
  const core::MapGridParams& p = grid.params();
  core::ScanProjection projection;
  const int clearance = static_cast<int>(std::lround(p.obstacle_clearance / p.resolution));
  projection.plan(scan, pose, out.geometry, p.point_occupancy ? obstacles : nullptr, clearance, grid.parallel());
  std::vector<float> f(n), o(n), omega(n);
  projection.fill(0, n, f.data(), o.data(), omega.data());

  const core::GridGeometry& sg = scan.geometry();
  const float* const scan_f = scan.plane(core::FrameSG::kF);
  const double c = std::cos(pose.yaw), s = std::sin(pose.yaw);
  out.cells.assign(n, ScanEvidence::kUnreached);
  for (std::size_t i = 0; i < n; ++i)
  {
    if (f[i] > 0.0f)
    {
      out.cells[i] = ScanEvidence::kFree;
      continue;
    }
    if (o[i] > 0.0f)
    {
      out.cells[i] = ScanEvidence::kOccupied;
      continue;
    }
    // The ScanGrid cell under the window cell's centre (vehicle frame), as the projection samples it.
    const core::Point2 w = out.geometry.cellCentre(out.geometry.cellOf(i));
    const double dx = w.x - pose.x, dy = w.y - pose.y;
    core::CellIndex sc;
    if (sg.worldToCell(core::Point2{ c * dx + s * dy, -s * dx + c * dy }, sc) && scan_f[sg.index(sc)] > 0.0f)
      out.cells[i] = ScanEvidence::kCleared;
  }
  return out;
}

void refineAmbiguous(EvidenceGrid& evidence, const std::vector<LabelledPoint>& points,
                     const std::vector<core::ReturnClass>& classes)
{
  if (points.size() != classes.size())
    throw std::invalid_argument("refineAmbiguous: " + std::to_string(classes.size()) + " classes for " +
                                std::to_string(points.size()) + " points");
  for (std::size_t k = 0; k < points.size(); ++k)
  {
    const core::ReturnClass r = classes[k];
    if (r != core::ReturnClass::kHeightGap && r != core::ReturnClass::kLowRelief && r != core::ReturnClass::kDisputed)
      continue;
    core::CellIndex cell;
    if (!evidence.geometry.worldToCell(points[k].p, cell)) continue;
    ScanEvidence& e = evidence.cells[evidence.geometry.index(cell)];
    if (e == ScanEvidence::kUnreached) e = ScanEvidence::kAmbiguous;
  }
}

}  // namespace eval
}  // namespace map_aided_fusion

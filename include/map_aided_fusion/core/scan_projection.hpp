/**
 * @file scan_projection.hpp
 * @brief The ScanGrid (vehicle frame) in the cells of the MapGrid's window (map frame): nearest-neighbour
 *        resampling, occupancy marks and the steps "point occupancy" and "obstacle clearance".
 */
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "map_aided_fusion/core/fusion.hpp"
#include "map_aided_fusion/core/grid_geometry.hpp"
#include "map_aided_fusion/core/mass_grid.hpp"
#include "map_aided_fusion/core/parallel.hpp"

namespace map_aided_fusion {
namespace core {

/**
 * @brief A ScanGrid mapped into a window: planned once per scan, then written run by run where it is read.
 *
 * plan() finds, per window row, the interval of cells that sample the scan grid, the occupancy marks (the window
 * cells that an occupied scan cell or an obstacle return overwrites, in the order they apply), the window cells that
 * end with occupied mass and, with a clearance, the cells near one. fill() then writes any run of cells exactly as
 * projectScan() writes them, so the fused step (fusionStep() with a ScanCells) takes each chunk's scan masses
 * from a buffer of its own thread instead of a window of them in memory.
 *
 * The scan and the obstacle returns given to plan() must outlive the fill() calls; fill() may run on several threads
 * at once.
 */
class ScanProjection : public ScanCells
{
public:
  /**
   * @brief Plans the projection of @p scan, seen from @p vehicle_in_map, into @p window (see projectScan()).
   * @param obstacles  the scan's obstacle returns in the vehicle frame (step point occupancy), or nullptr
   * @param clearance_cells  step obstacle clearance, cells (square neighbourhood); 0: none
   * @param parallel  the threads of the passes over the window (the plan is the same for any number)
   */
  void plan(const ScanMassGrid& scan, const Pose2& vehicle_in_map, const GridGeometry& window,
            const ObstaclePoints* obstacles, int clearance_cells, const Parallel& parallel);

  const GridGeometry& geometry() const override { return window_; }
  void fill(std::size_t begin, std::size_t end, float* f, float* o, float* omega) const override;
  /// fill(), and m(∅) into @p empty: the scan cell's under an occupancy mark of the forward pass, 0 elsewhere.
  void fill(std::size_t begin, std::size_t end, float* f, float* o, float* omega, float* empty) const;

  /// Per window cell, 1 where the projected scan has occupied mass (m(O) > 0), 0 elsewhere.
  const std::vector<std::uint8_t>& occupied() const { return occupied_; }

private:
  struct Mark
  {
    std::size_t from, to;  // scan cell; window cell
  };

  void fillRun(std::size_t begin, std::size_t end, float* f, float* o, float* omega) const;

  const ScanMassGrid* scan_ = nullptr;
  GridGeometry window_;
  bool points_ = false;
  bool clearance_ = false;
  double dfx_ = 0.0, dfy_ = 0.0;       // scan cells per window column
  std::vector<double> fxr_, fyr_;      // scan cell coordinates of each window row's first cell centre
  std::vector<int> lo_, hi_;           // each window row's cells that sample the scan grid, [lo, hi)
  std::vector<std::vector<Mark>> found_;  // the marks per chunk of scan cells or returns, in their order
  std::vector<std::vector<Mark>> marks_;  // the marks per chunk of kFusionChunkCells window cells, in order
  std::vector<std::uint8_t> occupied_, row_near_, near_;
};

/**
 * @brief Maps a ScanGrid given in the vehicle frame into the cells of @p window (map frame).
 *
 * Sampling: every window cell takes the scan cell under its centre (nearest neighbour, through the inverse
 * pose), so mass functions are copied, never blended; then every scan cell that carries occupied mass
 * overwrites the window cell under its own centre when it is more occupied. With the same resolution and
 * no rotation this is an exact one-to-one copy; under rotation no occupied scan cell is lost (a thin pole
 * never vanishes between cells). Window cells outside the scan are vacuous.
 */
void projectScan(const ScanMassGrid& scan, const Pose2& vehicle_in_map, const GridGeometry& window,
                 ScanMassGrid& out);

/**
 * @brief projectScan() with the steps "point occupancy" and "obstacle clearance" (ScanProjection, every cell).
 * @param obstacles  when not null: the scan's obstacle returns in the vehicle frame. Occupied scan cells then map to
 *                   Ω, and each return puts its scan cell's occupied mass in the window cell under it (exact).
 * @param clearance_cells  window cells within this many cells (square neighbourhood) of a cell with occupied mass
 *                   lose their free mass to Ω; 0: none.
 */
void projectScan(const ScanMassGrid& scan, const Pose2& vehicle_in_map, const GridGeometry& window, ScanMassGrid& out,
                 const ObstaclePoints* obstacles, int clearance_cells, const Parallel* parallel = nullptr);

}  // namespace core
}  // namespace map_aided_fusion

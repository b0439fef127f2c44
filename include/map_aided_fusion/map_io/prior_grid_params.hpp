/**
 * @file prior_grid_params.hpp
 * @brief Parameters of the PriorGridNodelet and prior_grid_tool (config/prior_grid.yaml), ROS-free, and the
 *        choice of the published window.
 */
#pragma once

#include <cstddef>
#include <string>

#include "map_aided_fusion/core/grid_geometry.hpp"
#include "map_aided_fusion/core/prior.hpp"
#include "map_aided_fusion/map_io/map_loader.hpp"

namespace map_aided_fusion {
namespace map_io {

/// Everything the PriorGrid component reads from its parameters. Units in the field comments.
struct PriorGridParams
{
  MapLoadParams map;                ///< the map file and how to read it (see map_loader.hpp)
  std::string frame_id = "map";     ///< frame of the published grids and markers
  double resolution = 0.5;          ///< cell side, metres (> 0)
  core::PriorConfidence beta;       ///< β_B, β_R, β_T of equation 1, each in [0, 1] (defaults 0.9, 0.9, 0.8)
  double margin = 0.0;              ///< metres added around the map's extent (>= 0)
  /// Side in metres of the square published around (publish_centre_x, publish_centre_y); 0: the map's extent.
  double publish_size = 0.0;
  double publish_centre_x = 0.0;    ///< map frame, metres (default: the origin)
  double publish_centre_y = 0.0;    ///< map frame, metres
  /// Upper bound on the published cells (an EvidentialGrid carries 16 bytes per cell): the default 4e6 cells is
  /// 1 km × 1 km at 0.5 m (64 MB). A larger window is cropped to the largest square around the publish centre
  /// that fits, with a warning.
  double max_published_cells = 4.0e6;
  bool publish_outlines = true;     ///< publish prior_grid/outlines (MarkerArray)

  /// @throws core::ParameterError naming the offending parameter (also validates map and beta).
  void validate() const;
};

/**
 * @brief The window to publish: the map's @p extent, or the publish_size square around the publish centre,
 *        intersected with the extent and then capped at max_published_cells (a square around the publish
 *        centre, clipped to the extent). Aligned on @p extent's cells.
 * @param cropped set when the cap reduced the window
 * @throws core::ParameterError when the window does not overlap the map's extent.
 */
core::GridGeometry publishedWindow(const core::GridGeometry& extent, const PriorGridParams& params, bool& cropped);

}  // namespace map_io
}  // namespace map_aided_fusion

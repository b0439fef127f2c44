#include "map_aided_fusion/map_io/prior_grid_params.hpp"

#include <algorithm>
#include <cmath>

#include "map_aided_fusion/core/parameters.hpp"

namespace map_aided_fusion {
namespace map_io {

namespace {
constexpr double kMaxVehicleDistance = 1e7;  // m
}  // namespace

void PriorGridParams::validate() const
{
  map.validate();
  beta.validate();
  options.validate();
  if (frame_id.empty()) throw core::ParameterError("frame_id", "must not be empty");
  core::requirePositive("resolution", resolution);
  if (!std::isfinite(margin) || margin < 0.0) throw core::ParameterError("margin", "must be finite and >= 0");
  if (!std::isfinite(publish_size) || publish_size < 0.0)
    throw core::ParameterError("publish_size", "must be finite and >= 0 (0: the map's extent)");
  if (!std::isfinite(publish_centre_x)) throw core::ParameterError("publish_centre_x", "must be finite");
  if (!std::isfinite(publish_centre_y)) throw core::ParameterError("publish_centre_y", "must be finite");
  core::requireInRange("max_published_cells", max_published_cells, 1.0, 1e9);
  core::requireInRange("max_vehicle_distance", max_vehicle_distance, 0.0, kMaxVehicleDistance);
}

namespace {

/// Cells [c0, c1) of @p extent along one axis covering [lo, hi).
void cellRange(double lo, double hi, double origin, double res, int n, int& c0, int& c1)
{
  const double n_cells = static_cast<double>(n);
  c0 = static_cast<int>(std::clamp(std::floor((lo - origin) / res), 0.0, n_cells));
  c1 = static_cast<int>(std::clamp(std::ceil((hi - origin) / res), 0.0, n_cells));
}

}  // namespace

core::GridGeometry publishedWindow(const core::GridGeometry& extent, const PriorGridParams& p, bool& cropped)
{
  cropped = false;
  const double res = extent.resolution;
  int x0 = 0, x1 = extent.width, y0 = 0, y1 = extent.height;
  if (p.publish_size > 0.0)
  {
    const double h = 0.5 * p.publish_size;
    cellRange(p.publish_centre_x - h, p.publish_centre_x + h, extent.origin_x, res, extent.width, x0, x1);
    cellRange(p.publish_centre_y - h, p.publish_centre_y + h, extent.origin_y, res, extent.height, y0, y1);
  }
  if (x1 <= x0 || y1 <= y0)
    throw core::ParameterError("publish_size", "the published window does not overlap the map's extent");
  const double cells = static_cast<double>(x1 - x0) * static_cast<double>(y1 - y0);
  if (cells > p.max_published_cells)
  {
    cropped = true;
    const int side = std::max(1, static_cast<int>(std::floor(std::sqrt(p.max_published_cells))));
    // A square of `side` cells around the publish centre, shifted to stay inside [x0, x1) × [y0, y1).
    const auto fit = [side](double centre_cell, int lo, int hi, int& a, int& b) {
      const int len = std::min(side, hi - lo);
      a = std::clamp(static_cast<int>(std::lround(centre_cell - 0.5 * len)), lo, hi - len);
      b = a + len;
    };
    fit((p.publish_centre_x - extent.origin_x) / res, x0, x1, x0, x1);
    fit((p.publish_centre_y - extent.origin_y) / res, y0, y1, y0, y1);
  }
  core::GridGeometry w;
  w.resolution = res;
  w.width = x1 - x0;
  w.height = y1 - y0;
  w.origin_x = extent.origin_x + x0 * res;
  w.origin_y = extent.origin_y + y0 * res;
  return w;
}

}  // namespace map_io
}  // namespace map_aided_fusion

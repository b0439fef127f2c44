#include "map_aided_fusion/map_io/projection.hpp"

#include <GeographicLib/LocalCartesian.hpp>

namespace map_aided_fusion {
namespace map_io {

struct LocalProjector::Impl
{
  GeographicLib::LocalCartesian lc;
};

LocalProjector::LocalProjector(double latitude, double longitude, double altitude)
  : impl_(std::make_unique<Impl>(Impl{ GeographicLib::LocalCartesian(latitude, longitude, altitude) }))
  , latitude_(latitude)
  , longitude_(longitude)
  , altitude_(altitude)
{
}

LocalProjector::~LocalProjector() = default;
LocalProjector::LocalProjector(LocalProjector&&) noexcept = default;
LocalProjector& LocalProjector::operator=(LocalProjector&&) noexcept = default;

core::Point2 LocalProjector::forward(double latitude, double longitude, double* up) const
{
  double x = 0.0, y = 0.0, z = 0.0;
  impl_->lc.Forward(latitude, longitude, altitude_, x, y, z);
  if (up) *up = z;
  return core::Point2{ x, y };
}

void LocalProjector::reverse(core::Point2 p, double& latitude, double& longitude) const
{
  double h = 0.0;
  impl_->lc.Reverse(p.x, p.y, 0.0, latitude, longitude, h);
}

}  // namespace map_io
}  // namespace map_aided_fusion

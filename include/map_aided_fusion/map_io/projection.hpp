/**
 * @file projection.hpp
 * @brief WGS84 ↔ local metric `map` frame (ENU, REP-103/105) with GeographicLib::LocalCartesian.
 */
#pragma once

#include <memory>

#include "map_aided_fusion/core/grid_geometry.hpp"

namespace map_aided_fusion {
namespace map_io {

/// Projects geographic coordinates onto the local East-North plane at an origin (LocalCartesian).
class LocalProjector
{
public:
  /// @param latitude, longitude origin in degrees (WGS84); @param altitude origin height above the ellipsoid, m
  LocalProjector(double latitude, double longitude, double altitude = 0.0);
  ~LocalProjector();
  LocalProjector(LocalProjector&&) noexcept;
  LocalProjector& operator=(LocalProjector&&) noexcept;

  /// (east, north) in metres of a point at the origin's altitude; @p up, when given, receives its up
  /// coordinate (negative away from the origin: the Earth's curvature; about −12.7e6 m at the antipode).
  core::Point2 forward(double latitude, double longitude, double* up = nullptr) const;
  /// (latitude, longitude) in degrees of a map-frame point at the origin's altitude.
  void reverse(core::Point2 p, double& latitude, double& longitude) const;

  double latitude() const { return latitude_; }
  double longitude() const { return longitude_; }
  double altitude() const { return altitude_; }

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  double latitude_;
  double longitude_;
  double altitude_;
};

}  // namespace map_io
}  // namespace map_aided_fusion

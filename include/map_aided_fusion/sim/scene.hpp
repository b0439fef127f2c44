/**
 * @file scene.hpp
 * @brief The 3D world of a simulation at one instant: static buildings (extruded footprints), the ground
 *        plane z = 0 and the objects of the current instant (oriented boxes and cylinders), with a 2D
 *        uniform grid that accelerates the casting of beam fans.
 */
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "map_aided_fusion/core/cell_class.hpp"
#include "map_aided_fusion/sim/geometry.hpp"

namespace map_aided_fusion {
namespace sim {

/// What a surface is made of; sets the return's intensity.
enum class Material : std::uint8_t
{
  kGround,
  kBuilding,
  kVehicle,
  kPedestrian,
  kVegetation,
  kStreetFurniture,
};

/// Intensity (0..255 scale, like most lidar drivers) of a return from a material.
float materialIntensity(Material material);

/// A real building of the simulated world, with its ground-truth class (C when the map knows it, N when
/// it is missing from the map).
struct WorldBuilding
{
  core::Polygon footprint;
  double height = 10.0;  ///< m
  core::CellClass cell_class = core::CellClass::kBuilding;
  std::string id;  ///< map identifier, or a scenario name for unmapped buildings
};

/// One object of the current instant.
struct WorldObject
{
  enum class Shape : std::uint8_t
  {
    kBox,
    kCylinder
  };
  Shape shape = Shape::kBox;
  OrientedBox box;    ///< used when shape == kBox
  Cylinder cylinder;  ///< used when shape == kCylinder
  core::CellClass cell_class = core::CellClass::kInfrastructure;
  Material material = Material::kStreetFurniture;
  std::uint32_t id = 0;
};

/// What one beam hit: horizontal distance s (range = s / cos(elevation)) and the solid.
struct BeamHit
{
  static constexpr int kNone = -1;    ///< no return within the beam's range
  static constexpr int kGround = -2;  ///< the ground plane
  double s = kNoHit;
  int solid = kNone;  ///< kNone, kGround, a building index, or kObjectBase + object index
};

/// Parameters of the scene's acceleration grid.
struct SceneParams
{
  double cell_size = 4.0;  ///< m, side of the acceleration grid's cells (> 0)
  double margin = 10.0;    ///< m added around the buildings' bounding box (≥ 0)
  /// @throws core::ParameterError naming the parameter
  void validate() const;
};

/**
 * @brief Static buildings + ground + per-instant objects, and exact fan casting.
 *
 * Not thread-safe: casting uses per-scene scratch space (one Scene per thread).
 */
class Scene
{
public:
  /// Solid indices ≥ kObjectBase are objects (index - kObjectBase).
  static constexpr int kObjectBase = 1 << 24;

  explicit Scene(std::vector<WorldBuilding> buildings, const SceneParams& params = SceneParams());

  /// Replaces the objects of the current instant (binned into the grid).
  void setObjects(std::vector<WorldObject> objects);

  /**
   * @brief Casts @p n beams that share one origin and one azimuth.
   * @param slopes    tan(elevation) of each beam
   * @param max_s     horizontal reach of each beam (max range · cos(elevation)); hits beyond are dropped
   * @param hits      output, one per beam: the nearest hit (solid or ground) within reach, else kNone
   *
   * The origin must not stand inside a solid's footprint (hits behind a footprint that contains the origin
   * may then be missed).
   */
  void castFan(double ox, double oy, double oz, double azimuth, const double* slopes, const double* max_s, int n,
               BeamHit* hits) const;

  /// Casts one ray; returns its hit with s the horizontal distance (range = s / cos(elevation)).
  BeamHit castRay(double ox, double oy, double oz, double azimuth, double elevation, double max_range) const;

  const std::vector<WorldBuilding>& buildings() const { return buildings_; }
  const std::vector<WorldObject>& objects() const { return objects_; }

  /// Material of a hit solid (kGround for the ground).
  Material materialOf(int solid) const;
  /// Ground-truth class of a hit solid (F for the ground, unknown for kNone).
  core::CellClass classOf(int solid) const;

private:
  struct Bin
  {
    std::vector<std::uint32_t> offsets;  // CSR, size cells + 1
    std::vector<std::uint32_t> items;
  };
  void buildStaticBins();
  bool cellRange(double min_x, double min_y, double max_x, double max_y, int& x0, int& y0, int& x1,
                 int& y1) const;
  void considerSolid(int solid, const Ray2& ray, double oz, const double* slopes, const double* max_s, int n,
                     BeamHit* hits) const;

  SceneParams params_;
  std::vector<WorldBuilding> buildings_;
  std::vector<WorldObject> objects_;
  double min_x_ = 0.0, min_y_ = 0.0;
  int nx_ = 1, ny_ = 1;
  Bin static_bins_;
  Bin object_bins_;
  std::vector<std::uint32_t> unbinned_objects_;
  mutable std::vector<std::uint32_t> building_stamp_;
  mutable std::vector<std::uint32_t> object_stamp_;
  mutable std::uint32_t stamp_ = 0;
  mutable std::vector<Span> spans_;
};

}  // namespace sim
}  // namespace map_aided_fusion

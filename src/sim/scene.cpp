#include "map_aided_fusion/sim/scene.hpp"

#include <algorithm>
#include <cmath>

#include "map_aided_fusion/core/parameters.hpp"

namespace map_aided_fusion {
namespace sim {

namespace {

constexpr double kBinEpsilon = 1e-9;
constexpr double kDefaultHalfExtent = 50.0;  // m, grid half-size of a scene without buildings
constexpr double kMinCosElevation = 1e-6;

constexpr float kIntensityGround = 15.0f;
constexpr float kIntensityBuilding = 45.0f;
constexpr float kIntensityVehicle = 90.0f;
constexpr float kIntensityPedestrian = 35.0f;
constexpr float kIntensityVegetation = 25.0f;
constexpr float kIntensityFurniture = 120.0f;

template <class F>
void forEachVertex(const core::Polygon& p, F&& f)
{
  for (const auto& v : p.outer) f(v);
  for (const auto& h : p.holes)
    for (const auto& v : h) f(v);
}

void objectBounds(const WorldObject& o, double& x0, double& y0, double& x1, double& y1)
{
  if (o.shape == WorldObject::Shape::kCylinder)
  {
    x0 = o.cylinder.cx - o.cylinder.radius;
    x1 = o.cylinder.cx + o.cylinder.radius;
    y0 = o.cylinder.cy - o.cylinder.radius;
    y1 = o.cylinder.cy + o.cylinder.radius;
    return;
  }
  const double c = std::abs(std::cos(o.box.yaw)), s = std::abs(std::sin(o.box.yaw));
  const double hx = 0.5 * (c * o.box.length + s * o.box.width);
  const double hy = 0.5 * (s * o.box.length + c * o.box.width);
  x0 = o.box.cx - hx;
  x1 = o.box.cx + hx;
  y0 = o.box.cy - hy;
  y1 = o.box.cy + hy;
}

}  // namespace

float materialIntensity(Material material)
{
  switch (material)
  {
    case Material::kGround: return kIntensityGround;
    case Material::kBuilding: return kIntensityBuilding;
    case Material::kVehicle: return kIntensityVehicle;
    case Material::kPedestrian: return kIntensityPedestrian;
    case Material::kVegetation: return kIntensityVegetation;
    case Material::kStreetFurniture: return kIntensityFurniture;
  }
  return kIntensityGround;
}

void SceneParams::validate() const
{
  core::requirePositive("scene.cell_size", cell_size);
  core::requireInRange("scene.margin", margin, 0.0, 1e4);
}

Scene::Scene(std::vector<WorldBuilding> buildings, const SceneParams& params)
  : params_(params), buildings_(std::move(buildings))
{
  params_.validate();
  double x0 = kNoHit, y0 = kNoHit, x1 = -kNoHit, y1 = -kNoHit;
  for (const auto& b : buildings_)
    forEachVertex(b.footprint, [&](const core::Point2& v) {
      x0 = std::min(x0, v.x);
      y0 = std::min(y0, v.y);
      x1 = std::max(x1, v.x);
      y1 = std::max(y1, v.y);
    });
  if (!(x0 <= x1 && y0 <= y1))
  {
    x0 = y0 = -kDefaultHalfExtent;
    x1 = y1 = kDefaultHalfExtent;
  }
  x0 -= params_.margin;
  y0 -= params_.margin;
  x1 += params_.margin;
  y1 += params_.margin;
  min_x_ = x0;
  min_y_ = y0;
  nx_ = std::max(1, static_cast<int>(std::ceil((x1 - x0) / params_.cell_size)));
  ny_ = std::max(1, static_cast<int>(std::ceil((y1 - y0) / params_.cell_size)));
  building_stamp_.assign(buildings_.size(), 0);
  buildStaticBins();
  object_bins_.offsets.assign(static_cast<std::size_t>(nx_) * ny_ + 1, 0);
}

bool Scene::cellRange(double ax, double ay, double bx, double by, int& x0, int& y0, int& x1, int& y1) const
{
  const double cs = params_.cell_size;
  x0 = static_cast<int>(std::floor((ax - kBinEpsilon - min_x_) / cs));
  y0 = static_cast<int>(std::floor((ay - kBinEpsilon - min_y_) / cs));
  x1 = static_cast<int>(std::floor((bx + kBinEpsilon - min_x_) / cs));
  y1 = static_cast<int>(std::floor((by + kBinEpsilon - min_y_) / cs));
  if (x1 < 0 || y1 < 0 || x0 >= nx_ || y0 >= ny_) return false;
  x0 = std::max(x0, 0);
  y0 = std::max(y0, 0);
  x1 = std::min(x1, nx_ - 1);
  y1 = std::min(y1, ny_ - 1);
  return true;
}

void Scene::buildStaticBins()
{
  const std::size_t cells = static_cast<std::size_t>(nx_) * ny_;
  std::vector<std::vector<std::uint32_t>> lists(cells);
  for (std::size_t b = 0; b < buildings_.size(); ++b)
  {
    auto addRing = [&](const core::Ring& ring) {
      for (std::size_t i = 0; i < ring.size(); ++i)
      {
        const auto& p = ring[i];
        const auto& q = ring[(i + 1) % ring.size()];
        int x0, y0, x1, y1;
        if (!cellRange(std::min(p.x, q.x), std::min(p.y, q.y), std::max(p.x, q.x), std::max(p.y, q.y), x0, y0, x1,
                       y1))
          continue;
        for (int y = y0; y <= y1; ++y)
          for (int x = x0; x <= x1; ++x)
          {
            auto& l = lists[static_cast<std::size_t>(y) * nx_ + x];
            if (l.empty() || l.back() != b) l.push_back(static_cast<std::uint32_t>(b));
          }
      }
    };
    addRing(buildings_[b].footprint.outer);
    for (const auto& h : buildings_[b].footprint.holes) addRing(h);
  }
  static_bins_.offsets.assign(cells + 1, 0);
  for (std::size_t c = 0; c < cells; ++c)
    static_bins_.offsets[c + 1] = static_bins_.offsets[c] + static_cast<std::uint32_t>(lists[c].size());
  static_bins_.items.resize(static_bins_.offsets[cells]);
  for (std::size_t c = 0; c < cells; ++c)
    std::copy(lists[c].begin(), lists[c].end(), static_bins_.items.begin() + static_bins_.offsets[c]);
}

void Scene::setObjects(std::vector<WorldObject> objects)
{
  objects_ = std::move(objects);
  object_stamp_.assign(objects_.size(), 0);
  unbinned_objects_.clear();
  const std::size_t cells = static_cast<std::size_t>(nx_) * ny_;
  auto& off = object_bins_.offsets;
  std::fill(off.begin(), off.end(), 0);
  std::vector<int> ranges(objects_.size() * 4, -1);
  const double gx1 = min_x_ + nx_ * params_.cell_size, gy1 = min_y_ + ny_ * params_.cell_size;
  for (std::size_t i = 0; i < objects_.size(); ++i)
  {
    double ax, ay, bx, by;
    objectBounds(objects_[i], ax, ay, bx, by);
    int* r = &ranges[4 * i];
    if (ax < min_x_ || ay < min_y_ || bx > gx1 || by > gy1 || !cellRange(ax, ay, bx, by, r[0], r[1], r[2], r[3]))
    {
      r[0] = -1;
      unbinned_objects_.push_back(static_cast<std::uint32_t>(i));
      continue;
    }
    for (int y = r[1]; y <= r[3]; ++y)
      for (int x = r[0]; x <= r[2]; ++x) ++off[static_cast<std::size_t>(y) * nx_ + x + 1];
  }
  for (std::size_t c = 0; c < cells; ++c) off[c + 1] += off[c];
  object_bins_.items.resize(off[cells]);
  std::vector<std::uint32_t> fill(off.begin(), off.end() - 1);
  for (std::size_t i = 0; i < objects_.size(); ++i)
  {
    const int* r = &ranges[4 * i];
    if (r[0] < 0) continue;
    for (int y = r[1]; y <= r[3]; ++y)
      for (int x = r[0]; x <= r[2]; ++x)
        object_bins_.items[fill[static_cast<std::size_t>(y) * nx_ + x]++] = static_cast<std::uint32_t>(i);
  }
}

void Scene::considerSolid(int solid, const Ray2& ray, double oz, const double* slopes, const double* max_s, int n,
                          BeamHit* hits) const
{
  spans_.clear();
  if (solid >= kObjectBase)
  {
    const WorldObject& o = objects_[static_cast<std::size_t>(solid - kObjectBase)];
    Span span;
    const bool crossed =
        o.shape == WorldObject::Shape::kBox ? spanOf(o.box, ray, span) : spanOf(o.cylinder, ray, span);
    if (crossed) spans_.push_back(span);
  }
  else
  {
    const WorldBuilding& b = buildings_[static_cast<std::size_t>(solid)];
    appendSpans(b.footprint, 0.0, b.height, ray, spans_);
  }
  for (const Span& span : spans_)
  {
    if (span.s_out < 0.0) continue;
    for (int k = 0; k < n; ++k)
    {
      const double s = hitDistance(span, oz, slopes[k]);
      if (s < hits[k].s && s <= max_s[k]) hits[k] = BeamHit{ s, solid };
    }
  }
}

void Scene::castFan(double ox, double oy, double oz, double azimuth, const double* slopes, const double* max_s,
                    int n, BeamHit* hits) const
{
  double limit = 0.0;
  for (int k = 0; k < n; ++k)
  {
    const double g = groundHitDistance(oz, slopes[k]);
    hits[k] = g <= max_s[k] ? BeamHit{ g, BeamHit::kGround } : BeamHit{};
    limit = std::max(limit, max_s[k]);
  }
  Ray2 ray{ core::Point2{ ox, oy }, std::cos(azimuth), std::sin(azimuth) };
  if (++stamp_ == 0)
  {
    std::fill(building_stamp_.begin(), building_stamp_.end(), 0);
    std::fill(object_stamp_.begin(), object_stamp_.end(), 0);
    stamp_ = 1;
  }
  for (std::uint32_t i : unbinned_objects_)
    considerSolid(static_cast<int>(i) + kObjectBase, ray, oz, slopes, max_s, n, hits);

  // Clip the 2D ray to the grid, then walk its cells in order (Amanatides & Woo).
  const double cs = params_.cell_size;
  const double gx1 = min_x_ + nx_ * cs, gy1 = min_y_ + ny_ * cs;
  double t0 = 0.0, t1 = limit;
  auto clip = [&](double o, double d, double lo, double hi) {
    if (std::abs(d) < 1e-15) return o >= lo && o <= hi;
    double a = (lo - o) / d, b = (hi - o) / d;
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
    return t0 <= t1;
  };
  if (!clip(ox, ray.dx, min_x_, gx1) || !clip(oy, ray.dy, min_y_, gy1)) return;
  const double px = ox + t0 * ray.dx, py = oy + t0 * ray.dy;
  int ix = std::clamp(static_cast<int>(std::floor((px - min_x_) / cs)), 0, nx_ - 1);
  int iy = std::clamp(static_cast<int>(std::floor((py - min_y_) / cs)), 0, ny_ - 1);
  const int step_x = ray.dx > 0.0 ? 1 : -1, step_y = ray.dy > 0.0 ? 1 : -1;
  double t_max_x = ray.dx != 0.0 ? (min_x_ + (ix + (ray.dx > 0.0 ? 1 : 0)) * cs - ox) / ray.dx : kNoHit;
  double t_max_y = ray.dy != 0.0 ? (min_y_ + (iy + (ray.dy > 0.0 ? 1 : 0)) * cs - oy) / ray.dy : kNoHit;
  const double dt_x = ray.dx != 0.0 ? cs / std::abs(ray.dx) : kNoHit;
  const double dt_y = ray.dy != 0.0 ? cs / std::abs(ray.dy) : kNoHit;
  while (true)
  {
    const std::size_t cell = static_cast<std::size_t>(iy) * nx_ + ix;
    for (std::uint32_t j = static_bins_.offsets[cell]; j < static_bins_.offsets[cell + 1]; ++j)
    {
      const std::uint32_t b = static_bins_.items[j];
      if (building_stamp_[b] == stamp_) continue;
      building_stamp_[b] = stamp_;
      considerSolid(static_cast<int>(b), ray, oz, slopes, max_s, n, hits);
    }
    for (std::uint32_t j = object_bins_.offsets[cell]; j < object_bins_.offsets[cell + 1]; ++j)
    {
      const std::uint32_t o = object_bins_.items[j];
      if (object_stamp_[o] == stamp_) continue;
      object_stamp_[o] = stamp_;
      considerSolid(static_cast<int>(o) + kObjectBase, ray, oz, slopes, max_s, n, hits);
    }
    const double t_exit = std::min(t_max_x, t_max_y);
    if (t_exit >= t1) break;
    bool resolved = true;
    for (int k = 0; k < n && resolved; ++k) resolved = std::min(hits[k].s, max_s[k]) <= t_exit;
    if (resolved) break;
    if (t_max_x < t_max_y)
    {
      ix += step_x;
      t_max_x += dt_x;
      if (ix < 0 || ix >= nx_) break;
    }
    else
    {
      iy += step_y;
      t_max_y += dt_y;
      if (iy < 0 || iy >= ny_) break;
    }
  }
}

BeamHit Scene::castRay(double ox, double oy, double oz, double azimuth, double elevation, double max_range) const
{
  const double slope = std::tan(elevation);
  const double max_s = max_range * std::max(std::cos(elevation), kMinCosElevation);
  BeamHit hit;
  castFan(ox, oy, oz, azimuth, &slope, &max_s, 1, &hit);
  return hit;
}

Material Scene::materialOf(int solid) const
{
  if (solid == BeamHit::kGround || solid == BeamHit::kNone) return Material::kGround;
  if (solid >= kObjectBase) return objects_[static_cast<std::size_t>(solid - kObjectBase)].material;
  return Material::kBuilding;
}

core::CellClass Scene::classOf(int solid) const
{
  if (solid == BeamHit::kNone) return core::CellClass::kUnknown;
  if (solid == BeamHit::kGround) return core::CellClass::kFree;
  if (solid >= kObjectBase) return objects_[static_cast<std::size_t>(solid - kObjectBase)].cell_class;
  return buildings_[static_cast<std::size_t>(solid)].cell_class;
}

}  // namespace sim
}  // namespace map_aided_fusion

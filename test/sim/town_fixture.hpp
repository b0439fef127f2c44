// The buildings of maps/town.osm (see maps/generate_town.py) as a core::VectorMap, for tests and
// benchmarks that must not depend on the map loader: heights from `height`, else 3 m per level, else 0.
#pragma once

#include <vector>

#include "map_aided_fusion/core/vector_map.hpp"

namespace maf_test {

inline map_aided_fusion::core::VectorMap townLikeMap()
{
  using map_aided_fusion::core::Building;
  using map_aided_fusion::core::Point2;
  struct R
  {
    double x0, y0, x1, y1, h;
  };
  const std::vector<R> rects{
    { -72, 10, -45, 35, 12 },  { -40, 10, -8, 30, 9 },    { -72, 45, -40, 72, 12 },  { -32, 42, -8, 72, 0 },
    { -72, -72, -50, -45, 9 }, { -45, -70, -8, -40, 6 },  { -72, -35, -30, -10, 15 }, { 8, -72, 35, -10, 20 },
    { 42, -40, 72, -10, 9 },   { -140, 90, -95, 130, 6 }, { -70, 90, -20, 120, 6 },  { 20, 90, 60, 140, 0 },
    { 95, 90, 140, 130, 3 },   { -140, -130, -95, -90, 0 }, { -60, -125, -10, -90, 7.5 }, { 10, -120, 70, -90, 12 },
    { 90, 10, 140, 60, 9 },    { 90, -60, 140, -15, 0 },  { -140, 15, -95, 60, 10 },  { -140, -60, -95, -20, 0 },
  };
  map_aided_fusion::core::VectorMap map;
  int id = 0;
  for (const R& r : rects)
  {
    Building b;
    b.footprint.outer = { { r.x0, r.y0 }, { r.x1, r.y0 }, { r.x1, r.y1 }, { r.x0, r.y1 } };
    b.height = r.h;
    b.id = "way/" + std::to_string(++id);
    map.buildings.push_back(b);
  }
  Building l;  // the L-shaped one
  l.footprint.outer = { { 42, -72 }, { 72, -72 }, { 72, -60 }, { 55, -60 }, { 55, -48 }, { 42, -48 } };
  l.id = "way/" + std::to_string(++id);
  map.buildings.push_back(l);
  Building cloister;  // courtyard
  cloister.footprint.outer = { { 10, 12 }, { 70, 12 }, { 70, 70 }, { 10, 70 } };
  cloister.footprint.holes = { { { 25, 27 }, { 55, 27 }, { 55, 55 }, { 25, 55 } } };
  cloister.height = 15;
  cloister.id = "relation/" + std::to_string(++id);
  map.buildings.push_back(cloister);
  return map;
}

}  // namespace maf_test

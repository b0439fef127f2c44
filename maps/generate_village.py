#!/usr/bin/env python3
"""Writes maps/village.osm: a small fictional village whose layout differs from the town's grid: a diagonal
high street, a curved lane, a north-south road crossing them, a dead end and a square, with terraced houses set
close to the roads (2.5 m pavements) and detached houses along the lane. Laid out in local ENU metres around
ORIGIN, converted to WGS84 (osm_layout.py); the houses are placed by a fixed pseudo-random draw and kept only
where they clear every road surface and every other house.
Run it only to change the village; the .osm file is what the package uses."""
import math
import os
import random
import sys

from osm_layout import OsmLayout

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "learning"))
from maf_learning import geometry as geo  # noqa: E402

ORIGIN = (45.7640, 4.8357, 170.0)  # lat, lon (degrees), altitude (m)
E = 150.0
village = OsmLayout(ORIGIN, "maps/generate_village.py")


def arc(cx, cy, r, a0, a1, n):
    return [(cx + r * math.cos(math.radians(a0 + (a1 - a0) * i / n)),
             cy + r * math.sin(math.radians(a0 + (a1 - a0) * i / n))) for i in range(n + 1)]


# Roads (centre line, tags, surface width as the loader computes it).
high_street = [(-E, -100.0), (E, 100.0)]
lane = arc(-20.0, -170.0, 190.0, 140.0, 62.0, 16)          # Mill Lane, a wide curve north of the high street
vines = [(40.0, -E), (40.0, E)]                           # Vine Road, north-south
dead_end = [(40.0, -70.0), (110.0, -70.0)]                # Chapel Close, a dead end east of Vine Road
roads = [
    (high_street, {"highway": "primary", "name": "High Street", "lanes": "2", "width": "9"}, 9.0),
    (lane, {"highway": "residential", "name": "Mill Lane"}, 6.0),
    (vines, {"highway": "tertiary", "name": "Vine Road", "lanes": "2"}, 7.0),
    (dead_end, {"highway": "service", "name": "Chapel Close"}, 4.0),
]
for line, tags, _ in roads:
    village.way(line, tags)
# The square where Vine Road crosses the high street, drawn as a road surface.
cy = -100.0 + (40.0 + E) * 200.0 / (2 * E)
square = [(28.0, cy - 12.0), (52.0, cy - 12.0), (52.0, cy + 12.0), (28.0, cy + 12.0)]
village.way(square, {"area:highway": "primary", "name": "Church Square"}, closed=True)

PAVEMENT = 2.5
rng = random.Random(7)
houses = []


def clear_of_roads(poly):
    for p in geo.ring_samples(poly, 0.5):
        if geo.dist_point_polygon(p, square) < PAVEMENT:
            return False
        for line, _, width in roads:
            if geo.dist_point_polyline(p, line) < width / 2 + PAVEMENT - 1e-6:
                return False
    return all(abs(x) <= E - 2 and abs(y) <= E - 2 for x, y in poly)


def place_along(line, width, side, depth_range, length_range, gap_range, tags_of):
    total = geo.length(line)
    s = rng.uniform(2.0, 8.0)
    while s < total:
        length_m = rng.uniform(*length_range)
        depth = rng.uniform(*depth_range)
        x, y, heading = geo.point_at(line, s + length_m / 2)
        d = side * (width / 2 + PAVEMENT + depth / 2 + rng.uniform(0.0, 0.5))
        cx, cy_ = x - d * math.sin(heading), y + d * math.cos(heading)
        poly = geo.rectangle(cx, cy_, heading, length_m, depth)
        if clear_of_roads(poly) and all(geo.polygons_clear(poly, h, 1.0) for h, _ in houses):
            houses.append((poly, tags_of()))
        s += length_m + rng.uniform(*gap_range)


def levels():
    return {"building:levels": str(rng.choice([1, 2, 2, 3]))}


# Terraced houses along the high street (both sides), detached houses along the lane and Vine Road.
for side in (1, -1):
    place_along(high_street, 9.0, side, (8.0, 12.0), (9.0, 16.0), (0.5, 3.0), levels)
    place_along(lane, 6.0, side, (8.0, 11.0), (8.0, 12.0), (6.0, 14.0), levels)
    place_along(vines, 7.0, side, (9.0, 14.0), (10.0, 18.0), (4.0, 10.0), lambda: {"height": f"{rng.uniform(5, 9):.1f}"})
    place_along(dead_end, 4.0, side, (10.0, 14.0), (12.0, 20.0), (5.0, 9.0), levels)

# The church: an L-shaped hall north-east of the square, and a barn south of the high street.
church = [(58.0, cy + 14.0), (80.0, cy + 14.0), (80.0, cy + 36.0), (70.0, cy + 36.0), (70.0, cy + 24.0),
          (58.0, cy + 24.0)]
barn = geo.rectangle(-60.0, -110.0, math.radians(10.0), 30.0, 16.0)
for poly, tags in ((church, {"height": "14", "name": "Church"}), (barn, {"height": "7", "name": "Barn"})):
    if clear_of_roads(poly):
        houses = [(h, t) for h, t in houses if geo.polygons_clear(poly, h, 1.0)]
        houses.append((poly, tags))

for poly, tags in houses:
    village.way([(round(x, 3), round(y, 3)) for x, y in poly], dict(building="yes", **tags), closed=True)
village.write(sys.stdout, E)

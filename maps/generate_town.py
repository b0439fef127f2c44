#!/usr/bin/env python3
"""Writes maps/town.osm: a small fictional town laid out in local ENU metres around ORIGIN and
converted to WGS84 (ellipsoidal local tangent plane, first order: error < 1 mm over 200 m).
Run it only to change the town; the .osm file is what the package uses."""
import math
import sys

ORIGIN = (49.4150, 2.8230, 40.0)  # lat, lon (degrees), altitude (m)
A, F = 6378137.0, 1 / 298.257223563
E2 = F * (2 - F)


def to_latlon(x, y):
    lat0 = math.radians(ORIGIN[0])
    s = math.sin(lat0)
    n = A / math.sqrt(1 - E2 * s * s)            # prime vertical radius
    m = A * (1 - E2) / (1 - E2 * s * s) ** 1.5   # meridian radius
    return ORIGIN[0] + math.degrees(y / m), ORIGIN[1] + math.degrees(x / (n * math.cos(lat0)))


nodes, ways, relations = [], [], []
next_id = [1000]


def nid():
    next_id[0] += 1
    return next_id[0]


def node(x, y):
    i = nid()
    nodes.append((i, *to_latlon(x, y)))
    return i


def way(points, tags, closed=False):
    refs = [node(x, y) for x, y in points]
    if closed:
        refs.append(refs[0])
    i = nid()
    ways.append((i, refs, tags))
    return i


def rect(x0, y0, x1, y1):
    return [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]


# Roads: centre lines spanning the town. Surfaces: Main 10 m (width), North 2 lanes (7 m),
# South residential default (6 m), West 8 m (width), Centre 2 lanes (7 m), East 5 m (width, 1 lane).
E = 150.0
way([(-E, 0), (0, 0), (E, 0)], {"highway": "primary", "name": "Main Street", "lanes": "2", "width": "10"})
way([(-E, 80), (E, 80)], {"highway": "residential", "name": "North Street", "lanes": "2"})
way([(-E, -80), (E, -80)], {"highway": "residential", "name": "South Street"})
way([(-80, -E), (-80, E)], {"highway": "secondary", "name": "West Avenue", "lanes": "2", "width": "8"})
way([(0, -E), (0, 0), (0, E)], {"highway": "tertiary", "name": "Centre Avenue", "lanes": "2"})
way([(80, -E), (80, E)], {"highway": "residential", "name": "East Avenue", "lanes": "1", "width": "5"})
way([(80, -44), (45, -44)], {"highway": "service", "name": "Yard Lane"})
way([(-90, 95), (-90, 140)], {"highway": "footway", "name": "Garden Path"})
# The Main Street / Centre Avenue junction drawn as a road surface (20 m x 20 m).
way(rect(-10, -10, 10, 10), {"area:highway": "primary", "name": "Market Junction"}, closed=True)

buildings = [
    (rect(-72, 10, -45, 35), {"height": "12"}),
    (rect(-40, 10, -8, 30), {"building:levels": "3"}),
    (rect(-72, 45, -40, 72), {"building:levels": "4"}),
    (rect(-32, 42, -8, 72), {}),
    (rect(-72, -72, -50, -45), {"height": "9"}),
    (rect(-45, -70, -8, -40), {"building:levels": "2"}),
    (rect(-72, -35, -30, -10), {"building:levels": "5"}),
    (rect(8, -72, 35, -10), {"height": "20"}),
    (rect(42, -40, 72, -10), {"building:levels": "3"}),
    ([(42, -72), (72, -72), (72, -60), (55, -60), (55, -48), (42, -48)], {}),
    (rect(-140, 90, -95, 130), {"height": "6"}),
    (rect(-70, 90, -20, 120), {"building:levels": "2"}),
    (rect(20, 90, 60, 140), {}),
    (rect(95, 90, 140, 130), {"building:levels": "1"}),
    (rect(-140, -130, -95, -90), {}),
    (rect(-60, -125, -10, -90), {"height": "7.5"}),
    (rect(10, -120, 70, -90), {"building:levels": "4"}),
    (rect(90, 10, 140, 60), {"building:levels": "3"}),
    (rect(90, -60, 140, -15), {}),
    (rect(-140, 15, -95, 60), {"height": "10"}),
    (rect(-140, -60, -95, -20), {}),
]
c, s, h = math.cos(math.radians(30)), math.sin(math.radians(30)), 15.0
buildings.append(([(118 + c * dx - s * dy, -118 + s * dx + c * dy) for dx, dy in rect(-h, -h, h, h)],
                  {"building:levels": "2", "name": "Rotated House"}))
for pts, tags in buildings:
    way(pts, dict(building="yes", **tags), closed=True)

# A multipolygon building with a courtyard (height 15 m).
outer = way(rect(10, 12, 70, 70), {}, closed=True)
inner = way(rect(25, 27, 55, 55), {}, closed=True)
relations.append((nid(), [("way", outer, "outer"), ("way", inner, "inner")],
                  {"type": "multipolygon", "building": "yes", "height": "15", "name": "Cloister"}))

lat_min, lon_min = to_latlon(-E, -E)
lat_max, lon_max = to_latlon(E, E)
out = sys.stdout
out.write('<?xml version="1.0" encoding="UTF-8"?>\n')
out.write('<osm version="0.6" generator="map_aided_fusion maps/generate_town.py">\n')
out.write(f'  <bounds minlat="{lat_min:.7f}" minlon="{lon_min:.7f}" maxlat="{lat_max:.7f}" maxlon="{lon_max:.7f}"/>\n')
for i, lat, lon in nodes:
    out.write(f'  <node id="{i}" version="1" lat="{lat:.8f}" lon="{lon:.8f}"/>\n')
for i, refs, tags in ways:
    out.write(f'  <way id="{i}" version="1">\n')
    for r in refs:
        out.write(f'    <nd ref="{r}"/>\n')
    for k, v in tags.items():
        out.write(f'    <tag k="{k}" v="{v}"/>\n')
    out.write('  </way>\n')
for i, members, tags in relations:
    out.write(f'  <relation id="{i}" version="1">\n')
    for t, r, role in members:
        out.write(f'    <member type="{t}" ref="{r}" role="{role}"/>\n')
    for k, v in tags.items():
        out.write(f'    <tag k="{k}" v="{v}"/>\n')
    out.write('  </relation>\n')
out.write('</osm>\n')

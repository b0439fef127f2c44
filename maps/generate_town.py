#!/usr/bin/env python3
"""Writes maps/town.osm: a small fictional town laid out in local ENU metres around ORIGIN and
converted to WGS84 (osm_layout.py).
Run it only to change the town; the .osm file is what the package uses."""
import math
import sys

from osm_layout import OsmLayout, rect

ORIGIN = (49.4150, 2.8230, 40.0)  # lat, lon (degrees), altitude (m)
town = OsmLayout(ORIGIN, "maps/generate_town.py")
way, nid = town.way, town.nid


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
town.relation([("way", outer, "outer"), ("way", inner, "inner")],
              {"type": "multipolygon", "building": "yes", "height": "15", "name": "Cloister"})

town.write(sys.stdout, E)

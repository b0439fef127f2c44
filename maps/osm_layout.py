"""A map layout in local ENU metres around an origin, written as OpenStreetMap XML (WGS84).

Shared by the generators of the bundled maps (generate_town.py, generate_village.py). The conversion is the
ellipsoidal local tangent plane to first order: the error is below 1 mm over 200 m."""
import math

A, F = 6378137.0, 1 / 298.257223563
E2 = F * (2 - F)


class OsmLayout:
    def __init__(self, origin, generator):
        self.origin = origin  # lat, lon (degrees), altitude (m)
        self.generator = generator
        self.nodes, self.ways, self.relations = [], [], []
        self._next_id = 1000

    def to_latlon(self, x, y):
        lat0 = math.radians(self.origin[0])
        s = math.sin(lat0)
        n = A / math.sqrt(1 - E2 * s * s)            # prime vertical radius
        m = A * (1 - E2) / (1 - E2 * s * s) ** 1.5   # meridian radius
        return self.origin[0] + math.degrees(y / m), self.origin[1] + math.degrees(x / (n * math.cos(lat0)))

    def nid(self):
        self._next_id += 1
        return self._next_id

    def node(self, x, y):
        i = self.nid()
        self.nodes.append((i, *self.to_latlon(x, y)))
        return i

    def way(self, points, tags, closed=False):
        refs = [self.node(x, y) for x, y in points]
        if closed:
            refs.append(refs[0])
        i = self.nid()
        self.ways.append((i, refs, tags))
        return i

    def relation(self, members, tags):
        self.relations.append((self.nid(), members, tags))

    def write(self, out, extent):
        lat_min, lon_min = self.to_latlon(-extent, -extent)
        lat_max, lon_max = self.to_latlon(extent, extent)
        out.write('<?xml version="1.0" encoding="UTF-8"?>\n')
        out.write(f'<osm version="0.6" generator="map_aided_fusion {self.generator}">\n')
        out.write(f'  <bounds minlat="{lat_min:.7f}" minlon="{lon_min:.7f}" maxlat="{lat_max:.7f}" '
                  f'maxlon="{lon_max:.7f}"/>\n')
        for i, lat, lon in self.nodes:
            out.write(f'  <node id="{i}" version="1" lat="{lat:.8f}" lon="{lon:.8f}"/>\n')
        for i, refs, tags in self.ways:
            out.write(f'  <way id="{i}" version="1">\n')
            for r in refs:
                out.write(f'    <nd ref="{r}"/>\n')
            self._tags(out, tags)
            out.write('  </way>\n')
        for i, members, tags in self.relations:
            out.write(f'  <relation id="{i}" version="1">\n')
            for t, r, role in members:
                out.write(f'    <member type="{t}" ref="{r}" role="{role}"/>\n')
            self._tags(out, tags)
            out.write('  </relation>\n')
        out.write('</osm>\n')

    @staticmethod
    def _tags(out, tags):
        for k, v in tags.items():
            out.write(f'    <tag k="{k}" v="{v}"/>\n')


def rect(x0, y0, x1, y1):
    return [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]


def rotated_rect(cx, cy, length, width, angle_deg):
    """The corners of a length x width rectangle centred on (cx, cy), its length along angle_deg."""
    c, s = math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))
    return [(cx + c * dx - s * dy, cy + s * dx + c * dy)
            for dx, dy in rect(-length / 2, -width / 2, length / 2, width / 2)]

"""Generated drives: a scenario template (a map and ranges) and a seed give one simulator scenario.

A template (scenarios/templates/*.yaml) names an OSM map and the ranges each drive draws from: traffic density and
speeds, parked and leaving vehicles, pedestrians and cyclists, street furniture, the ego's speed, the lidar preset,
pose and map errors. The ego route and every path are random walks on the road graph read from the map itself
(drivable `highway` centre lines, widths as the map loader computes them from config/prior_grid.yaml), so a new
map needs no hand-written routes. Objects are kept only where they clear the mapped buildings.

A drive set (learning/drives.yaml) lists the training and the held-out drives as (template, seed) pairs.
"""
import math
import os
import random
import xml.etree.ElementTree as ET

import yaml

from . import geometry as geo

def _package_root():
    """The source checkout (learning/maf_learning/..) or, installed, <prefix>/share/map_aided_fusion."""
    if os.environ.get("MAF_PACKAGE_ROOT"):
        return os.path.abspath(os.environ["MAF_PACKAGE_ROOT"])
    here = os.path.dirname(os.path.abspath(__file__))
    for root in (os.path.join(here, "..", ".."), os.path.join(here, "..", "..", "..", "share", "map_aided_fusion")):
        if os.path.isfile(os.path.join(root, "config", "fusion.yaml")):
            return os.path.abspath(root)
    return os.path.abspath(os.path.join(here, "..", ".."))


PACKAGE_ROOT = _package_root()
TEMPLATE_DIR = os.path.join(PACKAGE_ROOT, "scenarios", "templates")

_A, _F = 6378137.0, 1 / 298.257223563
_E2 = _F * (2 - _F)

LANE_MAX_OFFSET = 1.75      # m, lane centre from the road centre line (3.5 m lanes)
KERB_PARKING_WIDTH = 9.0    # m, roads at least this wide have kerb parking inside the surface
JUNCTION_CLEARANCE = 12.0   # m, no parked car or furniture closer to a junction
BUILDING_CLEARANCE = 0.4    # m, an object's footprint keeps this far from every mapped building
OBJECT_SPACING = 6.5        # m, between the centres of parked vehicles
VEHICLE_KINDS = (("car", 0.7), ("van", 0.15), ("truck", 0.07), ("bus", 0.08))
VEHICLE_SIZE = {"car": (4.5, 1.8), "van": (5.2, 2.0), "truck": (8.0, 2.5), "bus": (12.0, 2.55)}
FURNITURE_RADIUS = {"pole": 0.15, "bin": 0.45, "tree": 0.4}

TEMPLATE_KEYS = {
    "name": str, "map": str, "map_origin": list, "default_building_height": float, "ego_speed": list,
    "traffic": list, "traffic_speed": list, "parked": list, "leaving": list, "pedestrians": list, "cyclists": list,
    "furniture": list, "lidar_presets": dict, "pose_error_probability": float, "map_error_probability": float,
}
DRIVE_SET_KEYS = {"duration", "training", "held_out", "sealed"}
# The splits of a drive set: training (a study sees these), held_out (scored per drive and pooled), sealed (fresh
# drives frozen before a redesign: scored pooled only, their per-drive results never written).
SPLITS = ("training", "held_out", "sealed")
DRIVE_KEYS = {"template", "seed", "preset", "duration"}
PRESETS = ("ibeo4", "vlp32", "hdl64")


class DriveError(ValueError):
    """A template or drive set that cannot be used; the message names the item."""


# ---- templates and drive sets ----------------------------------------------------------------------------


def load_template(name_or_path):
    path = name_or_path if name_or_path.endswith(".yaml") else os.path.join(TEMPLATE_DIR, name_or_path + ".yaml")
    if not os.path.isfile(path):
        raise DriveError(f"template '{name_or_path}': no file {path}")
    with open(path) as f:
        t = yaml.safe_load(f) or {}
    if not isinstance(t, dict):
        raise DriveError(f"template {path}: must be a mapping")
    for key, value in t.items():
        if key not in TEMPLATE_KEYS:
            raise DriveError(f"template {path}: unknown key '{key}' (known: {', '.join(sorted(TEMPLATE_KEYS))})")
        want = TEMPLATE_KEYS[key]
        if want is float and isinstance(value, int):
            value = float(value)
        if not isinstance(value, want):
            raise DriveError(f"template {path}: '{key}' must be a {want.__name__}")
        if want is list and key not in ("map_origin",) and (len(value) != 2 or value[0] > value[1]):
            raise DriveError(f"template {path}: '{key}' must be a range [lo, hi] with lo <= hi")
    for key in ("name", "map", "map_origin"):
        if key not in t:
            raise DriveError(f"template {path}: '{key}' is required")
    for preset in t.get("lidar_presets", {}):
        if preset not in PRESETS:
            raise DriveError(f"template {path}: lidar_presets: unknown preset '{preset}' ({', '.join(PRESETS)})")
    t["map_path"] = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(path)), t["map"]))
    return t


def load_drive_set(path):
    """{'duration': s, 'training': [drive], 'held_out': [drive], 'sealed': [drive]}, each drive {'template', 'seed',
    ...}; the splits must not share a drive."""
    with open(path) as f:
        d = yaml.safe_load(f) or {}
    if not isinstance(d, dict):
        raise DriveError(f"drive set {path}: must be a mapping")
    for key in d:
        if key not in DRIVE_SET_KEYS:
            raise DriveError(f"drive set {path}: unknown key '{key}' (known: {', '.join(sorted(DRIVE_SET_KEYS))})")
    duration = float(d.get("duration", 20.0))
    if not 1.0 <= duration <= 600.0:
        raise DriveError(f"drive set {path}: duration {duration} s is outside [1, 600]")
    out = {"duration": duration}
    seen = {}
    for split in SPLITS:
        drives = d.get(split, []) or []
        if not isinstance(drives, list):
            raise DriveError(f"drive set {path}: '{split}' must be a list")
        out[split] = []
        for i, drive in enumerate(drives):
            where = f"drive set {path}: {split}[{i}]"
            if not isinstance(drive, dict):
                raise DriveError(f"{where}: must be a mapping {{template, seed}}")
            for key in drive:
                if key not in DRIVE_KEYS:
                    raise DriveError(f"{where}: unknown key '{key}' (known: {', '.join(sorted(DRIVE_KEYS))})")
            if "template" not in drive or "seed" not in drive:
                raise DriveError(f"{where}: needs 'template' and 'seed'")
            if drive.get("preset") is not None and drive["preset"] not in PRESETS:
                raise DriveError(f"{where}: unknown preset '{drive['preset']}' ({', '.join(PRESETS)})")
            drive = dict(drive)
            drive.setdefault("duration", duration)
            name = drive_name(drive)
            if name in seen and seen[name] != split:
                raise DriveError(f"{where}: {name} is also a {seen[name]} drive: the splits must not share a drive")
            seen[name] = split
            out[split].append(drive)
    return out


def drive_name(drive):
    name = f"{os.path.splitext(os.path.basename(drive['template']))[0]}_{int(drive['seed'])}"
    return name + (f"_{drive['preset']}" if drive.get("preset") else "")


# ---- the map: road graph and buildings -------------------------------------------------------------------


class RoadMap:
    """Drivable road centre lines (with widths) and building footprints of an OSM file, in local metres."""

    def __init__(self, osm_path, origin, prior_config=None):
        cfg_path = prior_config or os.path.join(PACKAGE_ROOT, "config", "prior_grid.yaml")
        with open(cfg_path) as f:
            cfg = yaml.safe_load(f)
        drivable = set(cfg["drivable_classes"])
        class_widths = cfg["road_class_widths"]
        lat0, lon0 = math.radians(origin[0]), origin[1]
        s = math.sin(lat0)
        n = _A / math.sqrt(1 - _E2 * s * s)
        m = _A * (1 - _E2) / (1 - _E2 * s * s) ** 1.5
        root = ET.parse(osm_path).getroot()
        nodes = {}
        for nd in root.iter("node"):
            nodes[nd.get("id")] = (math.radians(float(nd.get("lon")) - lon0) * n * math.cos(lat0),
                                   math.radians(float(nd.get("lat")) - origin[0]) * m)
        ways = {}
        self.roads, self.buildings = [], []
        for w in root.iter("way"):
            pts = [nodes[r.get("ref")] for r in w.iter("nd") if r.get("ref") in nodes]
            tags = {t.get("k"): t.get("v") for t in w.iter("tag")}
            ways[w.get("id")] = pts
            if tags.get("highway") in drivable and tags.get("tunnel", "no") in ("no", "building_passage"):
                self.roads.append((pts, self._width(tags, class_widths, cfg), tags.get("name", w.get("id"))))
            elif tags.get("building", "no") != "no" and len(pts) >= 4:
                self.buildings.append(pts[:-1])
        for r in root.iter("relation"):
            tags = {t.get("k"): t.get("v") for t in r.iter("tag")}
            if tags.get("building", "no") != "no":
                for mem in r.iter("member"):
                    if mem.get("role") == "outer" and mem.get("ref") in ways and len(ways[mem.get("ref")]) >= 4:
                        self.buildings.append(ways[mem.get("ref")][:-1])
        self._build_graph()

    @staticmethod
    def _width(tags, class_widths, cfg):
        w = tags.get("width")
        if w:
            try:
                return float(w.split()[0])
            except ValueError:
                pass
        if tags.get("lanes"):
            try:
                return int(tags["lanes"]) * float(cfg.get("lane_width", 3.5))
            except ValueError:
                pass
        return float(class_widths.get(tags.get("highway"), cfg.get("default_road_width", 6.0)))

    def _build_graph(self):
        """Nodes at road ends and crossings; an edge per piece of road between two nodes."""
        cuts = [set([0.0, geo.length(line)]) for line, _, _ in self.roads]
        for i, (a, _, _) in enumerate(self.roads):
            for j in range(i + 1, len(self.roads)):
                b = self.roads[j][0]
                for ka in range(len(a) - 1):
                    for kb in range(len(b) - 1):
                        p = geo.segment_intersection(a[ka], a[ka + 1], b[kb], b[kb + 1])
                        if p is not None:
                            cuts[i].add(geo.length(a[:ka + 1] + [p]))
                            cuts[j].add(geo.length(b[:kb + 1] + [p]))
        self.nodes = []

        def node_of(p):
            for k, q in enumerate(self.nodes):
                if math.hypot(p[0] - q[0], p[1] - q[1]) < 1.0:
                    return k
            self.nodes.append(p)
            return len(self.nodes) - 1

        self.edges = []  # (u, v, line, width, name)
        for (line, width, name), c in zip(self.roads, cuts):
            s = sorted(c)
            for s0, s1 in zip(s, s[1:]):
                if s1 - s0 < 0.5:
                    continue
                piece = geo.sub_line(line, s0, s1)
                self.edges.append((node_of(piece[0]), node_of(piece[-1]), piece, width, name))
        self.adjacent = {k: [] for k in range(len(self.nodes))}
        for e, (u, v, _, _, _) in enumerate(self.edges):
            self.adjacent[u].append((e, False))
            self.adjacent[v].append((e, True))

    def edge_line(self, e, reverse):
        line = self.edges[e][2]
        return list(reversed(line)) if reverse else list(line)

    def near_junction(self, p):
        return any(math.hypot(p[0] - q[0], p[1] - q[1]) < JUNCTION_CLEARANCE
                   for k, q in enumerate(self.nodes) if len(self.adjacent[k]) > 2)

    def clear_of_buildings(self, poly, clearance=BUILDING_CLEARANCE):
        pts = geo.ring_samples(poly, 0.4) if len(poly) > 1 else poly
        return all(geo.dist_point_polygon(p, b) >= clearance for b in self.buildings for p in pts)

    def random_walk(self, rng, min_length, start_edges=None, tries=60):
        """A route along the graph (no U-turns) at least min_length long, as [(edge, reversed)], or the longest."""
        best = []
        candidates = start_edges or list(range(len(self.edges)))
        for _ in range(tries):
            e = rng.choice(candidates)
            rev = rng.random() < 0.5
            route = [(e, rev)]
            total = geo.length(self.edges[e][2])
            while total < min_length:
                u, v = self.edges[e][:2]
                at = u if rev else v
                nxt = [(f, r) for f, r in self.adjacent[at] if f != e]
                if not nxt:
                    break
                e, rev = rng.choice(nxt)
                if (e, rev) in route:
                    break
                route.append((e, rev))
                total += geo.length(self.edges[e][2])
            if total >= min_length:
                return route
            if total > sum(geo.length(self.edges[f][2]) for f, _ in best):
                best = route
        return best

    def route_line(self, route, side_offset=None):
        """The centre line of a route, moved to its right lane (or by -side_offset)."""
        pts = []
        for e, rev in route:
            piece = self.edge_line(e, rev)
            width = self.edges[e][3]
            d = side_offset if side_offset is not None else min(width / 4, LANE_MAX_OFFSET)
            moved = geo.offset(piece, -d)
            pts.extend(moved if not pts else moved[1:])
        return pts


# ---- one drive -------------------------------------------------------------------------------------------


def _uniform(rng, r):
    return rng.uniform(float(r[0]), float(r[1]))


def _count(rng, r):
    return rng.randint(int(r[0]), int(r[1]))


def _weighted(rng, choices):
    total = sum(w for _, w in choices)
    x = rng.random() * total
    for value, w in choices:
        x -= w
        if x <= 0:
            return value
    return choices[-1][0]


def _pt(p):
    return [round(p[0], 2), round(p[1], 2)]


def generate(template, drive, road_map=None):
    """The scenario (a dict in the simulator's format) of one drive: deterministic in (template, seed)."""
    t = load_template(template) if isinstance(template, str) else template
    seed = int(drive["seed"])
    duration = float(drive.get("duration", 20.0))
    rng = random.Random(f"{t['name']}:{seed}")
    rm = road_map or RoadMap(t["map_path"], t["map_origin"])
    objects = []
    placed = []  # (x, y) of parked and static objects, for spacing

    ego_speed = _uniform(rng, t.get("ego_speed", [5.0, 10.0]))
    ego_route = rm.random_walk(rng, ego_speed * duration + 40.0)
    ego_line = rm.route_line(ego_route)
    near = set(e for e, _ in ego_route)
    for e, _ in ego_route:
        for node in rm.edges[e][:2]:
            near.update(f for f, _ in rm.adjacent[node])
    near = sorted(near)
    stops = []
    if rng.random() < 0.4:
        stops.append({"s": round(rng.uniform(20.0, max(25.0, 0.6 * ego_speed * duration)), 1),
                      "duration": round(rng.uniform(1.0, 4.0), 1)})
    ego = {"route": [_pt(p) for p in ego_line], "speed": round(ego_speed, 2), "acceleration": 1.5,
           "corner_radius": 8.0}
    if stops:
        ego["stops"] = stops

    def spaced(p, spacing=OBJECT_SPACING):
        return all(math.hypot(p[0] - q[0], p[1] - q[1]) >= spacing for q in placed)

    def kerb_spot(kind, tries=40):
        """(x, y, heading, edge, side, s) of a parking place for kind, or None."""
        length_m, width_m = VEHICLE_SIZE[kind]
        for _ in range(tries):
            e = rng.choice(near)
            line, width = rm.edges[e][2], rm.edges[e][3]
            total = geo.length(line)
            if total < 2 * JUNCTION_CLEARANCE:
                continue
            s = rng.uniform(JUNCTION_CLEARANCE, total - JUNCTION_CLEARANCE)
            x, y, h = geo.point_at(line, s)
            side = rng.choice((-1, 1))
            d = width / 2 - 0.9 if width >= KERB_PARKING_WIDTH else width / 2 + 1.1
            cx, cy = x - side * d * math.sin(h), y + side * d * math.cos(h)
            heading = h if side < 0 else h + math.pi
            poly = geo.rectangle(cx, cy, heading, length_m + 0.4, width_m + 0.4)
            if rm.near_junction((cx, cy)) or not spaced((cx, cy), max(OBJECT_SPACING, length_m + 2.0)):
                continue
            if not rm.clear_of_buildings(poly):
                continue
            return cx, cy, heading, e, side, s
        return None

    for _ in range(_count(rng, t.get("parked", [3, 8]))):
        kind = "car" if rng.random() < 0.85 else "van"
        spot = kerb_spot(kind)
        if spot:
            placed.append(spot[:2])
            objects.append({"kind": kind, "at": _pt(spot[:2]), "yaw_deg": round(math.degrees(spot[2]), 1)})

    for _ in range(_count(rng, t.get("leaving", [0, 2]))):
        spot = kerb_spot("car")
        if not spot:
            continue
        cx, cy, _, e, side, s = spot
        placed.append((cx, cy))
        line, width = rm.edges[e][2], rm.edges[e][3]
        lane = min(width / 4, LANE_MAX_OFFSET)
        # from the kerb into the right lane of its direction (10 m on), then along the road to its end
        if side < 0:
            rest = geo.offset(geo.sub_line(line, min(s + 10.0, geo.length(line) - 0.5), geo.length(line)), -lane)
        else:
            rest = geo.offset(list(reversed(geo.sub_line(line, 0.0, max(s - 10.0, 0.5)))), -lane)
        objects.append({"kind": "car", "path": [_pt((cx, cy))] + [_pt(p) for p in rest],
                        "speed": round(rng.uniform(4.0, 8.0), 1), "acceleration": 1.5, "corner_radius": 4.0,
                        "stops": [{"s": 0.0, "duration": round(rng.uniform(2.0, 0.6 * duration), 1)}],
                        "end": "vanish"})

    for k in range(_count(rng, t.get("traffic", [2, 6]))):
        kind = _weighted(rng, VEHICLE_KINDS)
        speed = _uniform(rng, t.get("traffic_speed", [6.0, 12.0]))
        if k == 0:  # one vehicle ahead of the ego on its own route
            line = geo.sub_line(ego_line, min(25.0, geo.length(ego_line) / 3), geo.length(ego_line))
            start = 0.0
        else:
            line = rm.route_line(rm.random_walk(rng, speed * duration + 60.0, near))
            start = round(rng.uniform(0.0, 0.6 * duration), 1)
        if len(line) < 2:
            continue
        objects.append({"kind": kind, "path": [_pt(p) for p in line], "speed": round(speed, 2),
                        "acceleration": 2.0, "corner_radius": 8.0, "start_time": start, "end": "vanish"})

    for _ in range(_count(rng, t.get("cyclists", [0, 2]))):
        route = rm.random_walk(rng, 120.0, near)
        width = min(rm.edges[e][3] for e, _ in route) if route else 6.0
        line = rm.route_line(route, side_offset=max(0.6, width / 2 - 0.8))
        if len(line) >= 2:
            objects.append({"kind": "cyclist", "path": [_pt(p) for p in line],
                            "speed": round(rng.uniform(3.5, 6.0), 2), "corner_radius": 5.0,
                            "start_time": round(rng.uniform(0.0, 0.5 * duration), 1), "end": "vanish"})

    def pavement_line(e, offset_out, s0, s1, side):
        line, width = rm.edges[e][2], rm.edges[e][3]
        return geo.offset(geo.sub_line(line, s0, s1), side * (width / 2 + offset_out))

    for _ in range(_count(rng, t.get("pedestrians", [2, 6]))):
        for _try in range(30):
            e = rng.choice(near)
            total = geo.length(rm.edges[e][2])
            walk = rng.uniform(20.0, 60.0)
            if total < walk + 2.0:
                continue
            s0 = rng.uniform(0.0, total - walk)
            side = rng.choice((-1, 1))
            if rng.random() < 0.2:  # crossing the road
                x, y, h = geo.point_at(rm.edges[e][2], s0)
                half = rm.edges[e][3] / 2 + 1.2
                line = [(x - half * math.sin(h), y + half * math.cos(h)), (x + half * math.sin(h), y - half * math.cos(h))]
            else:
                line = pavement_line(e, 1.2, s0, s0 + walk, side)
                if rng.random() < 0.5:
                    line = list(reversed(line))
            if not all(rm.clear_of_buildings([p], 0.6) for p in geo.ring_samples(line + [line[-1]], 1.0)):
                continue
            ped = {"kind": "pedestrian", "path": [_pt(p) for p in line], "speed": round(rng.uniform(1.0, 1.6), 2),
                   "start_time": round(rng.uniform(0.0, 0.5 * duration), 1)}
            if rng.random() < 0.3:
                ped["stops"] = [{"s": 0.0, "duration": round(rng.uniform(2.0, 10.0), 1)}]
            objects.append(ped)
            break

    for _ in range(_count(rng, t.get("furniture", [5, 12]))):
        kind = _weighted(rng, (("pole", 0.5), ("bin", 0.25), ("tree", 0.25)))
        for _try in range(30):
            e = rng.choice(near)
            line, width = rm.edges[e][2], rm.edges[e][3]
            total = geo.length(line)
            if total < 4.0:
                continue
            x, y, h = geo.point_at(line, rng.uniform(1.0, total - 1.0))
            side = rng.choice((-1, 1))
            d = width / 2 + (0.7 if kind != "tree" else 1.0)
            p = (x - side * d * math.sin(h), y + side * d * math.cos(h))
            if rm.near_junction(p) or not spaced(p, 3.0):
                continue
            if not rm.clear_of_buildings([p], FURNITURE_RADIUS[kind] + 0.3):
                continue
            placed.append(p)
            objects.append({"kind": kind, "at": _pt(p)})
            break

    for i, o in enumerate(objects):
        o["id"] = i + 1
    objects = [dict([("id", o.pop("id"))] + list(o.items())) for o in objects]

    preset = drive.get("preset") or _weighted(rng, sorted(t.get("lidar_presets", {"vlp32": 1.0}).items()))
    scenario = {
        "name": drive_name(drive),
        "map": t["map_path"],
        "map_origin": list(t["map_origin"]),
        "duration": duration,
        "seed": seed,
        "default_building_height": float(t.get("default_building_height", 10.0)),
        "tf_rate_hz": 100.0,
        "lidar": {"preset": preset},
        "ground_truth": {"size_x": 100.0, "size_y": 100.0, "resolution": 0.5, "stop_speed": 0.1},
        "ego": ego,
    }
    if rng.random() < float(t.get("pose_error_probability", 0.0)):
        a = rng.uniform(0.0, 2 * math.pi)
        b = rng.uniform(0.1, 0.5)
        scenario["localisation_error"] = {"bias": [round(b * math.cos(a), 3), round(b * math.sin(a), 3)],
                                          "random_walk": round(rng.uniform(0.0, 0.3), 3), "random_walk_time": 10.0,
                                          "white_noise": round(rng.uniform(0.0, 0.05), 3)}
    if rng.random() < float(t.get("map_error_probability", 0.0)):
        errors = {"shift": [round(rng.uniform(-0.4, 0.4), 2), round(rng.uniform(-0.4, 0.4), 2)],
                  "rotation_deg": round(rng.uniform(-0.2, 0.2), 3)}
        seen = [b for b in rm.buildings if min(geo.dist_point_polyline(p, ego_line) for p in b) < 30.0]
        if seen:
            b = rng.choice(seen)
            cx = sum(p[0] for p in b) / len(b)
            cy = sum(p[1] for p in b) / len(b)
            if geo.point_in_polygon((cx, cy), b):
                errors["absent_buildings"] = [{"at": _pt((cx, cy))}]
        lot = _free_lot(rng, rm, ego_line)
        if lot:
            errors["unmapped_buildings"] = [{"name": "unmapped_lot", "footprint": [_pt(p) for p in lot],
                                             "height": round(rng.uniform(4.0, 12.0), 1)}]
        scenario["map_errors"] = errors
    scenario["objects"] = objects
    return scenario


def _free_lot(rng, rm, ego_line, tries=200):
    """A rectangle 15-40 m from the ego route, clear of every road surface and building: an unmapped building."""
    total = geo.length(ego_line)
    for _ in range(tries):
        x, y, h = geo.point_at(ego_line, rng.uniform(0.0, total))
        d = rng.choice((-1, 1)) * rng.uniform(15.0, 40.0)
        c = (x - d * math.sin(h), y + d * math.cos(h))
        poly = geo.rectangle(c[0], c[1], h, rng.uniform(8.0, 16.0), rng.uniform(8.0, 14.0))
        if not rm.clear_of_buildings(poly, 2.0):
            continue
        if all(geo.dist_point_polyline(p, line) >= width / 2 + 2.0 for line, width, _ in rm.roads
               for p in geo.ring_samples(poly, 1.0)):
            return poly
    return None


def write_scenario(scenario, path):
    with open(path, "w") as f:
        f.write(f"# Generated by learning/maf_learning/drives.py: drive {scenario['name']} (keys: "
                "scenarios/default.yaml)\n")
        yaml.safe_dump(scenario, f, sort_keys=False, default_flow_style=None, width=118)

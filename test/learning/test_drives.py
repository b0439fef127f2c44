"""The drive generator: deterministic per seed, objects clear of the buildings, routes on the roads, a held-out split
that shares no drive with the training split, and scenarios the simulator accepts."""
import math
import os
import subprocess

import pytest
import yaml

from conftest import ROOT, write_drive_set
from maf_learning import drives, geometry as geo

SEEDS = (1, 2, 3, 101)


@pytest.fixture(scope="module")
def maps():
    out = {}
    for name in ("town", "village"):
        t = drives.load_template(name)
        out[name] = (t, drives.RoadMap(t["map_path"], t["map_origin"]))
    return out


def test_geometry_offsets_and_arc_length():
    line = [(0.0, 0.0), (10.0, 0.0), (10.0, 10.0)]
    assert geo.length(line) == pytest.approx(20.0)
    assert geo.point_at(line, 15.0)[:2] == pytest.approx((10.0, 5.0))
    right = geo.offset(line, -1.0)  # the right of an eastward then northward line
    assert right[0] == pytest.approx((0.0, -1.0))
    assert right[1] == pytest.approx((11.0, -1.0))  # mitred corner
    assert right[2] == pytest.approx((11.0, 10.0))
    square = [(0, 0), (4, 0), (4, 4), (0, 4)]
    assert geo.point_in_polygon((2, 2), square) and not geo.point_in_polygon((5, 2), square)
    assert geo.dist_point_polygon((6, 2), square) == pytest.approx(2.0)
    assert geo.segment_intersection((0, 0), (2, 2), (0, 2), (2, 0)) == pytest.approx((1.0, 1.0))


def test_road_graphs_of_both_maps(maps):
    town, village = maps["town"][1], maps["village"][1]
    assert len(town.roads) == 7 and len(town.buildings) == 23  # maps/README.md (footway not drivable)
    # the grid town has four-way junctions (a node of the road graph with four road pieces)
    assert max(len(a) for a in town.adjacent.values()) == 4
    assert len(village.roads) == 4 and len(village.buildings) >= 40
    # no village building on a road surface (the generator's own rule)
    for b in village.buildings:
        for p in geo.ring_samples(b, 1.0):
            for line, width, name in village.roads:
                assert geo.dist_point_polyline(p, line) >= width / 2 + 2.0, name


def test_generation_is_deterministic_and_seeds_differ(maps):
    t, rm = maps["town"]
    a = drives.generate(t, {"template": "town", "seed": 5, "duration": 20.0}, rm)
    b = drives.generate(t, {"template": "town", "seed": 5, "duration": 20.0}, rm)
    c = drives.generate(t, {"template": "town", "seed": 6, "duration": 20.0}, rm)
    assert yaml.safe_dump(a) == yaml.safe_dump(b)
    assert yaml.safe_dump(a) != yaml.safe_dump(c)


@pytest.mark.parametrize("name", ["town", "village"])
def test_drives_place_objects_clear_of_buildings_and_routes_on_roads(maps, name):
    t, rm = maps[name]
    kinds = set()
    for seed in SEEDS:
        sc = drives.generate(t, {"template": name, "seed": seed, "duration": 20.0}, rm)
        route = sc["ego"]["route"]
        assert geo.length(route) >= sc["ego"]["speed"] * 20.0, (seed, "the route ends before the drive does")
        for p in route:
            assert min(geo.dist_point_polyline(p, line) - w / 2 for line, w, _ in rm.roads) <= 0.01, (seed, p)
        for o in sc["objects"]:
            kinds.add(o["kind"])
            if "at" in o:
                assert all(geo.dist_point_polygon(o["at"], b) >= 0.3 for b in rm.buildings), (seed, o)
            elif o["kind"] == "pedestrian":
                assert all(not geo.point_in_polygon(p, b) for p in o["path"] for b in rm.buildings), (seed, o)
        assert sorted(o["id"] for o in sc["objects"]) == list(range(1, len(sc["objects"]) + 1))
    assert {"car", "pedestrian", "pole"} <= kinds


def test_bundled_drive_set_has_disjoint_held_out_and_sealed_splits():
    ds = drives.load_drive_set(os.path.join(ROOT, "learning", "drives.yaml"))
    train = {drives.drive_name(d) for d in ds["training"]}
    held = {drives.drive_name(d) for d in ds["held_out"]}
    sealed = {drives.drive_name(d) for d in ds["sealed"]}
    assert len(train) >= 4 and len(held) >= 4 and len(sealed) >= 6
    assert not train & held and not train & sealed and not held & sealed
    # No seed is shared either: a sealed drive is not a held-out drive with another lidar.
    seeds = lambda split: {(d["template"], d["seed"]) for d in ds[split]}  # noqa: E731
    assert not seeds("sealed") & (seeds("training") | seeds("held_out"))
    assert {d["template"] for d in ds["training"]} == {d["template"] for d in ds["held_out"]} == {"town", "village"}
    assert {d["template"] for d in ds["sealed"]} == {"town", "village"}


def test_drive_set_errors_name_the_item(tmp_path):
    def error(text):
        p = tmp_path / "set.yaml"
        p.write_text(text)
        with pytest.raises(drives.DriveError) as e:
            drives.load_drive_set(str(p))
        return str(e.value)

    assert "unknown key 'trainig'" in error("trainig: []\n")
    assert "training[0]: unknown key 'sed'" in error("training: [{template: town, sed: 1}]\n")
    assert "unknown preset 'velodyne'" in error("training: [{template: town, seed: 1, preset: velodyne}]\n")
    assert "also a training drive" in error("training: [{template: town, seed: 1}]\nheld_out: [{template: town, seed: 1}]\n")
    assert "also a held_out drive" in error("held_out: [{template: town, seed: 1}]\nsealed: [{template: town, seed: 1}]\n")
    assert "'sealed' must be a list" in error("sealed: {template: town, seed: 1}\n")
    assert "duration" in error("duration: 0\n")


def test_template_errors_name_the_item(tmp_path):
    p = tmp_path / "t.yaml"
    p.write_text("name: t\nmap: ../../maps/town.osm\nmap_origin: [49.415, 2.823]\ntrafic: [1, 2]\n")
    with pytest.raises(drives.DriveError, match="unknown key 'trafic'"):
        drives.load_template(str(p))
    p.write_text("name: t\nmap: x.osm\nmap_origin: [49.415, 2.823]\ntraffic: [5, 2]\n")
    with pytest.raises(drives.DriveError, match="'traffic' must be a range"):
        drives.load_template(str(p))


def test_simulator_accepts_generated_drives_and_names_unknown_keys(maps, tools, tmp_path):
    for name in ("town", "village"):
        t, rm = maps[name]
        sc = drives.generate(t, {"template": name, "seed": 3, "duration": 1.0, "preset": "ibeo4"}, rm)
        path = tmp_path / f"{name}.yaml"
        drives.write_scenario(sc, str(path))
        r = subprocess.run([tools["simulate"], "--scenario", str(path), "--out", str(tmp_path / f"{name}.bag"),
                            "--quiet"], capture_output=True, text=True, timeout=120)
        assert r.returncode == 0, r.stderr
        assert (tmp_path / f"{name}.bag").stat().st_size > 0
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: bad\nego: {route: [[0, 0], [10, 0]], speed: 2}\nobjects: [{kind: car, at: [5, 5], colour: red}]\n")
    r = subprocess.run([tools["simulate"], "--scenario", str(bad), "--out", str(tmp_path / "bad.bag")],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode != 0
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and "objects[0].colour" in lines[0]


def test_make_drives_writes_every_drive(tmp_path):
    ds = write_drive_set(str(tmp_path / "set.yaml"))
    r = subprocess.run([os.path.join(ROOT, "learning", "make_drives"), "--drives", ds, "--out", str(tmp_path / "out")],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    written = sorted(os.listdir(tmp_path / "out"))
    assert written == ["town_101_ibeo4.yaml", "town_1_ibeo4.yaml", "village_1_ibeo4.yaml"]
    sc = yaml.safe_load((tmp_path / "out" / "town_1_ibeo4.yaml").read_text())
    assert sc["lidar"]["preset"] == "ibeo4" and sc["duration"] == 3.0
    assert math.isclose(sc["map_origin"][0], 49.415)

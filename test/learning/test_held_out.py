"""learning/held_out: the held-out drives scored per drive and pooled, end to end on a short drive set."""
import json
import os
import subprocess
import sys

import pytest

from conftest import ROOT, bin_dir, write_drive_set

HELD_OUT = os.path.join(ROOT, "learning", "held_out")


def run_held_out(args, timeout=600):
    env = dict(os.environ, MAF_BIN=bin_dir(), PYTHONDONTWRITEBYTECODE="1")
    return subprocess.run([sys.executable, HELD_OUT] + args, capture_output=True, text=True, timeout=timeout, env=env)


def test_one_drive_pools_to_its_own_scores_and_two_drives_sum(tmp_path, tools):
    one = write_drive_set(str(tmp_path / "one.yaml"), held_out=[("town", 101, "vlp32")])
    r = run_held_out(["--drives", one, "--out", str(tmp_path / "one")])
    assert r.returncode == 0, r.stderr
    result = json.load(open(tmp_path / "one" / "metrics.json"))
    assert [d["name"] for d in result["drives"]] == ["town_101_vlp32"] and result["drives"][0]["preset"] == "vlp32"
    assert set(result["variants"]) == {"default", "paper"}
    for profile, v in result["variants"].items():
        drive, pooled = v["drives"]["town_101_vlp32"], v["pooled"]
        # Pooling one drive's confusion matrix and objects gives back evaluate's own figures of that drive.
        for key in ("free.iou", "building.iou", "stopped.iou", "moving.iou", "moving.precision", "moving.recall",
                    "movers.all.seen", "movers.all.detected_within_1s", "movers.all.detected_within_0_5s",
                    "tracks.mota", "tracks.velocity_rmse_mps"):
            if key.startswith("tracks.") and profile == "paper":
                assert key not in pooled, "the paper's method has no tracks"
                continue
            assert pooled[key] == pytest.approx(drive[key], abs=1e-5), f"{profile}: {key}"
    assert f"wrote {tmp_path / 'one'}" in r.stdout

    two = write_drive_set(str(tmp_path / "two.yaml"), held_out=[("town", 101, "vlp32"), ("village", 102, "hdl64")])
    r = run_held_out(["--drives", two, "--out", str(tmp_path / "two"), "--work", str(tmp_path / "one")])
    assert r.returncode == 0, r.stderr
    assert "simulated town_101" not in r.stdout, "the first drive's bag is reused"
    v = json.load(open(tmp_path / "two" / "metrics.json"))["variants"]["default"]
    assert v["pooled"]["movers.all.seen"] == sum(d["movers.all.seen"] for d in v["drives"].values())
    assert v["pooled"]["tracks.objects"] == sum(d["tracks.objects"] for d in v["drives"].values())


def test_a_drive_set_without_held_out_drives_is_a_one_line_error(tmp_path):
    path = tmp_path / "none.yaml"
    path.write_text("duration: 3.0\ntraining:\n  - {template: town, seed: 1}\nheld_out: []\n")
    r = run_held_out(["--drives", str(path), "--out", str(tmp_path / "out")])
    assert r.returncode != 0
    assert r.stderr.strip().startswith("held_out:") and len(r.stderr.strip().splitlines()) == 1


def test_sealed_drives_are_written_pooled_only(tmp_path, tools):
    path = write_drive_set(str(tmp_path / "set.yaml"), held_out=[("town", 101, "vlp32")],
                           sealed=[("village", 102, "hdl64")])
    held = run_held_out(["--drives", path, "--out", str(tmp_path / "held")])
    assert held.returncode == 0, held.stderr
    r = run_held_out(["--drives", path, "--split", "sealed", "--out", str(tmp_path / "sealed"),
                      "--work", str(tmp_path / "held")])
    assert r.returncode == 0, r.stderr
    result = json.load(open(tmp_path / "sealed" / "metrics.json"))
    assert result["split"] == "sealed"
    assert [d["name"] for d in result["drives"]] == ["village_102_hdl64"], "the sealed split, not the held-out one"
    for profile, v in result["variants"].items():
        assert set(v) == {"pooled"}, f"{profile}: no per-drive scores of a sealed drive"
        assert v["pooled"]["movers.all.seen"] >= 0
    named = [line for line in r.stdout.splitlines() if "village_102" in line]
    assert all(line.startswith("held_out: simulated ") for line in named), "no per-drive score printed either"
    held_result = json.load(open(tmp_path / "held" / "metrics.json"))
    assert held_result["split"] == "held_out" and "drives" in held_result["variants"]["default"]


def test_a_drive_set_without_sealed_drives_is_a_one_line_error(tmp_path):
    path = write_drive_set(str(tmp_path / "set.yaml"))
    r = run_held_out(["--drives", path, "--split", "sealed", "--out", str(tmp_path / "out")])
    assert r.returncode != 0
    assert "no sealed drives" in r.stderr and len(r.stderr.strip().splitlines()) == 1

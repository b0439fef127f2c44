"""The evaluate tool on bags missing what it scores: it says so instead of printing zeros as results."""
import os
import subprocess

import pytest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
BIN = os.environ.get("MAF_BIN") or os.path.join(ROOT, "build", "devel", "lib", "map_aided_fusion")


@pytest.fixture(scope="module")
def sim_bag(tmp_path_factory):
    for tool in ("simulate", "evaluate"):
        if not os.access(os.path.join(BIN, tool), os.X_OK):
            pytest.fail(f"build the package first: missing {tool}")
    d = tmp_path_factory.mktemp("evaluate")
    bag = d / "short.bag"
    r = subprocess.run([os.path.join(BIN, "simulate"), "--scenario", os.path.join(ROOT, "scenarios", "default.yaml"),
                        "--out", str(bag), "--duration", "2", "--quiet"], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    return d, bag


def test_a_simulator_bag_without_objects_is_scored_per_cell_and_says_objects_are_not(sim_bag):
    import rosbag
    d, bag = sim_bag
    stripped = d / "no_objects.bag"
    with rosbag.Bag(str(bag)) as src, rosbag.Bag(str(stripped), "w") as dst:
        for topic, msg, t in src.read_messages():
            if topic != "/ground_truth/objects":
                dst.write(topic, msg, t)
    out = d / "out_stripped"
    r = subprocess.run([os.path.join(BIN, "evaluate"), "--bag", str(stripped), "--out", str(out), "--no-ablations",
                        "--only", "default", "--quiet"], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    assert "no /ground_truth/objects" in r.stderr, r.stderr
    md = (out / "metrics.md").read_text()
    assert "**Objects not scored**" in md
    assert "objects_scored" in (out / "metrics.json").read_text()
    # With the objects, nothing of the kind is said.
    out2 = d / "out_full"
    r = subprocess.run([os.path.join(BIN, "evaluate"), "--bag", str(bag), "--out", str(out2), "--no-ablations",
                        "--only", "default", "--quiet"], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    assert "no /ground_truth/objects" not in r.stderr
    assert "Objects not scored" not in (out2 / "metrics.md").read_text()

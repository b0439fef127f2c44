"""Progress lines are rewritten in place only on a terminal: a tool whose stderr is a file or a pipe (a log, CI)
writes no carriage return (kitti_to_bag once filled logs with "1/154 frames2/154 frames...")."""
import os
import struct
import subprocess

import pytest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
BIN = os.environ.get("MAF_BIN") or os.path.join(ROOT, "build", "devel", "lib", "map_aided_fusion")


def tool(name):
    path = os.path.join(BIN, name)
    if not os.access(path, os.X_OK):
        pytest.fail(f"build the package first: missing {name}")
    return path


def run(args):
    r = subprocess.run(args, capture_output=True, timeout=600)
    assert r.returncode == 0, r.stderr.decode(errors="replace")
    return r.stderr


def kitti_sequence(d):
    """Three sweeps of a few points in the KITTI odometry layout (as test/dataset/test_kitti.cpp writes it)."""
    (d / "velodyne").mkdir()
    (d / "calib.txt").write_text("P0: 1 0 0 0 0 1 0 0 0 0 1 0\nTr: 0 -1 0 0.1 0 0 -1 -0.2 1 0 0 -0.3\n")
    (d / "times.txt").write_text("0.0\n0.1\n0.2\n")
    (d / "poses.txt").write_text("".join(f"1 0 0 0 0 1 0 0 0 0 1 {k}\n" for k in range(3)))
    points = [(5, 0, -1.7, 0.1), (6, 1, 0, 0.2), (7, -1, 0.5, 0.3), (8, 2, 1, 0.4)]
    for k in range(3):
        (d / "velodyne" / f"{k:06d}.bin").write_bytes(b"".join(struct.pack("<4f", *p) for p in points))


def test_no_carriage_return_when_stderr_is_not_a_terminal(tmp_path):
    bag = tmp_path / "drive.bag"
    err = run([tool("simulate"), "--scenario", os.path.join(ROOT, "scenarios", "default.yaml"), "--out", str(bag),
               "--duration", "1"])
    assert b"\r" not in err and b"wrote" in err
    err = run([tool("evaluate"), "--bag", str(bag), "--out", str(tmp_path / "out"), "--no-ablations", "--only",
               "default"])
    assert b"\r" not in err
    seq = tmp_path / "kitti"
    seq.mkdir()
    kitti_sequence(seq)
    r = subprocess.run([tool("kitti_to_bag"), "--sequence", str(seq), "--out", str(tmp_path / "kitti.bag")],
                       capture_output=True, timeout=120)
    assert r.returncode == 0, r.stderr.decode(errors="replace")
    assert b"\r" not in r.stderr and b"\r" not in r.stdout and b"wrote" in r.stdout

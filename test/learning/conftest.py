"""Shared fixtures of the learning tests: the package's executables and short drive sets."""
import os
import subprocess
import sys

import pytest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "learning"))

TUNE = os.path.join(ROOT, "learning", "tune")


def bin_dir():
    return os.environ.get("MAF_BIN") or os.path.join(ROOT, "build", "devel", "lib", "map_aided_fusion")


@pytest.fixture(scope="session")
def tools():
    d = bin_dir()
    paths = {n: os.path.join(d, n) for n in ("simulate", "evaluate", "kitti_to_bag")}
    missing = [p for p in paths.values() if not os.access(p, os.X_OK)]
    if missing:
        pytest.fail(f"build the package first: missing {', '.join(missing)}")
    return paths


def write_drive_set(path, duration=3.0, training=None, held_out=None, sealed=None):
    training = training or [("town", 1, "ibeo4"), ("village", 1, "ibeo4")]
    held_out = held_out or [("town", 101, "ibeo4")]
    with open(path, "w") as f:
        f.write(f"duration: {duration}\ntraining:\n")
        for t, s, p in training:
            f.write(f"  - {{template: {t}, seed: {s}, preset: {p}}}\n")
        f.write("held_out:\n")
        for t, s, p in held_out:
            f.write(f"  - {{template: {t}, seed: {s}, preset: {p}}}\n")
        if sealed:
            f.write("sealed:\n")
            for t, s, p in sealed:
                f.write(f"  - {{template: {t}, seed: {s}, preset: {p}}}\n")
    return path


def run_tune(args, timeout=600, env_extra=None):
    env = dict(os.environ, MAF_BIN=bin_dir(), PYTHONDONTWRITEBYTECODE="1")
    env.update(env_extra or {})
    return subprocess.run([sys.executable, TUNE] + args, capture_output=True, text=True, timeout=timeout, env=env)

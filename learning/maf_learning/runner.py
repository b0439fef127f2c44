"""Drives as bags, and `evaluate` runs of a configuration directory on them (the ROS-free offline pipeline)."""
import hashlib
import json
import os
import shutil
import subprocess
import tempfile

import yaml

from . import drives as drv
from .drives import PACKAGE_ROOT

KITTI_DIR = os.path.normpath(os.path.join(PACKAGE_ROOT, "..", "shared", "data", "lidar", "kitti_00"))


class EvaluationError(RuntimeError):
    """evaluate (or simulate) failed or timed out on a drive; the message says which and why."""


def tool(name):
    """The path of one of the package's executables (MAF_BIN, then build/, then devel or install spaces)."""
    candidates = []
    if os.environ.get("MAF_BIN"):
        candidates.append(os.path.join(os.environ["MAF_BIN"], name))
    candidates.append(os.path.join(PACKAGE_ROOT, "build", "devel", "lib", "map_aided_fusion", name))
    here = os.path.dirname(os.path.realpath(__file__))
    candidates.append(os.path.join(here, "..", name))
    for c in candidates:
        if os.path.isfile(c) and os.access(c, os.X_OK):
            return os.path.abspath(c)
    raise EvaluationError(f"cannot find the '{name}' executable (set MAF_BIN to the folder holding it)")


class Drive:
    """One generated drive: its scenario, its bag (simulated once, cached by content) and how to score it."""

    def __init__(self, spec, work_dir, road_maps):
        template = drv.load_template(spec["template"])
        if template["map_path"] not in road_maps:
            road_maps[template["map_path"]] = drv.RoadMap(template["map_path"], template["map_origin"])
        self.scenario = drv.generate(template, spec, road_maps[template["map_path"]])
        self.name = self.scenario["name"]
        self.template = template
        self.preset = self.scenario["lidar"]["preset"]
        self.pose_covariance = "localisation_error" in self.scenario
        text = yaml.safe_dump(self.scenario, sort_keys=True)
        digest = hashlib.sha1(text.encode()).hexdigest()[:12]
        self.dir = os.path.join(work_dir, "drives")
        self.yaml = os.path.join(self.dir, f"{self.name}.yaml")
        self.bag = os.path.join(self.dir, f"{self.name}-{digest}.bag")

    def prepare(self, simulate, timeout=900):
        """Simulates the bag unless a bag of the same scenario, newer than the simulator, exists (written whole:
        .partial renamed)."""
        os.makedirs(self.dir, exist_ok=True)
        drv.write_scenario(self.scenario, self.yaml)
        if os.path.isfile(self.bag) and os.path.getmtime(self.bag) >= os.path.getmtime(simulate):
            return False
        partial = self.bag + ".partial.bag"
        try:
            r = subprocess.run([simulate, "--scenario", self.yaml, "--out", partial, "--quiet"], capture_output=True,
                               text=True, timeout=timeout)
        except subprocess.TimeoutExpired:
            raise EvaluationError(f"simulate timed out after {timeout} s on {self.name}")
        if r.returncode != 0:
            raise EvaluationError(f"simulate failed on {self.name}: {_last_line(r.stderr)}")
        os.replace(partial, self.bag)
        return True

    def sensor_config(self, config_dir, name):
        """The sensor's file `name` (scan_grid.yaml, fusion.yaml): config_dir/ibeo/ for the 4-layer IBEO when the
        directory has it, else config_dir/."""
        ibeo = os.path.join(config_dir, "ibeo", name)
        if self.preset == "ibeo4" and os.path.isfile(ibeo):
            return ibeo
        return os.path.join(config_dir, name)

    def evaluate(self, evaluate, config_dir, variant="default", timeout=600):
        """metrics.json's scores of `variant` (default: the configured method of config_dir; paper: the paper's)."""
        extra = ["--map", self.template["map_path"], "--origin", ",".join(str(v) for v in self.template["map_origin"])]
        if self.pose_covariance:
            extra += ["--pose-covariance-topic", "/localisation/pose"]
        return run_evaluate(evaluate, self.bag, config_dir, self.sensor_config(config_dir, "scan_grid.yaml"), variant,
                            self.name, timeout, extra, fusion_config=self.sensor_config(config_dir, "fusion.yaml"))


def _last_line(text):
    lines = [ln.strip() for ln in (text or "").splitlines() if ln.strip()]
    return lines[-1] if lines else "no message"


def run_evaluate(evaluate, bag, config_dir, scan_grid_config, variant, what, timeout, extra=(), fusion_config=None):
    """`evaluate --only variant` of config_dir on bag (in a temporary folder): the variant's metrics.json scores.
    fusion_config: the fusion file (default config_dir/fusion.yaml)."""
    out_dir = tempfile.mkdtemp(prefix="maf_eval_")
    fusion_config = fusion_config or os.path.join(config_dir, "fusion.yaml")
    cmd = [evaluate, "--bag", bag, "--out", out_dir, "--fusion-config", fusion_config,
           "--scan-grid-config", scan_grid_config, "--prior-config", os.path.join(config_dir, "prior_grid.yaml"),
           "--only", variant, "--no-ablations", "--quiet", *extra]
    try:
        try:
            r = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
        except subprocess.TimeoutExpired:
            raise EvaluationError(f"evaluate timed out after {timeout} s on {what}")
        if r.returncode != 0:
            raise EvaluationError(f"evaluate failed on {what} (exit {r.returncode}): {_last_line(r.stderr)}")
        with open(os.path.join(out_dir, "metrics.json")) as f:
            return json.load(f)["variants"][variant]
    except (OSError, ValueError, KeyError) as e:
        raise EvaluationError(f"evaluate wrote no scores of '{variant}' for {what}: {e}")
    finally:
        shutil.rmtree(out_dir, ignore_errors=True)


def kitti_bag(work_dir, kitti_to_bag, source=KITTI_DIR):
    """The real KITTI 00 frames as a labelled bag (converted once), or None without ../shared/data."""
    if not os.path.isdir(os.path.join(source, "velodyne")):
        return None
    bag = os.path.join(work_dir, "kitti_00.bag")
    if not os.path.isfile(bag):
        os.makedirs(work_dir, exist_ok=True)
        r = subprocess.run([kitti_to_bag, "--sequence", source, "--out", bag], capture_output=True, text=True,
                           timeout=600)
        if r.returncode != 0:
            raise EvaluationError(f"kitti_to_bag failed: {_last_line(r.stderr)}")
    return bag


def evaluate_kitti(evaluate, bag, config_dir, variant="default", timeout=600):
    """The labelled-point summary of `variant` on the KITTI bag (no map: the sequence has none)."""
    return run_evaluate(evaluate, bag, config_dir, os.path.join(config_dir, "scan_grid.yaml"), variant,
                        "the KITTI frames", timeout)

"""The held-out drives of a drive set scored with fixed profiles (no study): each drive's `evaluate` scores and the
scores pooled over the drives, in the keys of `evaluate`'s metrics.json so that the same tables read both."""
import concurrent.futures
import json
import os

from . import drives as drv
from . import objective as obj
from . import runner

PROFILES = ("default", "paper")  # evaluate's variants: the configured method, the paper's exact method


def as_metrics(pooled):
    """A pooled record (objective.pool) in the keys of one drive's metrics.json variant."""
    mv, tr = pooled["movers"], pooled["tracks"]
    out = {f"{name}.iou": pooled[f"iou_{obj.SHORT[name]}"] for name in obj.CLASSES}
    out.update({
        "scans": pooled["scans"],
        "moving.precision": pooled["v_precision"],
        "moving.recall": pooled["v_recall"],
        "moving.trail_cells_per_scan": pooled["trail"],
        "objects.stopped.called_moving_rate": pooled["stopped_moving"],
        "movers.all.seen": mv["seen"],
        "movers.all.detected_within_0_5s": mv["within_0_5s"],
        "movers.all.detected_within_1s": mv["within_1s"],
        "movers.all.never_v": mv["never"],
        "movers.all.median_delay_s": mv["median_delay_s"],
        "movers.all.mean_v_share": mv["mean_v_share"],
        "movers.all.s_share": mv["s_share"],
    })
    if tr["drives"]:
        out.update({"tracks.mota": tr["mota"], "tracks.velocity_rmse_mps": tr["velocity_rmse_mps"],
                    "tracks.velocity_pairs": tr["velocity_pairs"], "tracks.objects": tr["objects"]})
    return out


SPLITS = ("held_out", "sealed")  # the drive set's splits this scores; sealed: pooled only


def score(drive_set, work, config, profiles=PROFILES, jobs=1, simulate=None, evaluate=None, timeout=600.0,
          log=print, split="held_out"):
    """Simulates (once, cached under work/drives) and evaluates every drive of drive_set's split (held_out or
    sealed) with each profile. Returns {"drive_set", "split", "drives": [{name, template, seed, preset}], "variants":
    {profile: {"pooled": metrics, "drives": {name: metrics}}}}; for the sealed split "drives" of each variant is
    left out: those drives are looked at pooled only. Raises runner.EvaluationError naming the drive that failed."""
    if split not in SPLITS:
        raise runner.EvaluationError(f"unknown split '{split}' ({', '.join(SPLITS)})")
    simulate = simulate or runner.tool("simulate")
    evaluate = evaluate or runner.tool("evaluate")
    spec = drv.load_drive_set(drive_set)
    road_maps = {}
    held = [runner.Drive(s, work, road_maps) for s in spec[split]]
    if not held:
        raise runner.EvaluationError(f"{drive_set} has no {split.replace('_', '-')} drives")
    for d in held:
        if d.prepare(simulate, timeout):
            log(f"held_out: simulated {d.name} -> {d.bag}")
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
        futures = {(p, d.name): pool.submit(d.evaluate, evaluate, config, p, timeout) for p in profiles for d in held}
        results = {key: f.result() for key, f in futures.items()}
    variants = {}
    for p in profiles:
        per_drive = {d.name: results[(p, d.name)] for d in held}
        variants[p] = {"pooled": as_metrics(obj.pool(list(per_drive.values())))}
        if split != "sealed":
            variants[p]["drives"] = per_drive
    return {"drive_set": os.path.abspath(drive_set), "split": split,
            "drives": [{"name": d.name, "template": d.template["name"], "seed": d.scenario["seed"],
                        "preset": d.preset} for d in held],
            "variants": variants}


def write(result, out_dir):
    """out_dir/metrics.json."""
    os.makedirs(out_dir, exist_ok=True)
    path = os.path.join(out_dir, "metrics.json")
    with open(path, "w") as f:
        json.dump(result, f, indent=1, sort_keys=True)
    return path

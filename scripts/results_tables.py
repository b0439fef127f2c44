#!/usr/bin/env python3
"""Results tables from the metrics.json files `evaluate` writes (scripts/demo calls it).

    results_tables.py OUT [--doc DOC_DIR --readme README.md]

Writes OUT/results.md (every table) and OUT/results_summary.md (the README's table: default against paper on the
simulator, the labelled real sequences pooled (OUT/real/NAME), KITTI tracking and the held-out drives, OUT/held_out
from learning/held_out), and OUT/real/pooled.json (the real sequences' counts summed per variant). With --doc and
--readme, and only when every dataset was evaluated, also
DOC_DIR/results.md, the README's block between the `results:begin` and `results:end` markers and (--figure) the
picture under DOC_DIR/images/: the documentation then shows what this run measured, never a typed figure.
"""
import argparse
import json
import os
import shutil
import sys

BEGIN = "<!-- results:begin (scripts/demo writes this table; do not edit) -->"
END = "<!-- results:end -->"

SIMULATOR = "default scenario (simulator, 600 scans, town map)"
REAL = "Labelled real sequences (KITTI 00, SemanticKITTI 02, 06, 09, 10; 10 sweeps each, every point labelled, no map)"
# The labelled real sequences scripts/demo scores (out/real/NAME): name, title; KITTI 00 twice (two sources of pose).
REAL_SEQUENCES = [
    ("kitti_00", "KITTI 00, GPS/INS poses"),
    ("kitti_00_suma", "KITTI 00, SemanticKITTI poses"),
    ("semantic_kitti_02", "SemanticKITTI 02"),
    ("semantic_kitti_06", "SemanticKITTI 06"),
    ("semantic_kitti_09", "SemanticKITTI 09 (nothing moves)"),
    ("semantic_kitti_10", "SemanticKITTI 10"),
]
# The pooled real set: each drive once (KITTI 00 with its GPS/INS poses).
REAL_POOLED = ("kitti_00", "semantic_kitti_02", "semantic_kitti_06", "semantic_kitti_09", "semantic_kitti_10")
TRACKING = "KITTI tracking 0000 (real, 154 sweeps, 5 movers, no map)"
HELD_OUT = "Held-out drives (simulator, `learning/drives.yaml`)"


def read_json(path):
    if not os.path.exists(path):
        return None
    with open(path) as f:
        return json.load(f)


def load(path):
    """The variants of an `evaluate` metrics.json, or None when it is absent."""
    data = read_json(path)
    return data["variants"] if data else None


def num(v, digits=3):
    if v is None:
        return "–"
    if isinstance(v, str):
        return v
    return f"{v:.{digits}f}"


def frac(v, key_num, key_den):
    a, b = v.get(key_num), v.get(key_den)
    if a is None or b is None:
        return "–"
    return f"{int(a)}/{int(b)}"


# (column title, function of one variant's metrics)
SIM_COLUMNS = [
    ("IoU F", lambda v: num(v.get("free.iou"))),
    ("IoU C", lambda v: num(v.get("building.iou"))),
    ("IoU N", lambda v: num(v.get("infrastructure.iou"))),
    ("IoU S", lambda v: num(v.get("stopped.iou"))),
    ("IoU V", lambda v: num(v.get("moving.iou"))),
    ("V precision", lambda v: num(v.get("moving.precision"))),
    ("V recall", lambda v: num(v.get("moving.recall"))),
    ("movers V ≤ 0.5 s", lambda v: frac(v, "movers.all.detected_within_0_5s", "movers.all.seen")),
    ("movers V ≤ 1 s", lambda v: frac(v, "movers.all.detected_within_1s", "movers.all.seen")),
    ("stopped called moving", lambda v: num(v.get("objects.stopped.called_moving_rate"))),
    ("V trail (cells/scan)", lambda v: num(v.get("moving.trail_cells_per_scan"), 1)),
    ("MOTA", lambda v: num(v.get("tracks.mota"), 2)),
    ("velocity RMSE (m/s)", lambda v: num(v.get("tracks.velocity_rmse_mps"), 2)),
]
def counted(v, num_key, den_key, digits=3, scale=1.0):
    """A ratio of two of `evaluate`'s counts ("counts.*"), "–" when there is nothing to count."""
    c = v.get("counts", v)
    a, b = c.get(num_key), c.get(den_key)
    if a is None or b is None or b <= 0:
        return "–"
    return f"{scale * a / b:.{digits}f}"


def iou(v):
    c = v.get("counts", v)
    tp, fp, fn = (c.get(k) for k in ("moving_tp", "moving_fp", "moving_fn"))
    if tp is None or tp + fp + fn <= 0:
        return "–"
    return f"{tp / (tp + fp + fn):.3f}"


def f1(v):
    c = v.get("counts", v)
    tp, fp, fn = (c.get(k) for k in ("segmentation_tp", "segmentation_fp", "segmentation_fn"))
    if tp is None or 2 * tp + fp + fn <= 0:
        return "–"
    return f"{2 * tp / (2 * tp + fp + fn):.3f}"


# Columns of the labelled real sequences; each a ratio of counts, so that sequences pool by summing them.
REAL_COLUMNS = [
    ("false V / labelled sweep", lambda v: counted(v, "false_v", "labelled_sweeps", 1)),
    ("movers' cells V", lambda v: counted(v, "mover_v_cells", "mover_cells", 2)),
    ("moving IoU (points)", iou),
    ("ground cells F", lambda v: counted(v, "ground_f_cells", "ground_cells")),
    ("ground cells F, settled", lambda v: counted(v, "ground_f_cells_settled", "ground_cells_settled")),
    ("obstacle cells F (%)", lambda v: counted(v, "obstacle_f_cells", "obstacle_cells", 3, 100.0)),
    ("obstacle cells F, vegetation left out (%)", lambda v: counted(v, "rigid_f_cells", "rigid_cells", 3, 100.0)),
    ("movers' cells S", lambda v: counted(v, "mover_s_cells", "mover_cells", 3)),
    ("ground F1 (points)", f1),
    ("ground returns called obstacle", lambda v: counted(v, "ground_as_obstacle", "ground_points")),
]


def real_counts(v):
    """The counts of one variant of a labelled real sequence's metrics.json, with the sweeps and ground points."""
    c = {k[len("counts."):]: x for k, x in v.items() if k.startswith("counts.")}
    c["labelled_sweeps"] = v.get("labelled_sweeps", 0)
    if "segmentation_tp" in c:
        c["ground_points"] = c["segmentation_tp"] + c["segmentation_fn"]
    return c


def pool_real(real, names=REAL_POOLED):
    """Per variant present in every named sequence, the sum of their counts: {variant: {"counts": {...}}}."""
    present = [real[n] for n in names if n in real]
    if not present:
        return {}
    variants = [v for v in present[0] if all(v in r for r in present)]
    pooled = {}
    for v in variants:
        total = {}
        for r in present:
            for k, x in real_counts(r[v]).items():
                total[k] = total.get(k, 0) + x
        pooled[v] = {"counts": total, "sequences": len(present)}
    return pooled


def real_table(real, pooled):
    """Each labelled real sequence and the pool, default, paper and live rows, in REAL_COLUMNS."""
    lines = ["| sequence | variant | " + " | ".join(c for c, _ in REAL_COLUMNS) + " |",
             "| --- | --- | " + " | ".join("---:" for _ in REAL_COLUMNS) + " |"]
    for name, title in REAL_SEQUENCES:
        for variant in ("default", "live_default", "paper"):
            if name in real and variant in real[name]:
                c = {"counts": real_counts(real[name][variant])}
                lines.append(f"| {title} | {variant} | " + " | ".join(f(c) for _, f in REAL_COLUMNS) + " |")
    for variant in ("default", "live_default", "paper"):
        if variant in pooled:
            lines.append(f"| **pooled** ({pooled[variant]['sequences']} drives) | {variant} | " +
                         " | ".join(f(pooled[variant]) for _, f in REAL_COLUMNS) + " |")
    return "\n".join(lines) + "\n"


# Labelled-ground cells not decided F, by what the sweep's scan gave them (`evaluate`, eval/scan_evidence.hpp).
GROUND_LOSS_COLUMNS = [
    ("decided F", lambda v: counted(v, "ground_f_cells", "ground_cells")),
    ("not F: scan free", lambda v: counted(v, "ground_not_f_free", "ground_cells_with_evidence")),
    ("not F: scan occupied", lambda v: counted(v, "ground_not_f_occupied", "ground_cells_with_evidence")),
    ("not F: free cleared near an obstacle", lambda v: counted(v, "ground_not_f_cleared", "ground_cells_with_evidence")),
    ("not F: beyond the sector's free space", lambda v: counted(v, "ground_not_f_unreached",
                                                                "ground_cells_with_evidence")),
    ("not F: ambiguous return", lambda v: counted(v, "ground_not_f_ambiguous", "ground_cells_with_evidence")),
]
# The variants whose ground handling differs from the default's, in the pooled rows of that table.
GROUND_LOSS_VARIANTS = ("default", "paper", "default_with_ground_cells_free", "default_without_obstacle_clearance",
                        "default_without_ambiguous_unknown", "default_without_ground_consensus",
                        "default_with_ground_zones")


def ground_loss_table(real, pooled):
    """Per labelled real sequence (default, paper) and pooled, the labelled-ground cells decided F and why the others
    are not: what the sweep's scan gave them."""
    lines = ["| sequence | variant | " + " | ".join(c for c, _ in GROUND_LOSS_COLUMNS) + " |",
             "| --- | --- | " + " | ".join("---:" for _ in GROUND_LOSS_COLUMNS) + " |"]
    for name, title in REAL_SEQUENCES:
        for variant in ("default", "paper"):
            if name in real and variant in real[name]:
                c = {"counts": real_counts(real[name][variant])}
                lines.append(f"| {title} | {variant} | " + " | ".join(f(c) for _, f in GROUND_LOSS_COLUMNS) + " |")
    for variant in GROUND_LOSS_VARIANTS:
        if variant in pooled:
            lines.append(f"| **pooled** ({pooled[variant]['sequences']} drives) | {variant} | " +
                         " | ".join(f(pooled[variant]) for _, f in GROUND_LOSS_COLUMNS) + " |")
    return "\n".join(lines) + "\n"


def real_variants_table(pooled):
    """Every variant (the default, each step off, the paper and its ablations) on the pooled real sequences."""
    lines = ["| variant | " + " | ".join(c for c, _ in REAL_COLUMNS) + " |",
             "| --- | " + " | ".join("---:" for _ in REAL_COLUMNS) + " |"]
    lines += [f"| {n} | " + " | ".join(f(v) for _, f in REAL_COLUMNS) + " |" for n, v in pooled.items()]
    return "\n".join(lines) + "\n"


KITTI_COLUMNS = [
    ("V cells / sweep", lambda v: num(v.get("v_cells_per_sweep"), 1)),
    ("false V / labelled sweep", lambda v: num(v.get("false_v_per_labelled_sweep"), 1)),
    ("V on static points / labelled sweep", lambda v: num(v.get("v_on_static_per_labelled_sweep"), 1)),
    ("motorcyclist cells V", lambda v: num(v.get("mover_cells_v_share"), 2)),
    ("motorcyclist V share from its 3rd sweep", lambda v: num(v.get("mover_min_v_share_from_third_sweep"), 2)),
    ("first V (s)", lambda v: "never" if (v.get("mover_first_v_delay_s") or -1) < 0
     else num(v.get("mover_first_v_delay_s"), 2)),
]
TRACKING_COLUMNS = [
    ("movers V ≤ 0.5 s", lambda v: frac(v, "movers.all.detected_within_0_5s", "movers.all.seen")),
    ("movers V ≤ 1 s", lambda v: frac(v, "movers.all.detected_within_1s", "movers.all.seen")),
    ("movers' mean V share", lambda v: num(v.get("movers.all.mean_v_share"), 2)),
    ("movers' cells S", lambda v: num(v.get("movers.all.s_share"), 3)),
    ("parked V share", lambda v: num(v.get("parked.all.v_share"), 3)),
    ("false V / scan", lambda v: num(v.get("movers.false_v_per_scan"), 2)),
    ("MOTA", lambda v: num(v.get("tracks.mota"), 2)),
    ("velocity median error (m/s)", lambda v: num(v.get("tracks.velocity_median_mps"), 2)),
]


def table(variants, columns, names=None):
    names = [n for n in (names or variants.keys()) if n in variants]
    head = "| variant | " + " | ".join(c for c, _ in columns) + " |\n"
    rule = "| --- | " + " | ".join("---:" for _ in columns) + " |\n"
    rows = "".join("| " + n + " | " + " | ".join(f(variants[n]) for _, f in columns) + " |\n" for n in names)
    return head + rule + rows


def mover_tracks_table(variants, profile="default"):
    """Per judged mover, the tracks of one profile (metrics.json's tracks_objects): its identity share and velocity
    errors, the movers that make most of the squared velocity error first; "" without tracks."""
    v = (variants or {}).get(profile)
    if not v or not v.get("tracks_objects"):
        return ""
    kinds = {o["id"]: o["kind"] for o in v.get("movers_objects", {}).get("objects", [])}
    rows = sorted(v["tracks_objects"], key=lambda r: (-(r["velocity_error_share"] or 0.0), r["id"]))
    lines = [f"\nPer mover, the tracks of `{profile}` (doc/evaluation.md, \"Tracks: CLEAR-MOT\"); share: of the "
             "squared velocity error of all movers, so the largest shares are where the velocity RMSE comes from.\n",
             "| mover | kind | sweeps judged | tracked as moving | identity share | velocity pairs | "
             "velocity RMSE (m/s) | velocity median (m/s) | share of the squared velocity error |",
             "| ---: | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"]
    for r in rows:
        lines.append(f"| {r['id']} | {kinds.get(r['id'], '?')} | {r['frames']} | {r['tracked_frames']} | "
                     f"{num(r['identity_share'], 2)} | {r['velocity_pairs']} | {num(r['velocity_rmse_mps'], 2)} | "
                     f"{num(r['velocity_median_mps'], 2)} | {num(r['velocity_error_share'], 2)} |")
    return "\n".join(lines) + "\n"


def held_out_table(held, sealed=None):
    """Each held-out drive, then the drives pooled, for each profile, in the simulator's columns; then the sealed
    drives pooled (their scores exist only pooled)."""
    presets = {d["name"]: d["preset"] for d in held["drives"]}
    lines = ["| drive | profile | " + " | ".join(c for c, _ in SIM_COLUMNS) + " |",
             "| --- | --- | " + " | ".join("---:" for _ in SIM_COLUMNS) + " |"]
    for profile, v in held["variants"].items():
        rows = [(f"`{n}` ({presets.get(n, '?')})", m) for n, m in v["drives"].items()]
        rows.append((f"pooled ({len(v['drives'])} drives)", v["pooled"]))
        lines += [f"| {name} | {profile} | " + " | ".join(f(m) for _, f in SIM_COLUMNS) + " |" for name, m in rows]
    if sealed:
        for profile, v in sealed["variants"].items():
            name = f"**sealed**, pooled ({len(sealed['drives'])} drives)"
            lines.append(f"| {name} | {profile} | " + " | ".join(f(v["pooled"]) for _, f in SIM_COLUMNS) + " |")
    return ("The held-out split of `learning/drives.yaml` (never used for learning), written by `learning/held_out`: "
            "each drive, then the drives pooled (confusion matrices, movers and CLEAR-MOT counts summed over the "
            "drives, not averaged; `learning/maf_learning/objective.py`). Some held-out drives were looked at while "
            "steps were designed; the sealed split (fresh seeds, `learning/held_out --split sealed`) was frozen "
            "before the tracker's redesign and is written pooled only.\n\n" + "\n".join(lines) + "\n")


def summary(sim, real_pooled, tracking, held=None, sealed=None):
    """One table: each dataset's key figures for the default and the paper profiles."""
    lines = ["| data | figure | default | paper |", "| --- | --- | ---: | ---: |"]

    def add(data, variants, title, f):
        if variants and "default" in variants and "paper" in variants:
            lines.append(f"| {data} | {title} | {f(variants['default'])} | {f(variants['paper'])} |")

    cols = dict(SIM_COLUMNS)
    for title in ("IoU F", "IoU C", "V precision", "V recall", "movers V ≤ 1 s", "V trail (cells/scan)", "MOTA",
                  "velocity RMSE (m/s)"):
        add("simulator", sim, title, cols[title])
    if held:
        pooled = {profile: v["pooled"] for profile, v in held["variants"].items()}
        for title in ("V precision", "V recall", "movers V ≤ 1 s", "MOTA", "velocity RMSE (m/s)"):
            add("held-out drives, pooled", pooled, title, cols[title])
    if sealed:
        pooled = {profile: v["pooled"] for profile, v in sealed["variants"].items()}
        for title in ("V precision", "V recall", "movers V ≤ 1 s", "MOTA", "velocity RMSE (m/s)"):
            add("sealed drives, pooled", pooled, title, cols[title])
    if real_pooled:
        cols = dict(REAL_COLUMNS)
        data = f"real sequences, pooled ({next(iter(real_pooled.values()))['sequences']})"
        for title in ("false V / labelled sweep", "movers' cells V", "moving IoU (points)", "ground cells F",
                      "obstacle cells F (%)", "obstacle cells F, vegetation left out (%)", "ground F1 (points)"):
            add(data, real_pooled, title, cols[title])
    cols = dict(TRACKING_COLUMNS)
    for title in ("movers V ≤ 1 s", "movers' mean V share", "movers' cells S", "false V / scan", "MOTA"):
        add("KITTI tracking", tracking, title, cols[title])
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("--doc")
    ap.add_argument("--readme")
    ap.add_argument("--figure", help="a picture to copy to DOC_DIR/images/ with the tables (figure2.png)")
    a = ap.parse_args()
    sim = load(os.path.join(a.out, "metrics.json"))
    real = {n: v for n, v in ((n, load(os.path.join(a.out, "real", n, "metrics.json"))) for n, _ in REAL_SEQUENCES)
            if v}
    real_pooled = pool_real(real)
    if real_pooled:
        with open(os.path.join(a.out, "real", "pooled.json"), "w") as f:
            json.dump({"sequences": [n for n in REAL_POOLED if n in real], "variants": real_pooled}, f, indent=1)
    tracking = load(os.path.join(a.out, "kitti_tracking", "metrics.json"))
    held = read_json(os.path.join(a.out, "held_out", "metrics.json"))  # learning/held_out's
    sealed = read_json(os.path.join(a.out, "sealed", "metrics.json"))  # learning/held_out --split sealed
    if sim is None:
        sys.exit(f"results_tables.py: {a.out}/metrics.json is missing (run scripts/demo)")

    parts = ["# Results\n\n",
             "Written by `scripts/demo` from the `metrics.json` files of `evaluate` (do not edit). "
             "`default` is `config/`, `paper` is `config/paper/` (the paper's exact method), `live` the nodelets "
             "replaying the bag; `default_without_<step>` is the default with one added step off (doc/steps.md), "
             "`dempster`, `yager`, `single_rate`, `no_counter` are ablations of the paper. "
             "doc/evaluation.md defines every figure.\n\n",
             "## Summary\n\n", summary(sim, real_pooled, tracking, held, sealed),
             f"\n## {SIMULATOR}\n\n", table(sim, SIM_COLUMNS), mover_tracks_table(sim)]
    if held:
        parts += [f"\n## {HELD_OUT}\n\n", held_out_table(held, sealed)]
    if real:
        parts += [f"\n## {REAL}\n\n",
                  "Scored per labelled sweep (doc/evaluation.md, \"Labelled real sweeps\"); `live_default` is the "
                  "nodelets replaying the bag. Pooled: the counts of "
                  + ", ".join(f"`{n}`" for n in REAL_POOLED) + " summed, then divided.\n\n",
                  real_table(real, real_pooled)]
        if real_pooled:
            parts += ["\nEvery variant on the pooled real sequences (a step stays on by default only where it wins "
                      "here and makes no sequence worse; doc/steps.md):\n\n", real_variants_table(real_pooled)]
            parts += ["\nLabelled-ground cells not decided F, by what the sweep's scan gave them (doc/evaluation.md, "
                      "\"Why ground is not decided F\"); with the decided ones they add up to 1:\n\n",
                      ground_loss_table(real, real_pooled)]
        if "kitti_00" in real:
            parts += ["\nKITTI 00's motorcyclist (GPS/INS poses):\n\n", table(real["kitti_00"], KITTI_COLUMNS)]
    if tracking:
        parts += [f"\n## {TRACKING}\n\n", table(tracking, TRACKING_COLUMNS),
                  mover_tracks_table(tracking)]
    lies = [(n, load(os.path.join(a.out, n, "metrics.json")))
            for n in ("pose_bias", "pose_random_walk", "map_shift", "fast_ego_10", "fast_ego_15", "sloped_road", "ibeo")]
    lies = [(n, v) for n, v in lies if v]
    if lies:
        parts.append("\n## Scenarios of a simulator that lies and of real-sensor effects\n\n")
        parts.append("`scenarios/<name>.yaml`; doc/steps.md says what each one tests.\n\n")
        parts.append("| scenario | profile | " + " | ".join(c for c, _ in SIM_COLUMNS) + " |\n"
                     "| --- | --- | " + " | ".join("---:" for _ in SIM_COLUMNS) + " |\n")
        for n, v in lies:
            for profile in ("default", "paper"):
                if profile in v:
                    parts.append(f"| `{n}` | {profile} | " + " | ".join(f(v[profile]) for _, f in SIM_COLUMNS) + " |\n")
    text = "".join(p if p.endswith("\n") else p + "\n" for p in parts if p)
    with open(os.path.join(a.out, "results.md"), "w") as f:
        f.write(text)
    with open(os.path.join(a.out, "results_summary.md"), "w") as f:
        f.write(summary(sim, real_pooled, tracking, held, sealed))
    print(f"wrote {a.out}/results.md")

    if a.doc and a.readme:
        missing = [title for name, title in REAL_SEQUENCES if name not in real]
        missing += [name for name, v in (("KITTI tracking", tracking), ("held-out drives", held),
                                         ("sealed drives", sealed)) if v is None]
        if missing:
            print(f"results_tables.py: {', '.join(missing)} not evaluated (the real ones need ../shared/data, the "
                  "held-out drives learning/held_out, the sealed ones --split sealed): doc/results.md and the README "
                  "are left as they are")
            return
        with open(os.path.join(a.doc, "results.md"), "w") as f:
            f.write(text)
        with open(a.readme) as f:
            readme = f.read()
        i, j = readme.find(BEGIN), readme.find(END)
        if i < 0 or j < i:
            sys.exit(f"results_tables.py: {a.readme} has no results markers")
        readme = readme[:i + len(BEGIN)] + "\n" + summary(sim, real_pooled, tracking, held, sealed) + readme[j:]
        with open(a.readme, "w") as f:
            f.write(readme)
        print(f"wrote {a.doc}/results.md and the README's results table")
        if a.figure:
            os.makedirs(os.path.join(a.doc, "images"), exist_ok=True)
            shutil.copyfile(a.figure, os.path.join(a.doc, "images", os.path.basename(a.figure)))


if __name__ == "__main__":
    main()

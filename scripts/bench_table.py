#!/usr/bin/env python3
"""The benchmark table of doc/performance.md from a Google Benchmark JSON file (scripts/bench writes both).

    bench_table.py BENCH.json [--doc doc/performance.md]

Prints the table; with --doc, replaces the block between the bench markers of that file.
"""
import argparse
import json
import re
import sys

BEGIN = "<!-- bench:begin (scripts/bench writes this table; do not edit) -->"
END = "<!-- bench:end -->"

DRIVE = "BM_MapGridUpdateDrive/n:{n}/threads:{t}/skip:{s}/iterations:200/real_time"

SHARES = ("skipped_share", "observed_share", "changing_share")
FIXED_POINT = "BM_ScansToFixedPoint/history:{h}/iterations:1"

# (benchmark, what it measures, reference benchmark or None[, counters shown after "what"]): the ratio is median /
# median of the reference.
ROWS = [
    ("BM_MapGridUpdate/n:200/threads:1/real_time", "the whole per-scan update, the paper's 100 m at 0.5 m (200 × 200)", None),
    ("BM_MapGridUpdate/n:200/threads:2/real_time", "the same, 2 threads", "BM_MapGridUpdate/n:200/threads:1/real_time"),
    ("BM_MapGridUpdate/n:800/threads:1/real_time", "the whole update, 160 m at 0.2 m (800 × 800)", None),
    ("BM_MapGridUpdate/n:800/threads:2/real_time", "the same, 2 threads", "BM_MapGridUpdate/n:800/threads:1/real_time"),
    ("BM_MapGridUpdateReturns/n:800/threads:2/real_time", "the update with the scan's obstacle returns (the live default)", "BM_MapGridUpdate/n:800/threads:2/real_time"),
    ("BM_UpdateBaseline/n:800/threads:2/real_time", "the bytes the update cannot avoid, streamed once", "BM_MapGridUpdate/n:800/threads:2/real_time"),
    (DRIVE.format(n=800, t=1, s=0), "the update on a realistic drive (32-beam lidar through the simulated town at 8 m/s, prior, 200 sweeps from an empty grid), 800 × 800, `skip_unchanged` off", None),
    (DRIVE.format(n=800, t=1, s=1), "the same with `skip_unchanged` (the default)", DRIVE.format(n=800, t=1, s=0), SHARES),
    (DRIVE.format(n=800, t=2, s=0), "the realistic drive, 2 threads, `skip_unchanged` off", None),
    (DRIVE.format(n=800, t=2, s=1), "the same with `skip_unchanged`", DRIVE.format(n=800, t=2, s=0), SHARES),
    (DRIVE.format(n=200, t=2, s=0), "the realistic drive, 200 × 200 at 0.5 m, 2 threads, `skip_unchanged` off", None),
    (DRIVE.format(n=200, t=2, s=1), "the same with `skip_unchanged`", DRIVE.format(n=200, t=2, s=0), SHARES),
    (FIXED_POINT.format(h=0), "a cell seen free on a mapped road, then no longer observed: the scans the step still computes before it leaves the cell bit for bit (skip_unchanged then skips it); the time is that whole history on 16 × 16 cells", None, ("scans",)),
    (FIXED_POINT.format(h=1), "the same for a cell seen occupied on a mapped road (a parked car that left)", None, ("scans",)),
    (FIXED_POINT.format(h=2), "the same for a cell seen occupied on a mapped building", None, ("scans",)),
    (FIXED_POINT.format(h=3), "the same for a cell seen free without a map", None, ("scans",)),
    ("BM_MapGridShift/threads:2/skip:0/real_time", "moving the 800 × 800 window by 25 columns and 3 rows (a recentring after 5 m): masses and ζ, 2 threads", "BM_MapGridUpdate/n:800/threads:2/real_time"),
    ("BM_MapGridShift/threads:2/skip:1/real_time", "the same with what `skip_unchanged` keeps (flags, the prior they hold for, BetP, decisions)", "BM_MapGridShift/threads:2/skip:0/real_time"),
    ("BM_FusionStep/n:800/threads:2/real_time", "the fused step alone (refine, prior, discounting, ⊛, counter, BetP)", "BM_MapGridUpdate/n:800/threads:2/real_time"),
    ("BM_StreamBaseline/n:800/threads:2/real_time", "the fused step's bytes, streamed once", "BM_FusionStep/n:800/threads:2/real_time"),
    ("BM_ProjectScan/clearance:5/threads:2/real_time", "the scan's projection with a 1 m obstacle clearance", "BM_MapGridUpdate/n:800/threads:2/real_time"),
    ("BM_ScanGrid/points:130000/threads:1/real_time", "ScanGrid of a 130k-point cloud, 800 × 800 at 0.2 m, flat ground", None),
    ("BM_ScanGrid/points:130000/threads:2/real_time", "the same, 2 threads", "BM_ScanGrid/points:130000/threads:1/real_time"),
    ("BM_ScanGridGround/points:130000/threads:1/real_time", "the same with the default ground model (`planes`, and `zones` beside it for step ground consensus)", "BM_ScanGrid/points:130000/threads:1/real_time"),
    ("BM_ScanGridGround/points:130000/threads:2/real_time", "the same, 2 threads (the zones of a ring fit at once)", "BM_ScanGridGround/points:130000/threads:1/real_time"),
    ("BM_ScanGridGroundAlone/points:130000/threads:1/real_time", "the `planes` model alone (without step ground consensus)", "BM_ScanGridGround/points:130000/threads:1/real_time"),
    ("BM_Deskew/130000", "deskewing a 130k-point sweep at 15 m/s (check and move)", "BM_ScanGrid/points:130000/threads:1/real_time"),
    ("BM_ScanGridPaper/800", "ScanGrid of an 800-point IBEO-like scan at 0.5 m", None),
    ("BM_TrackerUpdate/200", "tracker update, 200 tracks and 200 measurements, one thread", None),
    ("BM_ClusterReturns/200", "clustering 20 000 returns in 200 clusters, one thread", None),
    ("BM_TrackerScan/n:200/free_space_check:0/open_ends:0/duplicates:0", "a whole scan of tracking: 20 000 returns in 200 objects, one thread", None),
    ("BM_TrackerScan/n:200/free_space_check:1/open_ends:0/duplicates:0", "the same with the free-space check on a 100 m ScanGrid", "BM_TrackerScan/n:200/free_space_check:0/open_ends:0/duplicates:0"),
    ("BM_TrackerScan/n:200/free_space_check:1/open_ends:1/duplicates:0", "the same with step open ends too", "BM_TrackerScan/n:200/free_space_check:1/open_ends:0/duplicates:0"),
    ("BM_TrackerScan/n:200/free_space_check:1/open_ends:1/duplicates:1", "the same with step duplicates too (the default)", "BM_TrackerScan/n:200/free_space_check:1/open_ends:1/duplicates:0"),
    ("BM_TrackerClutter/clusters:200", "a whole scan of clutter (rain, birds, hedges): 200 separate clusters of 20 returns on a 1.4 m lattice, the default bounds, one thread", None, ("returns", "tracks")),
    ("BM_TrackerClutter/clusters:5000", "the same with 5,000 clusters: the bounds keep 1,000 measurements and tracks, the cost linear in the returns", "BM_TrackerClutter/clusters:200", ("returns", "tracks")),
    ("BM_SeenFree/200", "the free space of one scan the free-space check reads (margins 0.5 m and 0 m), 200 × 200 at 0.5 m, one thread", None),
    ("BM_SeenFree/800", "the same, 800 × 800 at 0.2 m (`high_resolution.test`'s ScanGrid)", None),
    ("BM_PriorFillWindow/1/0", "the PriorGrid window the fusion samples, coverage test", None),
]


def median_runs(data):
    """The median aggregate (or the single run) of each benchmark, by run name."""
    out = {}
    for b in data["benchmarks"]:
        if b.get("aggregate_name") == "median" or ("aggregate_name" not in b and b["run_type"] == "iteration"):
            out[b["run_name"] if "run_name" in b else b["name"]] = b
    return out


def medians(data):
    unit = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}
    return {k: b["real_time"] * unit[b.get("time_unit", "ns")] for k, b in median_runs(data).items()}


def table(data):
    ctx = data["context"]
    reps = max((b.get("repetitions", 1) for b in data["benchmarks"]), default=1)
    cpu = ctx.get("mhz_per_cpu")
    m = medians(data)
    runs = median_runs(data)
    lines = [f"Machine: {ctx.get('host_name', '?')}, {ctx.get('num_cpus', '?')} CPUs at {cpu} MHz "
             f"({cpu_model()}); medians of {reps} repetitions, real time, ms; the ratio is the median over its "
             f"reference's median in the same run. Written by `scripts/bench` on {ctx.get('date', '?')[:10]}.", "",
             "| benchmark | what | median (ms) | ratio | to |", "| --- | --- | ---: | ---: | --- |"]
    for name, what, ref, *counter in ROWS:
        if name not in m:
            continue
        shown = [f"{c.replace('_', ' ')} {number(runs[name][c])}" for c in (counter[0] if counter else ()) if c in runs[name]]
        if shown:
            what += "; " + ", ".join(shown)
        ratio = f"{m[name] / m[ref]:.2f}" if ref and ref in m else ""
        lines.append(f"| `{short(name)}` | {what} | {m[name]:.3f} | {ratio} | "
                     f"{'`' + short(ref) + '`' if ref and ref in m else ''} |")
    bound = skip_bound(runs)
    if bound:
        lines += ["", bound]
    return "\n".join(lines) + "\n"


def skip_bound(runs):
    """What the realistic drive would still take were the cells skip_unchanged skips free: the stages of the drive
    without it, its fused step scaled by the share of cells the drive with it computes."""
    parts = []
    for n in (800, 200):
        off, on = runs.get(DRIVE.format(n=n, t=2, s=0)), runs.get(DRIVE.format(n=n, t=2, s=1))
        stages = ("shift_ms", "project_ms", "prior_ms", "fusion_ms")
        if not off or not on or "skipped_share" not in on or any(k not in off for k in stages):
            return None
        computed = 1.0 - on["skipped_share"]
        ms = off["shift_ms"] + off["project_ms"] + off["prior_ms"] + off["fusion_ms"] * computed
        parts.append(f"{ms:.2f} ms at {n} × {n} (computing {computed:.2f} of the cells)")
    return ("Were the cells `skip_unchanged` skips free, the realistic drive with 2 threads would still take "
            + " and ".join(parts) + ": the stages of the drive without it, its fused step scaled by the share of "
            "cells the drive with it computes.")


def number(value):
    """A counter: a whole count as such, a share with two decimals."""
    return f"{value:.0f}" if value > 1.0 and value == round(value) else f"{value:.2f}"


def short(name):
    return re.sub(r"/iterations:\d+", "", name.replace("/real_time", ""))


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "unknown CPU"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("json")
    ap.add_argument("--doc")
    a = ap.parse_args()
    with open(a.json) as f:
        text = table(json.load(f))
    print(text)
    if a.doc:
        with open(a.doc) as f:
            doc = f.read()
        i, j = doc.find(BEGIN), doc.find(END)
        if i < 0 or j < i:
            sys.exit(f"bench_table.py: {a.doc} has no bench markers")
        with open(a.doc, "w") as f:
            f.write(doc[:i + len(BEGIN)] + "\n" + text + doc[j:])


if __name__ == "__main__":
    main()

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

# (benchmark, what it measures, reference benchmark or None): the ratio is median / median of the reference.
ROWS = [
    ("BM_MapGridUpdate/n:200/threads:1/real_time", "the whole per-scan update, the paper's 100 m at 0.5 m (200 × 200)", None),
    ("BM_MapGridUpdate/n:200/threads:2/real_time", "the same, 2 threads", "BM_MapGridUpdate/n:200/threads:1/real_time"),
    ("BM_MapGridUpdate/n:800/threads:1/real_time", "the whole update, 160 m at 0.2 m (800 × 800)", None),
    ("BM_MapGridUpdate/n:800/threads:2/real_time", "the same, 2 threads", "BM_MapGridUpdate/n:800/threads:1/real_time"),
    ("BM_MapGridUpdateReturns/n:800/threads:2/real_time", "the update with the scan's obstacle returns (the live default)", "BM_MapGridUpdate/n:800/threads:2/real_time"),
    ("BM_UpdateBaseline/n:800/threads:2/real_time", "the bytes the update cannot avoid, streamed once", "BM_MapGridUpdate/n:800/threads:2/real_time"),
    ("BM_FusionStep/n:800/threads:2/real_time", "the fused step alone (refine, prior, discounting, ⊛, counter, BetP)", "BM_MapGridUpdate/n:800/threads:2/real_time"),
    ("BM_StreamBaseline/n:800/threads:2/real_time", "the fused step's bytes, streamed once", "BM_FusionStep/n:800/threads:2/real_time"),
    ("BM_ProjectScan/clearance:5/threads:2/real_time", "the scan's projection with a 1 m obstacle clearance", "BM_MapGridUpdate/n:800/threads:2/real_time"),
    ("BM_ScanGrid/points:130000/threads:1/real_time", "ScanGrid of a 130k-point cloud, 800 × 800 at 0.2 m, flat ground", None),
    ("BM_ScanGrid/points:130000/threads:2/real_time", "the same, 2 threads", "BM_ScanGrid/points:130000/threads:1/real_time"),
    ("BM_ScanGridGround/points:130000/threads:1/real_time", "the same with the `planes` ground model", "BM_ScanGrid/points:130000/threads:1/real_time"),
    ("BM_Deskew/130000", "deskewing a 130k-point sweep at 15 m/s (check and move)", "BM_ScanGrid/points:130000/threads:1/real_time"),
    ("BM_ScanGridPaper/800", "ScanGrid of an 800-point IBEO-like scan at 0.5 m", None),
    ("BM_TrackerUpdate/200", "tracker update, 200 tracks and 200 measurements, one thread", None),
    ("BM_ClusterReturns/200", "clustering 20 000 returns in 200 clusters, one thread", None),
    ("BM_PriorFillWindow/1/0", "the PriorGrid window the fusion samples, coverage test", None),
]


def medians(data):
    out = {}
    for b in data["benchmarks"]:
        if b.get("aggregate_name") == "median" or ("aggregate_name" not in b and b["run_type"] == "iteration"):
            unit = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}[b.get("time_unit", "ns")]
            out[b["run_name"] if "run_name" in b else b["name"]] = b["real_time"] * unit
    return out


def table(data):
    ctx = data["context"]
    reps = max((b.get("repetitions", 1) for b in data["benchmarks"]), default=1)
    cpu = ctx.get("mhz_per_cpu")
    m = medians(data)
    lines = [f"Machine: {ctx.get('host_name', '?')}, {ctx.get('num_cpus', '?')} CPUs at {cpu} MHz "
             f"({cpu_model()}); medians of {reps} repetitions, real time, ms; the ratio is the median over its "
             f"reference's median in the same run. Written by `scripts/bench` on {ctx.get('date', '?')[:10]}.", "",
             "| benchmark | what | median (ms) | ratio | to |", "| --- | --- | ---: | ---: | --- |"]
    for name, what, ref in ROWS:
        if name not in m:
            continue
        ratio = f"{m[name] / m[ref]:.2f}" if ref and ref in m else ""
        lines.append(f"| `{name.replace('/real_time', '')}` | {what} | {m[name]:.3f} | {ratio} | "
                     f"{'`' + ref.replace('/real_time', '') + '`' if ref and ref in m else ''} |")
    return "\n".join(lines) + "\n"


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

"""The generated tables of the documentation: scripts/results_tables.py (scripts/demo) and scripts/bench_table.py
(scripts/bench) on inputs with known answers, and the checked-in README and doc/results.md agreeing."""
import json
import os
import subprocess
import sys

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
RESULTS = os.path.join(ROOT, "scripts", "results_tables.py")
BENCH = os.path.join(ROOT, "scripts", "bench_table.py")
BEGIN = "<!-- results:begin (scripts/demo writes this table; do not edit) -->"
END = "<!-- results:end -->"


def write_metrics(path, variants):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        json.dump({"meta": {}, "variants": variants}, f)


def sim(iou_f, movers):
    return {"free.iou": iou_f, "building.iou": 0.5, "moving.precision": 0.25, "moving.recall": 0.125,
            "movers.all.detected_within_1s": movers, "movers.all.seen": 11, "moving.trail_cells_per_scan": 0.5}


def track(mover, rmse, share):
    return {"id": mover, "frames": 10, "tracked_frames": 9, "identity_share": 1.0, "velocity_pairs": 9,
            "velocity_rmse_mps": rmse, "velocity_median_mps": 1.5, "velocity_error_share": share}


def write_held_out(path, default_movers):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    drive = dict(sim(0.75, default_movers), **{"tracks.mota": 0.8, "tracks.velocity_rmse_mps": 0.25})
    pooled = dict(drive, **{"movers.all.seen": 11})
    with open(path, "w") as f:
        json.dump({"drives": [{"name": "town_101", "preset": "vlp32"}],
                   "variants": {"default": {"pooled": pooled, "drives": {"town_101": drive}},
                                "paper": {"pooled": sim(0.5, 2), "drives": {"town_101": sim(0.5, 2)}}}}, f)


def write_sealed(path, default_movers):
    """learning/held_out --split sealed's output: pooled scores only."""
    os.makedirs(os.path.dirname(path), exist_ok=True)
    pooled = dict(sim(0.625, default_movers), **{"tracks.mota": 0.5, "tracks.velocity_rmse_mps": 1.5})
    with open(path, "w") as f:
        json.dump({"split": "sealed", "drives": [{"name": "town_201", "preset": "vlp32"},
                                                  {"name": "village_201", "preset": "hdl64"}],
                   "variants": {"default": {"pooled": pooled}, "paper": {"pooled": sim(0.5, 1)}}}, f)


REAL = ("kitti_00", "kitti_00_suma", "semantic_kitti_02", "semantic_kitti_06", "semantic_kitti_09",
        "semantic_kitti_10")


def real_variant(ground_f, ground, false_v=0, sweeps=10, tp=0, fp=0, fn=0, seg=(0, 0, 0)):
    """A labelled real sequence's variant as `evaluate` writes it: ratios and the counts behind them."""
    return {"labelled_sweeps": sweeps, "counts.ground_f_cells": ground_f, "counts.ground_cells": ground,
            "counts.false_v": false_v, "counts.moving_tp": tp, "counts.moving_fp": fp, "counts.moving_fn": fn,
            "counts.segmentation_tp": seg[0], "counts.segmentation_fp": seg[1], "counts.segmentation_fn": seg[2],
            "counts.obstacle_cells": 1000, "counts.obstacle_f_cells": 1, "counts.mover_cells": 10,
            "counts.mover_v_cells": 5, "counts.ground_as_obstacle": 0,
            "ground_cells_f_recall": ground_f / ground if ground else -1}


def write_real(out, default=None, paper=None):
    for n in REAL:
        write_metrics(str(out / "real" / n / "metrics.json"),
                      {"default": default or real_variant(1, 2), "paper": paper or real_variant(0, 2)})


def fake_readme(tmp):
    path = os.path.join(tmp, "README.md")
    with open(path, "w") as f:
        f.write(f"# x\n\n{BEGIN}\nold table\n{END}\n\nafter\n")
    return path


def run(*args):
    return subprocess.run([sys.executable, RESULTS, *args], capture_output=True, text=True, check=True)


def test_summary_reads_each_profile_from_its_variant(tmp_path):
    out = tmp_path / "out"
    tracked = dict(sim(0.875, 4), movers_objects={"objects": [{"id": 5, "kind": "bus"}, {"id": 9, "kind": "car"}]},
                   tracks_objects=[track(9, 0.25, 0.2), track(5, 2.0, 0.8)])
    write_metrics(str(out / "metrics.json"), {"default": tracked, "paper": sim(0.5, 7)})
    write_real(out, default=real_variant(3, 4, false_v=25), paper=real_variant(1, 4, false_v=1400))
    write_metrics(str(out / "kitti_tracking" / "metrics.json"),
                  {"default": {"movers.all.detected_within_1s": 3, "movers.all.seen": 5, "tracks.mota": 0.853},
                   "paper": {"movers.all.detected_within_1s": 1, "movers.all.seen": 5}})
    write_held_out(str(out / "held_out" / "metrics.json"), 9)
    write_sealed(str(out / "sealed" / "metrics.json"), 6)
    (tmp_path / "doc").mkdir()
    readme = fake_readme(str(tmp_path))
    figure = tmp_path / "figure2.png"
    figure.write_bytes(b"png")
    run(str(out), "--doc", str(tmp_path / "doc"), "--readme", readme, "--figure", str(figure))
    text = open(readme).read()
    assert "| simulator | IoU F | 0.875 | 0.500 |" in text
    assert "| simulator | movers V ≤ 1 s | 4/11 | 7/11 |" in text
    assert "| real sequences, pooled (5) | false V / labelled sweep | 2.5 | 140.0 |" in text
    assert "| real sequences, pooled (5) | ground cells F | 0.750 | 0.250 |" in text
    assert "| KITTI tracking | movers V ≤ 1 s | 3/5 | 1/5 |" in text
    assert "| KITTI tracking | MOTA | 0.85 | – |" in text, "the paper has no tracks"
    assert "| held-out drives, pooled | movers V ≤ 1 s | 9/11 | 2/11 |" in text
    assert "| held-out drives, pooled | velocity RMSE (m/s) | 0.25 | – |" in text
    assert "| sealed drives, pooled | movers V ≤ 1 s | 6/11 | 1/11 |" in text
    assert "| sealed drives, pooled | MOTA | 0.50 | – |" in text
    assert "old table" not in text and text.endswith("after\n")
    doc = open(tmp_path / "doc" / "results.md").read()
    assert "## Labelled real sequences" in doc and "| default | 0.875 |" in doc
    assert "| SemanticKITTI 10 | default | 2.5 |" in doc
    assert "| `town_101` (vlp32) | default | 0.750 |" in doc and "| pooled (1 drives) | paper | 0.500 |" in doc
    # The sealed drives pooled only: one row per profile, no drive of theirs named.
    assert "| **sealed**, pooled (2 drives) | default | 0.625 |" in doc and "town_201" not in doc
    # The movers' velocity errors, the largest share of the squared error first; none for KITTI without tracks.
    assert "| 5 | bus | 10 | 9 | 1.00 | 9 | 2.00 | 1.50 | 0.80 |\n| 9 | car |" in doc
    assert doc.count("Per mover, the tracks of") == 1
    assert (tmp_path / "doc" / "images" / "figure2.png").read_bytes() == b"png"


def test_docs_are_left_alone_without_the_held_out_drives(tmp_path):
    out = tmp_path / "out"
    write_metrics(str(out / "metrics.json"), {"default": sim(0.875, 4), "paper": sim(0.5, 7)})
    write_real(out)
    write_metrics(str(out / "kitti_tracking" / "metrics.json"), {"default": {}, "paper": {}})
    (tmp_path / "doc").mkdir()
    readme = fake_readme(str(tmp_path))
    r = run(str(out), "--doc", str(tmp_path / "doc"), "--readme", readme)
    assert "held-out drives, sealed drives not evaluated" in r.stdout
    assert "old table" in open(readme).read()
    assert "Held-out" not in open(out / "results.md").read()
    # The held-out drives without the sealed ones: still left alone.
    write_held_out(str(out / "held_out" / "metrics.json"), 9)
    r = run(str(out), "--doc", str(tmp_path / "doc"), "--readme", readme)
    assert "sealed drives not evaluated" in r.stdout and "old table" in open(readme).read()


def test_docs_are_left_alone_without_the_real_datasets(tmp_path):
    out = tmp_path / "out"
    write_metrics(str(out / "metrics.json"), {"default": sim(0.875, 4), "paper": sim(0.5, 7)})
    (tmp_path / "doc").mkdir()
    readme = fake_readme(str(tmp_path))
    r = run(str(out), "--doc", str(tmp_path / "doc"), "--readme", readme)
    assert "left as they are" in r.stdout
    assert "old table" in open(readme).read()
    assert not (tmp_path / "doc" / "results.md").exists()
    assert "| default | 0.875 |" in open(out / "results.md").read()


def test_real_sequences_pool_by_summing_counts(tmp_path):
    out = tmp_path / "out"
    write_metrics(str(out / "metrics.json"), {"default": sim(0.875, 4), "paper": sim(0.5, 7)})
    # Ground cells F: 1/1 on kitti_00, 1/3 on each SemanticKITTI sequence; kitti_00_suma (9/9) is not pooled.
    # Pooled: (1 + 4 × 1) / (1 + 4 × 3) = 5/13, not the mean of the ratios. Moving IoU: TP 2, FP 1, FN 1 each.
    for n in REAL:
        ground_f, ground = (1, 1) if n == "kitti_00" else (9, 9) if n == "kitti_00_suma" else (1, 3)
        write_metrics(str(out / "real" / n / "metrics.json"),
                      {"default": real_variant(ground_f, ground, tp=2, fp=1, fn=1, seg=(90, 5, 5)),
                       "paper": real_variant(0, ground), "default_without_x": real_variant(0, 1)})
    run(str(out))
    pooled = json.load(open(out / "real" / "pooled.json"))
    assert pooled["sequences"] == ["kitti_00", "semantic_kitti_02", "semantic_kitti_06", "semantic_kitti_09",
                                   "semantic_kitti_10"]
    c = pooled["variants"]["default"]["counts"]
    assert (c["ground_f_cells"], c["ground_cells"]) == (5, 13)
    assert c["ground_points"] == 5 * 95
    text = open(out / "results.md").read()
    assert f"| **pooled** (5 drives) | default | 0.0 | 0.50 | 0.500 | {5 / 13:.3f} |" in text
    assert "| default_without_x |" in text, "every variant on the pooled sequences"
    summary = open(out / "results_summary.md").read()
    assert f"| real sequences, pooled (5) | ground cells F | {5 / 13:.3f} | 0.000 |" in summary
    assert "| real sequences, pooled (5) | ground F1 (points) | 0.947 | – |" in summary


def test_checked_in_readme_shows_the_summary_of_doc_results():
    readme = open(os.path.join(ROOT, "README.md")).read()
    block = readme[readme.index(BEGIN) + len(BEGIN):readme.index(END)].strip()
    results = open(os.path.join(ROOT, "doc", "results.md")).read()
    assert block and block in results, "README and doc/results.md come from different runs: run scripts/demo"


def test_bench_table_gives_ratios_within_one_run(tmp_path):
    data = {"context": {"host_name": "h", "num_cpus": 2, "mhz_per_cpu": 2000, "date": "2026-12-03T10:00:00"},
            "benchmarks": [
                {"name": "BM_MapGridUpdate/n:800/threads:1/real_time_median", "run_name": "BM_MapGridUpdate/n:800/threads:1/real_time",
                 "run_type": "aggregate", "aggregate_name": "median", "real_time": 20.0, "time_unit": "ms", "repetitions": 5},
                {"name": "BM_MapGridUpdate/n:800/threads:2/real_time_median", "run_name": "BM_MapGridUpdate/n:800/threads:2/real_time",
                 "run_type": "aggregate", "aggregate_name": "median", "real_time": 12500.0, "time_unit": "us", "repetitions": 5},
                {"name": "BM_MapGridUpdate/n:800/threads:2/real_time_mean", "run_name": "BM_MapGridUpdate/n:800/threads:2/real_time",
                 "run_type": "aggregate", "aggregate_name": "mean", "real_time": 99.0, "time_unit": "ms", "repetitions": 5},
            ]}
    path = tmp_path / "bench.json"
    path.write_text(json.dumps(data))
    doc = tmp_path / "performance.md"
    doc.write_text("x\n<!-- bench:begin (scripts/bench writes this table; do not edit) -->\nold\n<!-- bench:end -->\n")
    subprocess.run([sys.executable, BENCH, str(path), "--doc", str(doc)], check=True, capture_output=True)
    text = doc.read_text()
    assert "| `BM_MapGridUpdate/n:800/threads:2` | the same, 2 threads | 12.500 | 0.62 | `BM_MapGridUpdate/n:800/threads:1` |" in text
    assert "medians of 5 repetitions" in text and "2 CPUs" in text and "old" not in text


def test_bench_table_shows_the_drive_counter(tmp_path):
    drive = "BM_MapGridUpdateDrive/n:800/threads:2/skip:{}/iterations:200/real_time"
    data = {"context": {"host_name": "h", "num_cpus": 2, "mhz_per_cpu": 2000, "date": "2026-12-03T10:00:00"},
            "benchmarks": [
                {"name": drive.format(0) + "_median", "run_name": drive.format(0), "run_type": "aggregate",
                 "aggregate_name": "median", "real_time": 10.0, "time_unit": "ms", "repetitions": 3, "skipped_share": 0.0},
                {"name": drive.format(1) + "_median", "run_name": drive.format(1), "run_type": "aggregate",
                 "aggregate_name": "median", "real_time": 8.0, "time_unit": "ms", "repetitions": 3, "skipped_share": 0.456,
                 "observed_share": 0.1, "changing_share": 0.444},
                {"name": "BM_ScansToFixedPoint/history:1/iterations:1_median",
                 "run_name": "BM_ScansToFixedPoint/history:1/iterations:1", "run_type": "aggregate",
                 "aggregate_name": "median", "real_time": 4.0, "time_unit": "ms", "repetitions": 3, "scans": 428.0},
            ]}
    path = tmp_path / "bench.json"
    path.write_text(json.dumps(data))
    out = subprocess.run([sys.executable, BENCH, str(path)], check=True, capture_output=True, text=True).stdout
    assert ("| `BM_MapGridUpdateDrive/n:800/threads:2/skip:1` | the same with `skip_unchanged`; skipped share 0.46, "
            "observed share 0.10, changing share 0.44 | 8.000 | 0.80 | `BM_MapGridUpdateDrive/n:800/threads:2/skip:0` |") in out
    assert "| `BM_ScansToFixedPoint/history:1` | the same for a cell seen occupied on a mapped road (a parked car that left); scans 428 | 4.000 |  |  |" in out


def test_bench_table_bounds_the_drive_with_free_skips(tmp_path):
    drive = "BM_MapGridUpdateDrive/n:{}/threads:2/skip:{}/iterations:200/real_time"
    stages = {"shift_ms": 0.5, "project_ms": 0.25, "prior_ms": 0.0, "fusion_ms": 4.0}
    benchmarks = []
    for n in (800, 200):
        benchmarks.append({"name": drive.format(n, 0) + "_median", "run_name": drive.format(n, 0), "run_type": "aggregate",
                           "aggregate_name": "median", "real_time": 5.0, "time_unit": "ms", "repetitions": 3,
                           "skipped_share": 0.0, **stages})
        benchmarks.append({"name": drive.format(n, 1) + "_median", "run_name": drive.format(n, 1), "run_type": "aggregate",
                           "aggregate_name": "median", "real_time": 4.0, "time_unit": "ms", "repetitions": 3,
                           "skipped_share": 0.75 if n == 800 else 0.5, **stages})
    data = {"context": {"host_name": "h", "num_cpus": 2, "mhz_per_cpu": 2000, "date": "2026-12-03T10:00:00"},
            "benchmarks": benchmarks}
    path = tmp_path / "bench.json"
    path.write_text(json.dumps(data))
    out = subprocess.run([sys.executable, BENCH, str(path)], check=True, capture_output=True, text=True).stdout
    # 0.5 + 0.25 + 0 + 4 × (1 − skipped)
    assert ("would still take 1.75 ms at 800 × 800 (computing 0.25 of the cells) and 2.75 ms at 200 × 200 "
            "(computing 0.50 of the cells)") in out

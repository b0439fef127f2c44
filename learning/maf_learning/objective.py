"""The tuner's objective: one number from the `evaluate` metrics of a set of drives (higher is better).

The drives' confusion matrices and object counts are pooled (a drive with more cells or movers weighs more), then

    score = 0.40 * mean IoU (F, C, N, S, V)
          + 0.15 * V precision + 0.10 * V recall
          + 0.20 * moving objects detected within 1 s (share of the visible ones)
          - 0.10 * min(1, 10 * share of stopped objects called moving)
          - 0.05 * min(1, V trail / 5 cells per scan)
          - 1.00 * sum over the classes of max(0, 0.98 * IoU_reference - IoU)

The last term holds every class IoU within 2 % (relative) of a reference, the paper's parameters on the same
drives, when a reference is given: a set that buys V precision with a class's IoU pays for it.
"""
CLASSES = ("free", "building", "infrastructure", "stopped", "moving")
SHORT = dict(zip(CLASSES, "FCNSV"))
WEIGHTS = {"mean_iou": 0.40, "v_precision": 0.15, "v_recall": 0.10, "detected": 0.20,
           "stopped_moving": 0.10, "trail": 0.05, "iou_loss": 1.00}
IOU_TOLERANCE = 0.98  # a class may lose 2 % (relative) of the reference's IoU before it is penalised
STOPPED_MOVING_SCALE = 10.0
TRAIL_SCALE = 5.0  # cells per scan


def pool(metrics_list):
    """Pooled scores of several drives' `evaluate` variants (each the dict of metrics.json's variants[name])."""
    counts = [[0] * 6 for _ in range(5)]
    visible = detected = scans = 0
    trail = stopped = 0.0
    for m in metrics_list:
        for t in range(5):
            for d in range(6):
                counts[t][d] += m["confusion"]["counts"][t][d]
        visible += m["objects.moving.visible"]
        detected += m["objects.moving.detected_within_1s"]
        n = m["scans"]
        scans += n
        trail += m["moving.trail_cells_per_scan"] * n
        stopped += m["objects.stopped.called_moving_rate"] * n
    out = {"drives": len(metrics_list), "scans": scans, "moving_visible": visible, "moving_detected": detected}
    for c, name in enumerate(CLASSES):
        tp = counts[c][c]
        truth = sum(counts[c])
        decided = sum(counts[t][c] for t in range(5))
        union = truth + decided - tp
        out[f"iou_{SHORT[name]}"] = tp / union if union else 0.0
        if name == "moving":
            out["v_precision"] = tp / decided if decided else 0.0
            out["v_recall"] = tp / truth if truth else 0.0
    out["mean_iou"] = sum(out[f"iou_{SHORT[c]}"] for c in CLASSES) / len(CLASSES)
    out["detected"] = detected / visible if visible else 0.0
    out["trail"] = trail / scans if scans else 0.0
    out["stopped_moving"] = stopped / scans if scans else 0.0
    out["movers"] = pool_movers(metrics_list)
    out["tracks"] = pool_tracks(metrics_list)
    return out


HALF_SECOND = 0.5 + 1e-6  # s, "detected within 0.5 s" (stamps are rounded to ns)
ONE_SECOND = 1.0 + 1e-6


def pool_movers(metrics_list):
    """Moving objects pooled over several drives' `evaluate` variants (their `movers_objects`, doc/evaluation.md "Scoring
    moving objects"): movers seen, detected within 0.5 s and 1 s, never V, the median delay (never V counts as
    infinite: None when more than half never are), the mean V share over movers, the S share of their cells."""
    movers = [o for m in metrics_list for o in m.get("movers_objects", {}).get("objects", [])
              if o["mover"] and o["first_seen_s"] is not None]
    delays = sorted(float("inf") if o["delay_s"] is None else o["delay_s"] for o in movers)
    median = None
    if delays:
        n = len(delays)
        median = delays[n // 2] if n % 2 else 0.5 * (delays[n // 2 - 1] + delays[n // 2])
        median = None if median == float("inf") else median
    cells = sum(o["occupied_cells"] for o in movers)
    return {"seen": len(movers),
            "within_0_5s": sum(d <= HALF_SECOND for d in delays),
            "within_1s": sum(d <= ONE_SECOND for d in delays),
            "never": sum(o["delay_s"] is None for o in movers),
            "median_delay_s": median,
            "mean_v_share": sum(o["v_share"] for o in movers) / len(movers) if movers else 0.0,
            "s_share": sum(o["s_share"] * o["occupied_cells"] for o in movers) / cells if cells else 0.0}


def pool_tracks(metrics_list):
    """The tracks' CLEAR-MOT counts pooled over drives (doc/evaluation.md, "Tracks: CLEAR-MOT"): MOTA = 1 - (misses +
    false positives + id switches) / objects over all their frames, and the velocity RMSE over all matched pairs
    (each drive's RMSE weighted by its pairs). Drives without tracks (the paper's method) are left out; None when no
    drive has any."""
    keys = ("objects", "misses", "false_positives", "id_switches", "velocity_pairs")
    with_tracks = [m for m in metrics_list if all(f"tracks.{k}" in m for k in keys)]
    if not with_tracks:
        return {"drives": 0, "mota": None, "velocity_rmse_mps": None}
    total = {k: sum(int(m[f"tracks.{k}"]) for m in with_tracks) for k in keys}
    errors = total["misses"] + total["false_positives"] + total["id_switches"]
    pairs = total["velocity_pairs"]
    squared = sum((m.get("tracks.velocity_rmse_mps") or 0.0) ** 2 * int(m["tracks.velocity_pairs"])
                  for m in with_tracks)
    return {"drives": len(with_tracks), **total,
            "mota": 1.0 - errors / total["objects"] if total["objects"] else None,
            "velocity_rmse_mps": (squared / pairs) ** 0.5 if pairs else None}


def score(pooled, reference=None):
    w = WEIGHTS
    s = (w["mean_iou"] * pooled["mean_iou"] + w["v_precision"] * pooled["v_precision"]
         + w["v_recall"] * pooled["v_recall"] + w["detected"] * pooled["detected"]
         - w["stopped_moving"] * min(1.0, STOPPED_MOVING_SCALE * pooled["stopped_moving"])
         - w["trail"] * min(1.0, pooled["trail"] / TRAIL_SCALE))
    if reference:
        s -= w["iou_loss"] * sum(max(0.0, IOU_TOLERANCE * reference[f"iou_{c}"] - pooled[f"iou_{c}"]) for c in "FCNSV")
    return s

#!/usr/bin/env python3
"""Figures of a map_aided_fusion evaluation (the output folder of `evaluate`).

Writes, next to metrics.json:
  figure2.png        the paper's Figure 2 at one instant: (a) scene from above with ground-truth objects,
                     (b) PriorGrid, (c) MapGrid without prior, (d) MapGrid with prior (BetP colours)
  contact_sheet.png  the MapGrid decision (with prior) every few seconds of the drive, ground truth boxes on top
  scores_over_time.png  per-class recall over time, with and without the prior
  movers_timeline.png   per moving object, its decision sweep by sweep (V / S / other / unseen), per variant
usage: figures.py OUT_DIR                  (a simulated drive: all four figures)
       figures.py --kitti-tracking OUT_DIR  (labelled real objects: the timeline only)
"""
import csv
import json
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.patches as patches  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

# The paper's colours: F white, C blue, N cyan, S green, V red.
CLASS_NAMES = ["F free", "C building", "N infrastructure", "S stopped", "V moving"]
CLASS_COLOURS = np.array([[1.0, 1.0, 1.0], [0.0, 0.0, 1.0], [0.0, 0.85, 0.85], [0.0, 0.7, 0.0], [1.0, 0.0, 0.0]])
UNKNOWN = np.array([0.3, 0.3, 0.3])
PRIOR_COLOURS = {0: [0.0, 0.0, 0.0], 1: [0.0, 0.0, 1.0], 2: [1.0, 1.0, 1.0], 3: [0.6, 0.6, 0.6]}
OBJECT_EDGE = {2: "darkcyan", 3: "lime", 4: "red"}


def extent(grid):
    return [grid["origin_x"], grid["origin_x"] + grid["width"] * grid["resolution"],
            grid["origin_y"], grid["origin_y"] + grid["height"] * grid["resolution"]]


def classes_to_rgb(codes):
    rgb = np.empty(codes.shape + (3,))
    rgb[:] = UNKNOWN
    for k in range(5):
        rgb[codes == k] = CLASS_COLOURS[k]
    return rgb


def betp_to_rgb(betp, decision):
    rgb = np.tensordot(np.moveaxis(betp, 0, -1), CLASS_COLOURS, axes=([2], [0]))
    rgb[decision < 0] = UNKNOWN
    return np.clip(rgb, 0.0, 1.0)


def draw_objects(ax, meta, with_labels=False):
    x0, x1, y0, y1 = extent(meta["grid"])
    for o in meta["objects"]:
        if not (x0 <= o["x"] <= x1 and y0 <= o["y"] <= y1):
            continue
        if o["class"] not in OBJECT_EDGE:
            continue
        c, s = np.cos(o["yaw"]), np.sin(o["yaw"])
        corner = (o["x"] - 0.5 * (o["length"] * c - o["width"] * s), o["y"] - 0.5 * (o["length"] * s + o["width"] * c))
        ax.add_patch(patches.Rectangle(corner, o["length"], o["width"], angle=np.degrees(o["yaw"]), fill=False,
                                       edgecolor=OBJECT_EDGE[o["class"]], linewidth=1.2))
        if with_labels and o["class"] in (3, 4):
            ax.text(o["x"], o["y"] + 0.6 * max(o["length"], o["width"]), o["kind"], color=OBJECT_EDGE[o["class"]],
                    fontsize=6, ha="center", clip_on=True)
    e = meta["ego"]
    c, s = np.cos(e["yaw"]), np.sin(e["yaw"])
    length, width = 4.5, 2.0
    corner = (e["x"] - 0.5 * (length * c - width * s), e["y"] - 0.5 * (length * s + width * c))
    ax.add_patch(patches.Rectangle(corner, length, width, angle=np.degrees(e["yaw"]), facecolor="royalblue",
                                   edgecolor="navy", linewidth=1.0))


def scale_bar(ax, grid, metres=10.0):
    x0, x1, y0, y1 = extent(grid)
    bx, by = x0 + 0.05 * (x1 - x0), y0 + 0.05 * (y1 - y0)
    ax.plot([bx, bx + metres], [by, by], color="black", linewidth=3, solid_capstyle="butt")
    ax.plot([bx, bx + metres], [by, by], color="white", linewidth=1, solid_capstyle="butt")
    ax.text(bx + metres / 2, by + 0.02 * (y1 - y0), f"{metres:g} m", ha="center", fontsize=7,
            bbox=dict(facecolor="white", edgecolor="none", pad=1))


def finish(ax, grid, title):
    x0, x1, y0, y1 = extent(grid)
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal")
    ax.set_title(title, fontsize=9)
    ax.tick_params(labelsize=6)
    scale_bar(ax, grid)


def figure2(out):
    snap = out / "snapshots"
    meta = json.loads((snap / "figure.json").read_text())
    grid, truth_grid = meta["grid"], meta["truth_grid"]
    truth = np.load(snap / "figure_truth.npy")
    prior = np.load(snap / "figure_prior.npy")
    fig, axes = plt.subplots(2, 2, figsize=(11, 11))
    ax = axes[0, 0]
    ax.imshow(classes_to_rgb(truth), origin="lower", extent=extent(truth_grid), interpolation="nearest")
    draw_objects(ax, meta, with_labels=True)
    finish(ax, grid, f"(a) scene from above: ground truth at t = {meta['time_s']:.1f} s")
    ax = axes[0, 1]
    prior_rgb = np.zeros(prior.shape + (3,))
    for k, colour in PRIOR_COLOURS.items():
        prior_rgb[prior == k] = colour
    ax.imshow(prior_rgb, origin="lower", extent=extent(grid), interpolation="nearest")
    draw_objects(ax, meta)
    finish(ax, grid, "(b) PriorGrid: road R white, building B blue, other T grey")
    for ax, name, title in ((axes[1, 0], "default_no_prior", "(c) MapGrid without prior information"),
                            (axes[1, 1], "default", "(d) MapGrid with prior map knowledge")):
        betp = np.load(snap / f"figure_{name}_betp.npy")
        decision = np.load(snap / f"figure_{name}_decision.npy")
        ax.imshow(betp_to_rgb(betp, decision), origin="lower", extent=extent(grid), interpolation="nearest")
        draw_objects(ax, meta)
        finish(ax, grid, title + " (BetP colours)")
    handles = [patches.Patch(facecolor=CLASS_COLOURS[k], edgecolor="black", label=CLASS_NAMES[k]) for k in range(5)]
    handles.append(patches.Patch(facecolor=UNKNOWN, edgecolor="black", label="unknown / not observed"))
    handles.append(patches.Patch(facecolor="royalblue", edgecolor="navy", label="ego vehicle"))
    handles += [patches.Patch(fill=False, edgecolor=OBJECT_EDGE[k], label=f"true {n} object")
                for k, n in ((4, "moving"), (3, "stopped"), (2, "infrastructure"))]
    fig.legend(handles=handles, loc="lower center", ncol=5, fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    fig.savefig(out / "figure2.png", dpi=110)
    plt.close(fig)


def contact_sheet(out):
    snap = out / "snapshots"
    frames = sorted(snap.glob("sheet_*.json"), key=lambda p: int(p.stem.split("_")[1]))
    if not frames:
        return
    cols = min(4, len(frames))
    rows = (len(frames) + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(3.2 * cols, 3.4 * rows), squeeze=False)
    for ax in axes.flat:
        ax.axis("off")
    for ax, path in zip(axes.flat, frames):
        meta = json.loads(path.read_text())
        decision = np.load(snap / f"{path.stem}_with_prior_decision.npy")
        ax.imshow(classes_to_rgb(decision), origin="lower", extent=extent(meta["grid"]), interpolation="nearest")
        draw_objects(ax, meta)
        finish(ax, meta["grid"], f"t = {meta['time_s']:.0f} s")
        ax.axis("on")
    handles = [patches.Patch(facecolor=CLASS_COLOURS[k], edgecolor="black", label=CLASS_NAMES[k]) for k in range(5)]
    handles.append(patches.Patch(facecolor=UNKNOWN, edgecolor="black", label="unknown"))
    fig.legend(handles=handles, loc="lower center", ncol=6, fontsize=8, frameon=False)
    fig.suptitle("MapGrid decision with prior during the drive (true objects outlined)", fontsize=10)
    fig.tight_layout(rect=(0, 0.04, 1, 0.97))
    fig.savefig(out / "contact_sheet.png", dpi=100)
    plt.close(fig)


def scores_over_time(out):
    rows = list(csv.DictReader((out / "scores.csv").open()))
    if not rows:
        return
    fig, axes = plt.subplots(1, 3, figsize=(14, 4), sharey=True)
    for ax, cls in zip(axes, ("moving", "stopped", "building")):
        for variant, style in (("default", "-"), ("default_no_prior", "--")):
            pts = [(float(r["time_s"]), float(r[f"{cls}_recall"])) for r in rows
                   if r["variant"] == variant and r[f"{cls}_recall"] != ""]
            if not pts:
                continue
            t, v = np.array(pts).T
            k = min(10, len(v))
            smooth = np.convolve(v, np.ones(k) / k, mode="same")
            ax.plot(t, smooth, style, label=f"{variant} (1 s mean)")
        ax.set_title(f"{cls} recall per scan", fontsize=10)
        ax.set_xlabel("time [s]")
        ax.set_ylim(0, 1.05)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("recall")
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "scores_over_time.png", dpi=100)
    plt.close(fig)


# Timeline states (eval/movers.hpp, SightingState): 0 unseen, 1 V, 2 S, 3 other; and not labelled moving.
TIMELINE_COLOURS = {1: CLASS_COLOURS[4], 2: CLASS_COLOURS[3], 3: np.array([0.55, 0.55, 0.55]),
                    0: np.array([0.85, 0.85, 0.85])}
NOT_MOVING = np.array([1.0, 1.0, 1.0])
TIMELINE_VARIANTS = ("default", "paper", "live", "live_default", "live_paper")


def movers_timeline(out):
    """Per mover, its state in each sweep: V red, S green, seen but neither grey, labelled but unseen light grey."""
    metrics = json.loads((out / "metrics.json").read_text())
    panels = [(name, metrics["variants"][name]["movers_objects"]) for name in TIMELINE_VARIANTS
              if name in metrics["variants"] and "movers_objects" in metrics["variants"][name]]
    panels = [(n, m) for n, m in panels if any(o["mover"] for o in m["objects"])]
    if not panels:
        return None
    movers = [o for o in panels[0][1]["objects"] if o["mover"]]
    height = 0.9 + 0.28 * len(movers) * len(panels)
    fig, axes = plt.subplots(len(panels), 1, figsize=(12, height), squeeze=False, sharex=True)
    for ax, (name, m) in zip(axes[:, 0], panels):
        stamps = np.array(m["stamps"])
        dt = float(np.median(np.diff(stamps))) if len(stamps) > 1 else 0.1
        objs = [o for o in m["objects"] if o["mover"]]
        labels = []
        for row, o in enumerate(objs):
            colours = np.tile(NOT_MOVING, (len(stamps), 1))
            for scan, state in o["timeline"]:
                colours[scan] = TIMELINE_COLOURS[state]
            ax.imshow(colours[np.newaxis], extent=[stamps[0] - dt / 2, stamps[-1] + dt / 2, row + 0.1, row + 0.9],
                      aspect="auto", interpolation="nearest")
            delay = "never V" if o["delay_s"] is None else f"V after {o['delay_s']:.1f} s"
            labels.append(f"{o['kind']} #{o['id']} ({o['max_speed']:.1f} m/s, {delay})")
        ax.set_ylim(0, len(objs))
        ax.set_yticks(np.arange(len(objs)) + 0.5)
        ax.set_yticklabels(labels, fontsize=7)
        ax.invert_yaxis()
        ax.set_xlim(stamps[0] - dt / 2, stamps[-1] + dt / 2)
        ax.set_title(f"{name}: each mover's decision per sweep", fontsize=9)
    axes[-1, 0].set_xlabel("time [s]")
    handles = [patches.Patch(color=TIMELINE_COLOURS[1], label="V (most of its cells moving)"),
               patches.Patch(color=TIMELINE_COLOURS[2], label="S (most stopped)"),
               patches.Patch(color=TIMELINE_COLOURS[3], label="seen, neither"),
               patches.Patch(color=TIMELINE_COLOURS[0], label="labelled, too little seen"),
               patches.Patch(facecolor=NOT_MOVING, edgecolor="black", label="not labelled moving")]
    fig.legend(handles=handles, loc="lower center", ncol=5, fontsize=7, frameon=False)
    fig.tight_layout(rect=(0, 0.06, 1, 1))
    path = out / "movers_timeline.png"
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def main():
    args = sys.argv[1:]
    if args and args[0] == "--kitti-tracking":
        out = pathlib.Path(args[1] if len(args) > 1 else "out/kitti_tracking")
        path = movers_timeline(out)
        print(f"wrote {path}" if path else f"no movers in {out / 'metrics.json'}")
        return
    out = pathlib.Path(args[0] if args else "out")
    figure2(out)
    contact_sheet(out)
    scores_over_time(out)
    movers_timeline(out)
    print(f"wrote {out / 'figure2.png'}, {out / 'contact_sheet.png'}, {out / 'scores_over_time.png'}, "
          f"{out / 'movers_timeline.png'}")


if __name__ == "__main__":
    main()

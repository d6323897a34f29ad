#!/usr/bin/python3
"""Plots of aerie-map-bench's CSV results (run with /usr/bin/python3: matplotlib).

usage: /usr/bin/python3 bench/map/plot_map.py RESULTS_DIR [PNG_DIR]
"""
import csv
import glob
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def rows(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def throughput(src, dst):
    path = os.path.join(src, "throughput.csv")
    if not os.path.exists(path):
        return
    r = rows(path)
    labels = [f"{x['input']}\n{x['resolution_m']} m / {x['max_range_m']} m" for x in r]
    xs = range(len(r))
    fig, ax = plt.subplots(figsize=(10, 4))
    ax.bar([x - 0.2 for x in xs], [float(x["octomap_mpts_s"]) for x in r], 0.4, label="OctoMap insertPointCloud")
    ax.bar([x + 0.2 for x in xs], [float(x["ours_mpts_s"]) for x in r], 0.4, label="robust update (aerie_map)")
    for x, row in zip(xs, r):
        ax.text(x + 0.2, float(row["ours_mpts_s"]), f"x{float(row['speedup']):.1f}", ha="center", va="bottom", fontsize=8)
    ax.set_xticks(list(xs))
    ax.set_xticklabels(labels, fontsize=7)
    ax.set_yscale("log")
    ax.set_ylabel("M points / s of thread CPU time (log)")
    ax.set_title("Insertion throughput (resolution / max range)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(dst, "map_throughput.png"), dpi=110)


def quality(src, dst):
    for path in sorted(glob.glob(os.path.join(src, "quality_*.csv"))):
        if path.endswith("_study.csv"):  # parameter studies: robust update only
            continue
        r = rows(path)
        name = os.path.splitext(os.path.basename(path))[0]
        res = sorted({float(x["resolution_m"]) for x in r})
        fig, axes = plt.subplots(1, 4, figsize=(13, 3.4))
        for ax, key, title in zip(axes, ["artifacts_pct", "wrongly_free_pct", "surface_occupied_pct", "memory_bytes"],
                                  ["wrongly occupied (artifacts) %", "wrongly free % (of solid voxels known)",
                                   "surface voxels occupied %", "map memory (KiB)"]):
            for i, method in enumerate(["octomap", "robust"]):
                vals = [float(next(x[key] for x in r if x["method"] == method and float(x["resolution_m"]) == s))
                        for s in res]
                if key == "memory_bytes":
                    vals = [v / 1024 for v in vals]
                ax.bar([j + (i - 0.5) * 0.4 for j in range(len(res))], vals, 0.4,
                       label="OctoMap" if method == "octomap" else "robust")
            ax.set_xticks(range(len(res)))
            ax.set_xticklabels([f"{s} m" for s in res])
            ax.set_title(title, fontsize=9)
        axes[0].legend(fontsize=8)
        fig.suptitle(f"Map quality vs the simulator's exact geometry ({name})", fontsize=10)
        fig.tight_layout()
        fig.savefig(os.path.join(dst, f"map_{name}.png"), dpi=110)


def bandwidth(src, dst):
    path = os.path.join(src, "bandwidth.csv")
    if not os.path.exists(path):
        return
    r = rows(path)
    fig, ax = plt.subplots(figsize=(7, 4))
    styles = iter([("o", "-", 9), ("s", "--", 7), ("^", ":", 5), ("x", "-.", 5)])
    for image in sorted({x["image"] for x in r}):
        for depth in ["exact", "sgbm"]:
            sel = [x for x in r if x["image"] == image and x["depth"] == depth]
            if not sel:
                continue
            marker, line, size = next(styles, ("o", "-", 4))
            ax.plot([float(x["bin_deg"]) for x in sel], [float(x["vo_depth_bytes_mean"]) / 1024 for x in sel],
                    marker=marker, linestyle=line, markersize=size, fillstyle="none",
                    label=f"VO_DEPTH {image} ({depth} depth)")
            if depth == "exact":  # compression against this image's raw disparity
                for x in sel:
                    ax.annotate(f"x{float(x['ratio']):.1f}", (float(x["bin_deg"]), float(x["vo_depth_bytes_mean"]) / 1024),
                                textcoords="offset points", xytext=(6, 4 if image.startswith("3") else -12), fontsize=7)
        raw = float(next(x["raw_disparity_bytes"] for x in r if x["image"] == image))
        ax.axhline(raw / 1024, linestyle="--", color="gray")
        ax.text(0.3, raw / 1024 * 1.05, f"raw 16-bit disparity {image}", fontsize=8, color="gray")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("spherical bin (deg)")
    ax.set_ylabel("KiB per frame")
    ax.set_title("Depth bandwidth: VO_DEPTH vs raw disparity\n(x: compression vs 376x240 above the curve, vs 752x480 below)", fontsize=10)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(dst, "map_bandwidth.png"), dpi=110)


def main():
    src = sys.argv[1] if len(sys.argv) > 1 else "build/bench-map"
    dst = sys.argv[2] if len(sys.argv) > 2 else src
    os.makedirs(dst, exist_ok=True)
    throughput(src, dst)
    quality(src, dst)
    bandwidth(src, dst)


if __name__ == "__main__":
    main()

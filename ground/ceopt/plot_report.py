#!/usr/bin/python3
"""Plots for an aerie-ceopt output folder (run by aerie-ceopt; also by hand):
    /usr/bin/python3 ground/ceopt/plot_report.py OUT_DIR
Writes cost.png, pdf_stage1.png, pdf_stage2.png (PDF evolution per parameter, like the
thesis' Figs. 5.16-5.25), mfs.png (membership functions, Figs. 5.6-5.9 / 5.26-5.29),
trajectories.png, heading.png and rmse.png."""
import csv
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

THESIS = {"sf": {0.4: 4.812, 0.6: 6.060, 0.8: 7.427}, "sfmf": {0.4: 2.583, 0.6: 3.218, 0.8: 4.069}}
COLORS = {"initial": "tab:gray", "sf": "tab:blue", "sfmf": "tab:red", "pruned": "tab:green"}


def rows(path):
    if not os.path.exists(path):
        return []
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def progress(out, stage):
    r = rows(os.path.join(out, f"progress_stage{stage}.csv"))
    if not r:
        return None, []
    names = [k[5:] for k in r[0] if k.startswith("mean_")]
    return r, names


def plot_cost(out):
    fig, ax = plt.subplots(figsize=(8, 4.5))
    for stage in (1, 2):
        r, _ = progress(out, stage)
        if not r:
            continue
        it = [int(x["iteration"]) for x in r]
        ax.plot(it, [float(x["best_cost"]) for x in r], label=f"stage {stage}: best so far")
        ax.plot(it, [float(x["iteration_best_cost"]) for x in r], ":", label=f"stage {stage}: best of iteration")
        ax.plot(it, [float(x["gamma"]) for x in r], "--", alpha=0.6, label=f"stage {stage}: elite threshold gamma")
    ax.set_yscale("log")
    ax.set_xlabel("iteration")
    ax.set_ylabel("cost (mean ITSE + penalties)")
    ax.set_title("Cross-entropy optimisation: cost per iteration")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "cost.png"), dpi=110)
    plt.close(fig)


def plot_pdfs(out, stage):
    r, names = progress(out, stage)
    if not r:
        return
    n = len(names)
    cols = min(3, n)
    nrows = math.ceil(n / cols)
    fig = plt.figure(figsize=(5.2 * cols, 4.2 * nrows))
    its = [int(x["iteration"]) for x in r]
    pick = sorted(set([0] + list(range(0, len(r), max(1, len(r) // 20))) + [len(r) - 1]))
    for j, name in enumerate(names):
        ax = fig.add_subplot(nrows, cols, j + 1, projection="3d")
        mu = np.array([float(x["mean_" + name]) for x in r])
        sg = np.array([float(x["sigma_" + name]) for x in r])
        lo = min(mu[0] - 3 * sg[0], (mu - 3 * sg).min())
        hi = max(mu[0] + 3 * sg[0], (mu + 3 * sg).max())
        for k in pick:
            # Sample each Gaussian around its own mean so that narrow late ones are drawn.
            xs = np.concatenate(([lo], np.linspace(mu[k] - 4 * sg[k], mu[k] + 4 * sg[k], 200), [hi]))
            pdf = np.exp(-0.5 * ((xs - mu[k]) / sg[k]) ** 2) / (sg[k] * math.sqrt(2 * math.pi))
            ax.plot(xs, np.full_like(xs, its[k]), pdf, color=plt.cm.viridis(k / max(1, len(r) - 1)), lw=1)
        ax.set_xlabel(name)
        ax.set_ylabel("iteration")
        ax.set_zlabel("pdf")
        ax.set_title(f"{name}: mean {mu[-1]:.4g}, sigma {sg[-1]:.2g}", fontsize=9)
    fig.suptitle(f"Stage {stage}: evolution of the sampling PDF of each parameter")
    fig.tight_layout()
    fig.savefig(os.path.join(out, f"pdf_stage{stage}.png"), dpi=75)
    plt.close(fig)


def plot_mfs(out):
    r = rows(os.path.join(out, "mfs.csv"))
    if not r:
        return
    controllers = [c for c in ["initial", "sfmf", "pruned"] if any(x["controller"] == c for x in r)]
    variables = []
    for x in r:
        if x["variable"] not in variables:
            variables.append(x["variable"])
    fig, axes = plt.subplots(len(controllers), len(variables), figsize=(4.2 * len(variables), 2.6 * len(controllers)),
                             squeeze=False)
    for i, c in enumerate(controllers):
        for j, v in enumerate(variables):
            ax = axes[i][j]
            sets = [x for x in r if x["controller"] == c and x["variable"] == v]
            for s in sets:
                a, b, e = float(s["a"]), float(s["b"]), float(s["c"])
                if s["output"] == "1":
                    ax.vlines(b, 0, 1, lw=2)
                else:
                    ax.plot([a, b, e], [0, 1, 0], lw=1.2)
                ax.text(b, 1.04, s["set"], rotation=60, fontsize=6, ha="left", va="bottom")
            ax.set_xlim(float(sets[0]["min"]), float(sets[0]["max"]))
            ax.set_ylim(0, 1.5)
            ax.set_title(f"{c}: {v}", fontsize=9)
    fig.suptitle("Membership functions (scaled units; output sets as their peaks)")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "mfs.png"), dpi=80)
    plt.close(fig)


def trajectories(out):
    r = rows(os.path.join(out, "trajectories.csv"))
    data = {}
    for x in r:
        data.setdefault((x["controller"], float(x["speed"])), []).append(x)
    return data


def scene(out):
    try:
        with open(os.path.join(out, "summary.json")) as f:
            return json.load(f)["scene"]
    except (OSError, KeyError, ValueError):
        return {"normal_area_m": 1.0, "safe_area_m": 3.0, "wall_m": 5.0, "lateral_limit_m": 5.0}


def plot_trajectories(out, data):
    if not data:
        return
    sc = scene(out)
    nfa, saa, wall = sc["normal_area_m"], sc["normal_area_m"] + sc["safe_area_m"], sc["wall_m"]
    speeds = sorted({s for _, s in data})
    fig, axes = plt.subplots(1, len(speeds), figsize=(5 * len(speeds), 5), squeeze=False)
    for k, speed in enumerate(speeds):
        ax = axes[0][k]
        ax.axhspan(0, nfa, color="tab:green", alpha=0.08, label="normal flight area")
        ax.axhspan(nfa, saa, color="tab:orange", alpha=0.08, label="safe avoiding area")
        ax.axhspan(saa, wall, color="tab:red", alpha=0.12, label="dangerous alarm area")
        ax.axhline(wall, color="k", lw=3, label="wall")
        for (c, s), pts in data.items():
            if s != speed:
                continue
            ax.plot([abs(float(p["x"])) for p in pts], [float(p["y"]) for p in pts], color=COLORS.get(c), label=c)
        ax.set_xlim(-0.5, sc["lateral_limit_m"] + 0.5)
        ax.set_ylim(-0.2, wall + 0.5)
        ax.set_aspect("equal")
        ax.set_xlabel("sideways |x| (m; left turns mirrored)")
        ax.set_ylabel("y (m), toward the wall")
        ax.set_title(f"{speed} m/s")
        if k == 0:
            ax.legend(fontsize=7, loc="lower right")
    fig.suptitle("Avoidance trajectories (first evaluation run of each controller)")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "trajectories.png"), dpi=100)
    plt.close(fig)


def plot_heading(out, data):
    if not data:
        return
    speeds = sorted({s for _, s in data})
    fig, axes = plt.subplots(2, len(speeds), figsize=(5 * len(speeds), 7), squeeze=False, sharex="col")
    for k, speed in enumerate(speeds):
        for (c, s), pts in data.items():
            if s != speed:
                continue
            t = [float(p["t"]) for p in pts]
            h = [float(p["heading_deg"]) for p in pts]
            ref = [float(p["reference_deg"]) if p["active"] == "1" else float("nan") for p in pts]
            sign = -1.0 if any(r < 0 for r in ref if not math.isnan(r)) else 1.0  # left turns mirrored
            axes[0][k].plot(t, [sign * hh for hh in h], color=COLORS.get(c), label=c)
            axes[1][k].plot(t, [sign * (hh - rr) for hh, rr in zip(h, ref)], color=COLORS.get(c), label=c)
        axes[0][k].axhline(90, color="k", ls=":", lw=1)
        axes[0][k].set_title(f"{speed} m/s")
        axes[0][k].set_ylabel("heading (deg)")
        axes[1][k].set_ylabel("heading - reference (deg)")
        axes[1][k].set_ylim(-15, 15)
        axes[1][k].set_xlabel("time (s)")
        axes[1][k].grid(alpha=0.3)
        axes[0][k].grid(alpha=0.3)
    axes[0][0].legend(fontsize=8)
    fig.suptitle("Heading over time (true heading, left turns mirrored; the lower row zooms on the steady state)")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "heading.png"), dpi=100)
    plt.close(fig)


def plot_rmse(out):
    r = rows(os.path.join(out, "experiment_summary.csv"))
    if not r:
        return
    controllers = []
    for x in r:
        if x["controller"] not in controllers:
            controllers.append(x["controller"])
    speeds = sorted({float(x["speed"]) for x in r})
    fig, ax = plt.subplots(figsize=(8, 4.5))
    w = 0.8 / (len(controllers) + 2)
    for i, c in enumerate(controllers):
        vals = [next((float(x["rmse_mean_deg"]) for x in r if x["controller"] == c and float(x["speed"]) == s), np.nan)
                for s in speeds]
        errs = [next((float(x["rmse_std_deg"]) for x in r if x["controller"] == c and float(x["speed"]) == s), np.nan)
                for s in speeds]
        errs = [0 if np.isnan(e) else e for e in errs]
        ax.bar(np.arange(len(speeds)) + i * w, vals, w, yerr=errs, color=COLORS.get(c), label=f"{c} (simulation)")
    for i, c in enumerate(["sf", "sfmf"]):
        ax.bar(np.arange(len(speeds)) + (len(controllers) + i) * w, [THESIS[c].get(s, np.nan) for s in speeds], w,
               color=COLORS[c], alpha=0.35, hatch="//", label=f"{c} (thesis, real flights)")
    ax.set_xticks(np.arange(len(speeds)) + 0.4 - w / 2)
    ax.set_xticklabels([f"{s} m/s" for s in speeds])
    ax.set_ylabel("steady-state heading RMSE (deg)")
    ax.legend(fontsize=8)
    ax.grid(axis="y", alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "rmse.png"), dpi=110)
    plt.close(fig)


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    out = sys.argv[1]
    plot_cost(out)
    plot_pdfs(out, 1)
    plot_pdfs(out, 2)
    plot_mfs(out)
    data = trajectories(out)
    plot_trajectories(out, data)
    plot_heading(out, data)
    plot_rmse(out)


if __name__ == "__main__":
    main()

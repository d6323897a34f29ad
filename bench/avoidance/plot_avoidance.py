#!/usr/bin/python3
"""Plots and table of aerie-bench-avoidance's output.
   plot_avoidance.py DIR  (reads DIR/avoidance.csv and DIR/trajectories.csv; writes
   DIR/summary.md, DIR/heading_rmse.png (steady-state heading RMSE against speed, one line per
   heading source and controller), DIR/heading.png (the true heading after the turn started,
   first seed, per speed) and DIR/paths.png (top view of the first seed's flights with the
   zones of thesis Fig. 5.2))"""
import csv
import math
import statistics
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

SOURCES = ["gt", "vo", "vio"]
STYLE = {"gt": ("k", "-"), "vo": ("C1", "--"), "vio": ("C0", "-")}  # colour, line


def rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def conf(r):
    return (r["controller"], r["source"], float(r["speed_m_s"]))


def vib(r):
    return r.get("vibration", "on")


def table(runs):
    """One markdown row per (controller, source, speed)."""
    by = defaultdict(list)
    for r in runs:
        by[(vib(r),) + conf(r)].append(r)
    out = ["| vibration | controller | source | speed (m/s) | runs | completed | steady heading RMSE (deg), mean ± sd | "
           "settled | heading estimate RMSE (deg) | entered danger | collisions | closest to the wall (m) |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    order = {s: i for i, s in enumerate(SOURCES)}
    for k in sorted(by, key=lambda k: (k[0], k[1], k[3], order.get(k[2], 9))):
        rs = by[k]
        rm = [float(r["heading_rmse_deg"]) for r in rs if float(r["heading_rmse_deg"]) >= 0]
        est = [float(r["estimate_rmse_deg"]) for r in rs if r["estimate_rmse_deg"] not in ("nan", "")]
        sd = statistics.stdev(rm) if len(rm) > 1 else 0.0
        out.append(f"| {k[0]} | {k[1]} | {k[2]} | {k[3]:.1f} | {len(rs)} | {sum(int(r['completed']) for r in rs)} | "
                   f"{statistics.mean(rm) if rm else math.nan:.2f} ± {sd:.2f} | {len(rm)} | "
                   f"{statistics.mean(est) if est else math.nan:.2f} | {sum(int(r['entered_danger']) for r in rs)} | "
                   f"{sum(int(r['collision']) for r in rs)} | "
                   f"{min(float(r['min_wall_distance_m']) for r in rs):.2f} |")
    return "\n".join(out) + "\n"


def main(d):
    all_runs = rows(f"{d}/avoidance.csv")
    with open(f"{d}/summary.md", "w") as f:
        f.write(table(all_runs))
    # The plots show one vibration setting: on if it was flown.
    shown = "on" if any(vib(r) == "on" for r in all_runs) else "off"
    runs = [r for r in all_runs if vib(r) == shown]
    traj = [r for r in rows(f"{d}/trajectories.csv") if vib(r) == shown]
    controllers = sorted({r["controller"] for r in runs})
    speeds = sorted({float(r["speed_m_s"]) for r in runs})

    fig, axes = plt.subplots(1, len(controllers), figsize=(5 * len(controllers), 3.8), squeeze=False, sharey=True)
    for ax, c in zip(axes[0], controllers):
        for s in SOURCES:
            pts = []
            for v in speeds:
                rm = [float(r["heading_rmse_deg"]) for r in runs if conf(r) == (c, s, v) and float(r["heading_rmse_deg"]) >= 0]
                if rm:
                    pts.append((v, statistics.mean(rm), statistics.stdev(rm) if len(rm) > 1 else 0))
            if pts:
                ax.errorbar([p[0] for p in pts], [p[1] for p in pts], yerr=[p[2] for p in pts], color=STYLE[s][0], ls=STYLE[s][1],
                            marker="o", capsize=3, label=s)
        ax.set_title(f"controller {c}, vibration {shown}")
        ax.set_xlabel("forward speed (m/s)")
        ax.grid(alpha=0.3)
        ax.legend()
    axes[0][0].set_ylabel("steady-state heading RMSE (deg)")
    fig.tight_layout()
    fig.savefig(f"{d}/heading_rmse.png", dpi=110)

    first = min(int(r["seed"]) for r in runs)
    c0 = "sfmf" if "sfmf" in controllers else controllers[0]
    fig, axes = plt.subplots(1, len(speeds), figsize=(4.5 * len(speeds), 3.6), squeeze=False, sharey=True)
    fig2, axes2 = plt.subplots(1, len(speeds), figsize=(4.5 * len(speeds), 4.2), squeeze=False, sharey=True)
    for ax, ax2, v in zip(axes[0], axes2[0], speeds):
        for s in SOURCES:
            pts = [r for r in traj if int(r["seed"]) == first and conf(r) == (c0, s, v)]
            turning = [r for r in pts if r["turning"] == "1"]
            if turning:
                t0 = float(turning[0]["t_s"])
                ax.plot([float(r["t_s"]) - t0 for r in turning], [float(r["heading_deg"]) for r in turning],
                        color=STYLE[s][0], ls=STYLE[s][1], label=s)
            if pts:
                ax2.plot([float(r["lateral_m"]) for r in pts], [float(r["travel_m"]) for r in pts], color=STYLE[s][0],
                         ls=STYLE[s][1], label=s)
        ax.axhline(90, color="grey", lw=0.8)
        ax.set_title(f"{c0}, {v:.1f} m/s, seed {first}")
        ax.set_xlabel("time since the turn started (s)")
        ax.grid(alpha=0.3)
        ax.legend()
        for y0, y1, col in ((0, 1, "#e8f5e9"), (1, 4, "#fffde7"), (4, 5, "#ffebee")):
            ax2.axhspan(y0, y1, color=col, zorder=0)
        ax2.axhline(5, color="k", lw=2)
        ax2.set_title(f"{c0}, {v:.1f} m/s, seed {first}")
        ax2.set_xlabel("sideways (m)")
        ax2.set_ylim(-0.2, 5.2)
        ax2.legend(loc="lower right")
    axes[0][0].set_ylabel("true heading (deg, clockwise)")
    axes2[0][0].set_ylabel("towards the wall (m): normal / safe / dangerous")
    fig.tight_layout()
    fig.savefig(f"{d}/heading.png", dpi=110)
    fig2.tight_layout()
    fig2.savefig(f"{d}/paths.png", dpi=110)


if __name__ == "__main__":
    main(sys.argv[1])

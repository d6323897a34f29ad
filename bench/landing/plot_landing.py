#!/usr/bin/python3
"""Plots of aerie-bench-landing's output: touchdown scatter, success rate against wind,
TARGET_POSE error along the descent.   plot_landing.py DIR  (reads DIR/landings.csv and
DIR/descent.csv, writes DIR/touchdown.png, DIR/success_vs_wind.png, DIR/descent_error.png)"""
import csv
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def key(r):
    return f"{r['tracker']} {r['controller']} {r['world']} vib {r['vibration']}"


def main(out):
    landings = rows(f"{out}/landings.csv")
    descent = rows(f"{out}/descent.csv")

    # Touchdown points relative to the pad (error magnitude and yaw error), per configuration.
    fig, ax = plt.subplots(figsize=(6, 5))
    groups = defaultdict(list)
    for r in landings:
        if r["landed"] == "1":
            groups[f"{key(r)} wind {r['wind_m_s']}"].append(r)
    for name, rs in sorted(groups.items()):
        ax.scatter([float(r["touchdown_error_m"]) * 100 for r in rs], [float(r["yaw_error_deg"]) for r in rs],
                   s=12, label=name)
    ax.axvline(25, color="red", lw=0.8, ls="--")
    ax.axhline(10, color="red", lw=0.8, ls="--")
    ax.axhline(-10, color="red", lw=0.8, ls="--")
    ax.set_xlabel("touchdown error (cm, pad centre to touchdown point)")
    ax.set_ylabel("yaw error (deg, modulo the H's half turn)")
    ax.set_title("Touchdowns (dashed: success bounds)")
    ax.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(f"{out}/touchdown.png", dpi=120)

    # Success rate against wind.
    fig, ax = plt.subplots(figsize=(6, 4))
    by = defaultdict(lambda: defaultdict(list))
    for r in landings:
        by[key(r)][float(r["wind_m_s"])].append(int(r["success"]))
    for name, winds in sorted(by.items()):
        ws = sorted(winds)
        ax.plot(ws, [100 * sum(winds[w]) / len(winds[w]) for w in ws], marker="o", label=name)
    ax.set_xlabel("mean wind (m/s; gusts 0.3 x)")
    ax.set_ylabel("success (%)")
    ax.set_ylim(0, 105)
    ax.set_title("Landing success against wind")
    ax.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(f"{out}/success_vs_wind.png", dpi=120)

    # TARGET_POSE error against the height above the pad, during the descent.
    fig, axes = plt.subplots(1, 2, figsize=(9, 4))
    by = defaultdict(list)
    for r in descent:
        by[key(r)].append(r)
    for name, rs in sorted(by.items()):
        h = [float(r["height_m"]) for r in rs]
        xy = [100 * (float(r["err_x_m"]) ** 2 + float(r["err_y_m"]) ** 2) ** 0.5 for r in rs]
        z = [100 * abs(float(r["err_z_m"])) for r in rs]
        axes[0].scatter(h, xy, s=2, label=name)
        axes[1].scatter(h, z, s=2, label=name)
    axes[0].set_ylabel("|x, y error| (cm)")
    axes[1].set_ylabel("|z error| (cm)")
    for a in axes:
        a.set_xlabel("height above the pad (m)")
        a.invert_xaxis()
    axes[0].legend(fontsize=6, markerscale=4)
    fig.suptitle("TARGET_POSE error along the descent")
    fig.tight_layout()
    fig.savefig(f"{out}/descent_error.png", dpi=120)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])

#!/usr/bin/python3
"""Plots and table of aerie-bench-landing's output: touchdown scatter, success rate against
wind, TARGET_POSE error along the descent, one markdown row per configuration.
   plot_landing.py DIR  (reads DIR/landings.csv and DIR/descent.csv, writes DIR/touchdown.png,
   DIR/success_vs_wind.png, DIR/descent_error.png and DIR/summary.md)"""
import csv
import sys
from collections import defaultdict


def rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def success_and_errors(rs):
    """Successful runs among rs, and the sorted touchdown errors (cm) of those that landed."""
    ok = sum(int(r["success"]) for r in rs)
    return ok, sorted(100 * float(r["touchdown_error_m"]) for r in rs if r["landed"] == "1")


def mean(v):
    return sum(v) / len(v) if v else float("nan")


def key(r):
    return f"{r['tracker']} {r['controller']} {r['world']} vib {r['vibration']}"


def table(landings, descent):
    """One markdown row per configuration (tracker, controller, world, wind, vibration)."""
    conf = lambda r: (r["tracker"], r["controller"], r["world"], float(r["wind_m_s"]), r["vibration"])
    runs, desc = defaultdict(list), defaultdict(list)
    for r in landings:
        runs[conf(r)].append(r)
    for r in descent:
        desc[conf(r)].append(r)
    out = ["| tracker | controller | world | wind (m/s) | vibration | runs | success | touchdown error mean / p95 (cm) "
           "| time (s) | losses / run | TARGET_POSE RMSE x / y / z (cm), yaw (deg) | fitted poses only (box-only share) |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for k in sorted(runs):
        rs = runs[k]
        ok, err = success_and_errors(rs)
        landed = [r for r in rs if r["landed"] == "1"]
        p95 = err[min(len(err) - 1, max(0, -(-95 * len(err) // 100) - 1))] if err else float("nan")
        fitted = [r for r in desc[k] if r.get("fitted", "1") == "1"]
        rmse = lambda col, rs=desc[k]: mean([float(r[col]) ** 2 for r in rs]) ** 0.5
        box = 100 * (1 - len(fitted) / len(desc[k])) if desc[k] else float("nan")
        out.append(f"| {k[0]} | {k[1]} | {k[2]} | {k[3]:g} | {k[4]} | {len(rs)} | {ok}/{len(rs)} ({100 * ok / len(rs):.0f} %) "
                   f"| {mean(err):.1f} / {p95:.1f} | {mean([float(r['time_s']) for r in landed]):.1f} "
                   f"| {mean([int(r['losses']) for r in rs]):.2f} "
                   f"| {100 * rmse('err_x_m'):.2f} / {100 * rmse('err_y_m'):.2f} / {100 * rmse('err_z_m'):.2f}, "
                   f"{rmse('err_yaw_deg'):.2f} "
                   f"| {100 * rmse('err_x_m', fitted):.2f} / {100 * rmse('err_y_m', fitted):.2f} / "
                   f"{100 * rmse('err_z_m', fitted):.2f}, {rmse('err_yaw_deg', fitted):.2f} ({box:.1f} %) |")
    return "\n".join(out) + "\n"


def main(out):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    landings = rows(f"{out}/landings.csv")
    descent = rows(f"{out}/descent.csv")
    with open(f"{out}/summary.md", "w") as f:
        f.write(table(landings, descent))

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

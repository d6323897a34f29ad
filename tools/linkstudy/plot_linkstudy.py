#!/usr/bin/python3
"""Plots of aerie-linkstudy's OUT/study.csv: per workload and swept factor, the success rate,
the error metric and the operator's view age against the factor, one line per placement and
tracker. Usage: plot_linkstudy.py OUT"""
import csv
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402



def main(out):
    rows = list(csv.DictReader(open(f"{out}/study.csv")))
    # (workload, sweep) -> (placement, tracker) -> x -> [rows]
    groups = defaultdict(lambda: defaultdict(lambda: defaultdict(list)))
    for r in rows:
        sweep = r["sweep"]
        x = float(r[sweep])  # the swept factor's column
        groups[(r["workload"], sweep)][(r["placement"], r["tracker"])][x].append(r)
    for (workload, sweep), lines in groups.items():
        for what, ylabel, fn in (
                ("success", "success rate (%)", lambda rs: 100 * sum(int(r["success"]) for r in rs) / len(rs)),
                ("metric", {"landing": "touchdown error (cm)", "avoidance": "steady heading RMSE (deg)",
                            "replay": "AUC of the boxes the operator received"}[workload],
                 lambda rs: mean([float(r["value"]) * (100 if workload == "landing" else 1)
                                  for r in rs if float(r["value"]) >= 0])),
                ("view_age", "operator's view age, median (ms)",
                 lambda rs: mean([float(r["view_age_p50_ms"]) for r in rs if float(r["view_age_p50_ms"]) >= 0]))):
            fig, ax = plt.subplots(figsize=(6, 4))
            for (placement, tracker), by_x in sorted(lines.items()):
                xs = sorted(by_x)
                label = placement if tracker == "-" else f"{placement}, {tracker}"
                ax.plot(xs, [fn(by_x[x]) for x in xs], marker="o", label=label)
            ax.set_xlabel(sweep)
            ax.set_ylabel(ylabel)
            ax.set_title(f"{workload}: {what.replace('_', ' ')} against {sweep}")
            if what == "success":
                ax.set_ylim(-5, 105)
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7)
            fig.tight_layout()
            fig.savefig(f"{out}/{workload}_{what}_vs_{sweep}.png", dpi=90)
            plt.close(fig)


def mean(v):
    return sum(v) / len(v) if v else float("nan")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])

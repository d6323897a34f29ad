#!/usr/bin/python3
"""Best cost vs evaluations for each optimiser and stage (compare_optimisers output):
    /usr/bin/python3 bench/ceopt/plot_convergence.py OUT_DIR"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

out = sys.argv[1]
runs = {}
with open(os.path.join(out, "convergence.csv"), newline="") as f:
    for r in csv.DictReader(f):
        runs.setdefault((int(r["stage"]), r["optimiser"], r["seed"]), []).append((int(r["evaluations"]), float(r["best_cost"])))
colors = {"cross-entropy": "tab:red", "random": "tab:gray", "nlopt-crs2": "tab:blue", "nlopt-isres": "tab:green",
          "nlopt-direct-l": "tab:purple"}
fig, axes = plt.subplots(1, 2, figsize=(13, 5))
for stage, ax in zip((1, 2), axes):
    seen = set()
    for (s, opt, seed), pts in sorted(runs.items()):
        if s != stage:
            continue
        ax.plot([p[0] for p in pts], [p[1] for p in pts], color=colors.get(opt), alpha=0.8, lw=1.2,
                label=None if opt in seen else opt)
        seen.add(opt)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("cost evaluations")
    ax.set_ylabel("best cost so far (mean ITSE + penalties)")
    ax.set_title(f"stage {stage}: " + ("scaling factors" if stage == 1 else "membership functions"))
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
fig.tight_layout()
fig.savefig(os.path.join(out, "convergence.png"), dpi=110)

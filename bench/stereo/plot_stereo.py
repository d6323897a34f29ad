#!/usr/bin/python3
"""Bar charts of an aerie-bench-stereo run: CPU ms per pair and bad-2px per method.
Usage: plot_stereo.py RESULTS.csv OUT.png"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

rows = list(csv.DictReader(open(sys.argv[1])))
pairs = list(dict.fromkeys(r["pair"] for r in rows))
methods = list(dict.fromkeys(r["method"] for r in rows))
value = {(r["pair"], r["method"]): r for r in rows}
fig, ax = plt.subplots(1, 2, figsize=(14, 5))
width = 0.8 / len(methods)
x = np.arange(len(pairs))
for i, m in enumerate(methods):
    ms = [float(value[(p, m)]["ms"]) for p in pairs]
    bad2 = [float(value[(p, m)]["bad2"]) for p in pairs]
    ax[0].bar(x + i * width, ms, width, label=m)
    ax[1].bar(x + i * width, bad2, width, label=m)
for a, label in zip(ax, ["CPU ms per pair (single thread, best run)", "bad-2px (% of GT pixels with an estimate)"]):
    a.set_xticks(x + 0.4 - width / 2)
    a.set_xticklabels([p.replace("Middlebury_", "") for p in pairs], rotation=15)
    a.set_ylabel(label)
    a.legend(fontsize=8)
fig.tight_layout()
fig.savefig(sys.argv[2], dpi=100)

#!/usr/bin/python3
"""Plots bench_procman's results: deputy CPU overhead and order latency CDFs."""
import json
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

data = json.load(open(sys.argv[1]))
fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4))
names = list(data["deputy_cpu_percent"].keys())
a.barh(names, [data["deputy_cpu_percent"][n] for n in names], color="tab:blue")
a.set_xlabel("aerie-deputy CPU (% of one core)")
a.set_title("Deputy overhead")
for key, label in (("start_latency_ms", "order -> running"), ("stop_latency_ms", "order -> stopped")):
    v = sorted(data[key])
    if v:
        b.plot(v, [(i + 1) / len(v) for i in range(len(v))], label=f"{label} (median {v[len(v) // 2]:.1f} ms)")
b.set_xlabel("latency (ms)")
b.set_ylabel("fraction of trials")
b.set_title("Sheriff -> deputy order latency")
b.grid(alpha=0.3)
b.legend()
fig.tight_layout()
fig.savefig(sys.argv[2], dpi=100)

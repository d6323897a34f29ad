#!/usr/bin/python3
"""Plots bench_link's results: latency CDFs (same network vs through the link at zero
delay) and the relay throughput per message size."""
import json
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

data = json.load(open(sys.argv[1]))
fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4))
for key, label in (("direct_ms", "same network"), ("link_ms", "through aerie-link (0 ms configured)")):
    v = sorted(data[key])
    if v:
        a.plot(v, [(i + 1) / len(v) for i in range(len(v))], label=f"{label}: median {v[len(v) // 2]:.3f} ms")
a.set_xscale("log")
a.set_xlabel("latency (ms)")
a.set_ylabel("fraction of messages")
a.set_title("Added latency at zero configured delay")
a.grid(alpha=0.3, which="both")
a.legend(fontsize=8)
t = data["throughput"]
labels = [f"{x['size']} B" for x in t]
b.bar(labels, [x["msgs_per_s"] for x in t], color="tab:green")
for i, x in enumerate(t):
    b.text(i, x["msgs_per_s"], f"{x['mb_per_s']:.1f} MB/s\n{100 * x['delivered_fraction']:.0f}% delivered",
           ha="center", va="bottom", fontsize=8)
b.set_ylabel("messages/s relayed")
b.set_ylim(0, 1.25 * max(x["msgs_per_s"] for x in t))
b.set_title("Relay throughput when flooded")
fig.tight_layout()
fig.savefig(sys.argv[2], dpi=100)

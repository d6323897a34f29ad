#!/usr/bin/python3
"""Latency CSV of aerie-bench-capture-latency -> PNG (histogram and CDF per channel)."""
import csv
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

rows = list(csv.DictReader(open(sys.argv[1])))
by = {}
for r in rows:
    by.setdefault(r["channel"], []).append(float(r["latency_ms"]))
fig, ax = plt.subplots(1, 2, figsize=(10, 4))
for ch, v in sorted(by.items()):
    v.sort()
    ax[0].hist(v, bins=60, alpha=0.6, label=ch)
    ax[1].plot(v, [i / (len(v) - 1) for i in range(len(v))], label=ch)
ax[0].set_xlabel("latency (ms)")
ax[0].set_ylabel("messages")
ax[1].set_xlabel("latency (ms)")
ax[1].set_ylabel("fraction")
ax[1].grid(True)
for a in ax:
    a.legend()
fig.suptitle("LCM loopback latency, 752x480 stereo at 20 Hz (receive - publish stamp)")
fig.tight_layout()
fig.savefig(sys.argv[2], dpi=100)
print("wrote", sys.argv[2])

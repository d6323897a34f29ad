#!/usr/bin/python3
"""Plot of a VO run: aligned trajectory vs ground truth (top view and height) and the
position error over time. Usage: plot_vo.py RUN.csv OUT.png TITLE"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

csv, png, title = sys.argv[1], sys.argv[2], sys.argv[3]
d = np.genfromtxt(csv, delimiter=",", names=True)
t = d["t"] - d["t"][0]
err = np.sqrt((d["ex"] - d["gx"]) ** 2 + (d["ey"] - d["gy"]) ** 2 + (d["ez"] - d["gz"]) ** 2)
fig, ax = plt.subplots(1, 2, figsize=(12, 5))
ax[0].plot(d["gx"], d["gz"] if np.ptp(d["gz"]) > np.ptp(d["gy"]) else d["gy"], "k-", label="ground truth")
ax[0].plot(d["ex"], d["ez"] if np.ptp(d["gz"]) > np.ptp(d["gy"]) else d["ey"], "r-", label="Aerie VO (SE3 aligned)")
ax[0].set_aspect("equal", adjustable="datalim")
ax[0].set_xlabel("x (m)")
ax[0].set_ylabel("horizontal (m)")
ax[0].legend()
ax[0].set_title(title)
ax[1].plot(t, err * 100, "b-")
ax[1].set_xlabel("time (s)")
ax[1].set_ylabel("position error after alignment (cm)")
ax[1].set_title("ATE rmse %.1f mm" % (1000 * np.sqrt(np.mean(err ** 2))))
fig.tight_layout()
fig.savefig(png, dpi=100)

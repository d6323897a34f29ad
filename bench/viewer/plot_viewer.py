"""Bar chart of bench_viewer results: camera-pane and 3D-scene redraws per second and the
CPU they take, per case.  usage: plot_viewer.py DIR_OF_JSON OUT.png"""
import json
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

order = ["no-map", "floor", "rough", "rough-poses", "rough-poses-full-res", "full-redraw-no-map",
         "full-redraw-rough-full-res", "full-redraw-rough-full-res-msaa8"]
runs = {p.stem: json.loads(p.read_text()) for p in pathlib.Path(sys.argv[1]).glob("*.json")}
names = [n for n in order if n in runs]
x = range(len(names))
fig, ax = plt.subplots(figsize=(11, 4.5))
w = 0.27
ax.bar([i - w for i in x], [runs[n]["camera_pane_fps"] for n in names], w, label="camera pane redraws/s")
ax.bar(list(x), [runs[n]["scene_fps"] for n in names], w, label="3D scene redraws/s")
ax.bar([i + w for i in x], [runs[n]["cpu_percent_of_one_core"] / 5 for n in names], w,
       label="CPU (% of one core / 5)")
ax.axhline(20, color="k", lw=0.8, ls="--")
ax.text(len(names) - 0.5, 20.5, "20 Hz camera", ha="right", fontsize=8)
ax.set_xticks(list(x))
ax.set_xticklabels(names, rotation=20, ha="right", fontsize=8)
ax.set_ylabel("per second")
ax.set_title("aerie-viewer, 752x480 stereo at 20 Hz, 100k-voxel maps, software OpenGL (Xvfb)")
ax.legend(fontsize=8)
fig.tight_layout()
fig.savefig(sys.argv[2], dpi=110)

#!/usr/bin/python3
"""Success and precision plots (OTB style) from aerie-bench-track's curves.csv.

usage: plot_track.py OUT_DIR   -> OUT_DIR/success.png, OUT_DIR/precision.png,
                                  OUT_DIR/success_<SEQ>.png for each sequence
"""
import csv
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(out):
    curves = defaultdict(lambda: defaultdict(dict))  # curve -> tracker -> seq -> [(t, v)]
    with open(f"{out}/curves.csv") as f:
        for row in csv.DictReader(f):
            curves[row["curve"]][row["tracker"]].setdefault(row["sequence"], []).append(
                (float(row["threshold"]), float(row["value"])))
    sequences = sorted({s for t in curves["success"].values() for s in t})

    def mean_curve(per_seq):
        ts = [t for t, _ in next(iter(per_seq.values()))]
        vals = [sum(per_seq[s][i][1] for s in per_seq) / len(per_seq) for i in range(len(ts))]
        return ts, vals

    for curve, xlabel, title in (("success", "overlap threshold (IoU)", "Success plot (OTB one-pass)"),
                                 ("precision", "location error threshold (pixels)", "Precision plot (OTB one-pass)")):
        lines = []
        for tracker, per_seq in curves[curve].items():
            ts, vals = mean_curve(per_seq)
            key = sum(vals) / len(vals) if curve == "success" else vals[min(20, len(vals) - 1)]
            lines.append((key, tracker, ts, vals))
        lines.sort(reverse=True)
        plt.figure(figsize=(7, 5))
        for key, tracker, ts, vals in lines:
            style = "-" if not tracker.startswith("opencv-") else "--"
            label = f"{tracker} [{key:.3f}]"
            plt.plot(ts, vals, style, label=label, linewidth=2 if style == "-" else 1.2)
        plt.xlabel(xlabel)
        plt.ylabel("success rate" if curve == "success" else "precision")
        plt.title(f"{title}, mean over {len(sequences)} sequences")
        plt.ylim(0, 1.02)
        plt.grid(alpha=0.3)
        plt.legend(fontsize=8, loc="upper right" if curve == "success" else "lower right")
        plt.tight_layout()
        plt.savefig(f"{out}/{curve}.png", dpi=110)
        plt.close()

    for seq in sequences:
        plt.figure(figsize=(6, 4.5))
        for tracker, per_seq in sorted(curves["success"].items()):
            if seq not in per_seq:
                continue
            ts = [t for t, _ in per_seq[seq]]
            vals = [v for _, v in per_seq[seq]]
            style = "-" if not tracker.startswith("opencv-") else "--"
            plt.plot(ts, vals, style, label=f"{tracker} [{sum(vals) / len(vals):.3f}]")
        plt.title(f"Success plot: {seq}")
        plt.xlabel("overlap threshold (IoU)")
        plt.ylabel("success rate")
        plt.ylim(0, 1.02)
        plt.grid(alpha=0.3)
        plt.legend(fontsize=7)
        plt.tight_layout()
        plt.savefig(f"{out}/success_{seq}.png", dpi=100)
        plt.close()


if __name__ == "__main__":
    main(sys.argv[1])

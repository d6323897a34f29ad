#!/usr/bin/python3
"""Success and precision plots (OTB one-pass) from aerie-bench-ipsl's per-frame files.

usage: plot_ipsl.py OUT_DIR   (reads OUT_DIR/<tracker>/<SEQ>[.seedN].frames.csv,
                               writes OUT_DIR/success.png and OUT_DIR/precision.png)
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def load(out):
    """{tracker: {sequence: [(iou array, centre error array), ...]}} (synthetic sequences skipped)."""
    runs = {}
    for tracker in sorted(os.listdir(out)):
        folder = os.path.join(out, tracker)
        if not os.path.isdir(folder):
            continue
        for name in sorted(os.listdir(folder)):
            if not name.endswith(".frames.csv") or name.startswith("synthetic"):
                continue
            seq = name[: -len(".frames.csv")].split(".seed")[0]
            with open(os.path.join(folder, name)) as f:
                rows = list(csv.DictReader(f))
            iou = np.array([1.0] + [float(r["iou"]) for r in rows])  # frame 1 is the init box
            err = np.array([0.0] + [float(r["centre_error"]) for r in rows])
            runs.setdefault(tracker, {}).setdefault(seq, []).append((iou, err))
    return runs


def curve(runs, thresholds, index, above):
    """Mean over sequences of the mean over runs of the fraction of frames passing each threshold."""
    per_seq = []
    for seq_runs in runs.values():
        per_run = [[np.mean(r[index] > t) if above else np.mean(r[index] <= t) for t in thresholds] for r in seq_runs]
        per_seq.append(np.mean(per_run, axis=0))
    return np.mean(per_seq, axis=0)


def main():
    out = sys.argv[1]
    runs = load(out)
    if not runs:
        sys.exit(f"plot_ipsl: no <tracker>/*.frames.csv under {out}")
    overlap = np.linspace(0, 1, 21)
    pixels = np.arange(0, 51)
    for fname, xs, index, above, xlabel, metric in [
        ("success.png", overlap, 0, True, "overlap threshold (IoU)", lambda c: f"AUC {c.mean():.3f}"),
        ("precision.png", pixels, 1, False, "location error threshold (px)", lambda c: f"P@20 {c[20]:.3f}"),
    ]:
        plt.figure(figsize=(5, 4))
        for tracker, seqs in runs.items():
            c = curve(seqs, xs, index, above)
            plt.plot(xs, c, label=f"{tracker} [{metric(c)}]")
        plt.xlabel(xlabel)
        plt.ylabel("success rate" if above else "precision")
        plt.title(f"OTB one-pass, {len(next(iter(runs.values())))} sequences")
        plt.ylim(0, 1)
        plt.grid(alpha=0.3)
        plt.legend()
        plt.tight_layout()
        plt.savefig(os.path.join(out, fname), dpi=100)
        print(os.path.join(out, fname))


if __name__ == "__main__":
    main()

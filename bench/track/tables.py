#!/usr/bin/python3
"""Markdown tables from aerie-bench-track's output folders (docs/results/track.md).

usage: tables.py NATIVE_OUT [RESIZED_OUT]
  NATIVE_OUT:  a run with --folds (folds.csv, heldout_summary.csv, candidates.csv) and the per-run files
  RESIZED_OUT: the same trackers with --resize 640x480 (speed and accuracy side by side)

The last table compares each tracker with OpenCV's CSRT sequence by sequence on the held-out
AUC (each sequence scored with the candidate its fold chose on the other folds; with --starts,
the mean over the sequence's segments): the mean difference, the sequences won, and a 95 %
paired bootstrap interval of the mean difference (10,000 resamples of the sequences, seed 1):
how far the mean over this many sequences can be trusted to carry over to other footage of the
same kind.
"""
import csv
import os
import sys

import numpy as np

REFERENCE = "opencv-csrt"


def rows(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def f3(v):
    return f"{float(v):.3f}"


def heldout_per_sequence(native):
    """tracker -> sequence -> held-out AUC: the candidate chosen for the sequence's fold, averaged
    over the sequence's segments (SEQ, SEQ@frame, ... with --starts)."""
    chosen = {(r["tracker"], r["fold"]): r["candidate"] for r in rows(os.path.join(native, "folds.csv"))}
    segments = {}
    for r in rows(os.path.join(native, "candidates.csv")):
        if chosen.get((r["tracker"], r["fold"])) == r["candidate"]:
            segments.setdefault(r["tracker"], {}).setdefault(r["sequence"].split("@")[0], []).append(float(r["success_auc"]))
    return {t: {q: float(np.mean(v)) for q, v in per.items()} for t, per in segments.items()}


def paired_bootstrap(diff, resamples=10000, seed=1):
    """95 % interval of the mean of diff over resampled sets of the same size."""
    rng = np.random.default_rng(seed)
    means = diff[rng.integers(0, len(diff), size=(resamples, len(diff)))].mean(axis=1)
    return np.percentile(means, [2.5, 97.5])


def against_reference(native, order):
    per = heldout_per_sequence(native)
    if REFERENCE not in per:
        return
    seqs = sorted(per[REFERENCE])
    ref = np.array([per[REFERENCE][q] for q in seqs])
    print(f"| tracker | held-out AUC − {REFERENCE}'s, mean | sequences won | 95 % paired bootstrap interval |")
    print("|---|---|---|---|")
    for t in order:
        if t == REFERENCE or t not in per or sorted(per[t]) != seqs:
            continue
        diff = np.array([per[t][q] for q in seqs]) - ref
        lo, hi = paired_bootstrap(diff)
        print(f"| {t} | {diff.mean():+.3f} | {int((diff > 0).sum())} / {len(seqs)} | {lo:+.3f} … {hi:+.3f} |")
    print()
    shown = [t for t in ("eco", "dcf") if t in per]
    print("| sequence | " + " | ".join(shown) + f" | {REFERENCE} |")
    print("|---|" + "---|" * (len(shown) + 1))
    for q in seqs:
        print(f"| {q} | " + " | ".join(f3(per[t][q]) for t in shown) + f" | {f3(per[REFERENCE][q])} |")


def main(native, resized=None):
    summary = {r["tracker"]: r for r in rows(os.path.join(native, "summary.csv"))}
    held = {r["tracker"]: r for r in rows(os.path.join(native, "heldout_summary.csv"))}
    small = {r["tracker"]: r for r in rows(os.path.join(resized, "summary.csv"))} if resized else {}
    order = sorted(summary, key=lambda t: -float(held[t]["heldout_auc"] if t in held else summary[t]["mean_success_auc"]))
    print("| tracker | held-out AUC | P@20 | CLE (px) | tuned-on AUC | P@20 | CLE (px) | cpu fps native |"
          + (" AUC 640×480 | cpu fps 640×480 |" if small else ""))
    print("|---|---|---|---|---|---|---|---|" + ("---|---|" if small else ""))
    for t in order:
        h, s = held.get(t), summary[t]
        line = f"| {t} | {f3(h['heldout_auc'])} | {f3(h['heldout_p20'])} | {float(h['heldout_cle']):.1f} | " \
               f"{f3(h['tuned_auc'])} | {f3(h['tuned_p20'])} | {float(h['tuned_cle']):.1f} | {float(s['mean_cpu_fps']):.0f} |"
        if small:
            line += (f" {f3(small[t]['mean_success_auc'])} | {float(small[t]['mean_cpu_fps']):.0f} |" if t in small
                     else " — | — |")
        print(line)
    print()
    print("| tracker | fold | candidate chosen | tuned-on AUC | held-out AUC |")
    print("|---|---|---|---|---|")
    for r in rows(os.path.join(native, "folds.csv")):
        if r["tracker"] in ("eco", "dcf"):
            print(f"| {r['tracker']} | {r['fold']} | {r['candidate']}: `{r['settings']}` | {f3(r['tuned_auc'])} | {f3(r['heldout_auc'])} |")
    print()
    attrs = rows(os.path.join(native, "attributes.csv"))
    names = sorted({a["attribute"] for a in attrs})
    counts = {a["attribute"]: a["sequences"] for a in attrs}
    print("| tracker | " + " | ".join(f"{n} ({counts[n]} seq.)" for n in names) + " |")
    print("|---|" + "---|" * len(names))
    by = {(a["tracker"], a["attribute"]): a for a in attrs}
    for t in order:
        print(f"| {t} | " + " | ".join(f3(by[(t, n)]["mean_success_auc"]) if (t, n) in by else "" for n in names) + " |")
    print()
    lost = [r for r in rows(os.path.join(native, "lost.csv")) if r["sequence"] == "ALL"]
    print("| tracker | lost episodes | flagged within 5 frames | recall | frames IoU > 0.5 | flagged | false-alarm rate |")
    print("|---|---|---|---|---|---|---|")
    for r in sorted(lost, key=lambda r: -float(r["recall"]) if r["recall"] != "nan" else 1):
        print(f"| {r['tracker']} | {r['episodes']} | {r['flagged']} | {r['recall'][:5]} | {r['frames_iou_gt_05']} | "
              f"{r['false_alarms']} | {r['false_alarm_rate'][:6]} |")
    print()
    against_reference(native, order)


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:3]) if len(sys.argv) in (2, 3) else print(__doc__) or 2)

#!/usr/bin/python3
"""Choose the LOST flag's rule on one set of tracked sequences, report it on another.

The rule: lost once the tracker's confidence has stayed below `lost_confidence` for
`lost_after` frames in a row. The flag does not change the track (the learning gate is a
separate setting), so every rule is scored on the confidence series that aerie-bench-track
--states wrote: recall = share of lost episodes (ground truth absent or IoU = 0, maximal runs)
flagged within 5 frames of their start; false-alarm rate = share of frames with IoU > 0.5
flagged. The chosen rule has the largest recall - false-alarm rate on the tuning set (Youden's
J; ties: fewer false alarms); the script also prints the trade-off of every threshold on both
sets and plots it (lost_rule_TRACKER.png in REPORT_OUT).

Also reported for both sets: re-acquisition after the target was out of view (ground truth
absent): the share of re-entries after which the track reaches IoU > 0.5 before the target
leaves again or the sequence ends, and the median and largest number of frames that took.

usage: lost_rule.py TRACKER TUNE_OUT REPORT_OUT   (the --out folders of two --states runs)
"""
import csv
import glob
import math
import os
import sys


def series(out, tracker):
    runs = []
    for path in sorted(glob.glob(os.path.join(out, tracker, "*.states.csv"))):
        with open(path) as f:
            rows = list(csv.DictReader(f))
        runs.append(([float(r["confidence"]) for r in rows], [float(r["iou"]) for r in rows]))
    return runs


def score(runs, threshold, after, within=5):
    episodes = flagged = frames_ok = alarms = 0
    for conf, iou in runs:
        below = 0
        flags = []
        for c in conf:
            below = below + 1 if c < threshold else 0
            flags.append(below >= after)
        lost = [math.isnan(v) or v == 0 for v in iou]
        i = 0
        while i < len(lost):
            if lost[i]:
                j = i
                while j < len(lost) and lost[j]:
                    j += 1
                episodes += 1
                flagged += any(flags[i:min(j, i + within)])
                i = j
            else:
                i += 1
        for f, v in zip(flags, iou):
            if not math.isnan(v) and v > 0.5:
                frames_ok += 1
                alarms += f
    return episodes, flagged, frames_ok, alarms


def reacquisition(runs):
    delays, missed = [], 0
    for _, iou in runs:
        absent = [math.isnan(v) for v in iou]
        i = 0
        while i < len(iou):
            if absent[i] and i + 1 < len(iou) and not absent[i + 1]:
                j = i + 1  # the target is back
                while j < len(iou) and not absent[j] and not iou[j] > 0.5:
                    j += 1
                if j < len(iou) and not absent[j]:
                    delays.append(j - (i + 1))
                else:
                    missed += 1
            i += 1
    if not delays and not missed:
        return "no re-entries"
    delays.sort()
    median = delays[len(delays) // 2] if delays else float("nan")
    return (f"re-acquired {len(delays)}/{len(delays) + missed} re-entries, median {median} frames, "
            f"largest {max(delays) if delays else float('nan')}")


def fmt(s):
    e, f, n, a = s
    return f"recall {f}/{e} = {f / e if e else float('nan'):.3f}, false alarms {a}/{n} = {a / n if n else float('nan'):.4f}"


def rates(s):
    e, f, n, a = s
    return (f / e if e else float("nan")), (a / n if n else float("nan"))


def main(tracker, tune, report):
    tune_runs, report_runs = series(tune, tracker), series(report, tracker)
    thresholds = [x / 100 for x in range(5, 61, 5)]
    rules = [(t, k) for t in thresholds for k in (1, 2, 3, 4)]
    tuned = {r: score(tune_runs, *r) for r in rules}
    best = max(rules, key=lambda r: (rates(tuned[r])[0] - rates(tuned[r])[1], -rates(tuned[r])[1]))
    t, k = best
    print("lost_confidence  lost_after | tuning recall  false alarms | report recall  false alarms")
    for r in rules:
        if r[1] in (1, k):
            (rt, ft), (rr, fr) = rates(tuned[r]), rates(score(report_runs, *r))
            print(f"{r[0]:15.2f} {r[1]:11d} | {rt:13.3f} {ft:13.4f} | {rr:13.3f} {fr:13.4f}{'  <- chosen' if r == best else ''}")
    print(f"chosen on {tune}: lost_confidence {t}, lost_after {k}")
    print(f"  tuned on : {fmt(tuned[best])}")
    print(f"  reported : {fmt(score(report_runs, t, k))}")
    print(f"  re-acquisition, tuning set : {reacquisition(tune_runs)}")
    print(f"  re-acquisition, report set : {reacquisition(report_runs)}")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(5, 4))
        for runs, label in ((tune_runs, f"tuning ({os.path.basename(tune.rstrip('/'))})"),
                            (report_runs, f"report ({os.path.basename(report.rstrip('/'))})")):
            pts = [rates(score(runs, th, k)) for th in thresholds]
            ax.plot([p[1] for p in pts], [p[0] for p in pts], "o-", label=label)
        ax.axvline(0.02, color="grey", ls=":")
        ax.axhline(0.9, color="grey", ls=":")
        ax.set_xlabel("false-alarm rate (frames with IoU > 0.5 flagged)")
        ax.set_ylabel("recall (episodes flagged within 5 frames)")
        ax.set_title(f"{tracker}: LOST flag, lost_after {k}, lost_confidence 0.05..0.6")
        ax.legend()
        fig.tight_layout()
        fig.savefig(os.path.join(report, f"lost_rule_{tracker}.png"), dpi=100)
    except ImportError:
        pass
    return 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:4]) if len(sys.argv) == 4 else print(__doc__) or 2)

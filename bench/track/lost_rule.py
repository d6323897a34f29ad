#!/usr/bin/python3
"""Choose the LOST flag's rule on one set of tracked sequences, report it on another.

The rule: lost once the tracker's confidence has stayed below `lost_confidence` for
`lost_after` frames in a row, or (ECO's appearance verifier, when traced) once the verifier's
similarity has stayed below `verify_threshold` for `verify_after` frames in a row. The flag does
not change the track (the learning gate is a separate setting), so every rule is scored on the
series that aerie-bench-track --states wrote: recall = share of lost episodes (ground truth
absent or IoU = 0, maximal runs) flagged within 5 frames of their start; false-alarm rate = share
of frames with IoU > 0.5 flagged. A rule is chosen as issue 15 states its targets, recall first: among
the rules with a recall of at least 90 % on the tuning set, the one with the fewest false alarms
there (ties: the higher recall); when none reaches 90 %, the largest recall - false-alarm rate
(Youden's J, the criterion until 2026-11-27). First the confidence rule alone (as before the verifier),
then the verifier's threshold and run length beside it ("no verifier" among the choices): that
pair is the rule ECO flies. The verifier alone and both parts chosen together are printed for
information. The script also prints the trade-off of every threshold on both sets and plots it
(lost_rule_TRACKER.png in REPORT_OUT).

The verifier's similarity is not a column of .states.csv; it is traced through the bench's
candidates instead: `lost_rule.py grid > FILE` prints a --grid in which candidate 0 is the
tracker's section as it is and candidate c >= 1 sets verify_threshold to VERIFY_THRESHOLDS[c-1],
verify_after 1 and lost_confidence 0, so that its `lost` column is "similarity < threshold" on
every frame. Run both sets with `--states --folds 2 --grid FILE`; the script reads
TRACKER#c/*.states.csv, checks that every candidate's IoU series is candidate 0's (the verifier
changes the flag, never the box), and scores every combined rule. Without those folders only the
confidence rule is chosen, as before.

Also reported for both sets: re-acquisition after the target was out of view (ground truth
absent): the share of re-entries after which the track reaches IoU > 0.5 before the target
leaves again or the sequence ends, and the median and largest number of frames that took.

usage: lost_rule.py TRACKER TUNE_OUT REPORT_OUT   (the --out folders of two --states runs)
       lost_rule.py grid                          (the tracing grid for aerie-bench-track --grid)
"""
import csv
import glob
import math
import os
import sys

CONFIDENCE_THRESHOLDS = [x / 100 for x in range(2, 61, 2)]
MIN_RECALL = 0.9  # issue 15's recall target
CONFIDENCE_AFTER = (1, 2, 3, 4)
VERIFY_THRESHOLDS = [x / 100 for x in range(10, 81, 5)]
VERIFY_AFTER = (1, 2, 3, 4, 5)
OFF = None


def grid():
    print("# The tracing grid of bench/track/lost_rule.py: candidate c >= 1 flags lost exactly when the")
    print("# verifier's similarity is below VERIFY_THRESHOLDS[c - 1] (the confidence rule switched off).")
    print("eco:\n  - {}")
    for t in VERIFY_THRESHOLDS:
        print(f"  - {{verify_threshold: {t}, verify_after: 1, lost_confidence: 0}}")


def read(path, column):
    with open(path) as f:
        return [float(r[column]) for r in csv.DictReader(f)]


def series(out, tracker):
    """Per sequence: (confidence, iou, below) with below[c][i] = similarity < VERIFY_THRESHOLDS[c]
    on frame i, or below None when the verifier was not traced."""
    runs = []
    traced = all(os.path.isdir(os.path.join(out, f"{tracker}#{c + 1}")) for c in range(len(VERIFY_THRESHOLDS)))
    for path in sorted(glob.glob(os.path.join(out, tracker, "*.states.csv"))):
        conf, iou = read(path, "confidence"), read(path, "iou")
        below = None
        if traced:
            below = []
            for c in range(len(VERIFY_THRESHOLDS)):
                other = os.path.join(out, f"{tracker}#{c + 1}", os.path.basename(path))
                o_iou = read(other, "iou")
                if any(not (a == b or (math.isnan(a) and math.isnan(b))) for a, b in zip(o_iou, iou)) or len(o_iou) != len(iou):
                    sys.exit(f"{other}: the track differs from candidate 0's: the verifier must not move the box")
                below.append([v != 0 for v in read(other, "lost")])
            for c in range(1, len(below)):  # a lower threshold flags a subset of the frames
                if any(a and not b for a, b in zip(below[c - 1], below[c])):
                    sys.exit(f"{path}: the traced similarity is not monotone in the threshold")
        runs.append((conf, iou, below))
    return runs, traced


def runs_of(values, after):
    n, flags = 0, []
    for v in values:
        n = n + 1 if v else 0
        flags.append(n >= after)
    return flags


def score(runs, rule, within=5):
    """rule = (lost_confidence, lost_after, verify_index, verify_after); a threshold None = off."""
    t, k, vi, vk = rule
    episodes = flagged = frames_ok = alarms = 0
    for conf, iou, below in runs:
        flags = runs_of([c < t for c in conf], k) if t is not None else [False] * len(conf)
        if vi is not None:
            flags = [a or b for a, b in zip(flags, runs_of(below[vi], vk))]
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
    for _, iou, _ in runs:
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


def describe(rule):
    t, k, vi, vk = rule
    parts = []
    if t is not None:
        parts.append(f"lost_confidence {t}, lost_after {k}")
    if vi is not None:
        parts.append(f"verify_threshold {VERIFY_THRESHOLDS[vi]}, verify_after {vk}")
    return " OR ".join(parts) if parts else "never"


def choose(scored):
    recalled = [r for r in scored if rates(scored[r])[0] >= MIN_RECALL]
    if recalled:
        return min(recalled, key=lambda r: (rates(scored[r])[1], -rates(scored[r])[0]))
    return max(scored, key=lambda r: (rates(scored[r])[0] - rates(scored[r])[1], -rates(scored[r])[1]))


def table(header, rules, label, best, tune_runs, report_runs):
    """One row per rule: its label, then recall and false alarms on both sets."""
    print(header)
    for r in rules:
        (rt, ft), (rr, fr) = rates(score(tune_runs, r)), rates(score(report_runs, r))
        print(f"{label(r)} | {rt:13.3f} {ft:13.4f} | {rr:13.3f} {fr:13.4f}{'  <- chosen' if r == best else ''}")


def summary(title, scored, best, report_runs):
    """The rule chosen on the tuning set (scored), its figures there and on the report set."""
    print(f"{title}: {describe(best)}")
    print(f"  tuned on : {fmt(scored[best])}")
    print(f"  reported : {fmt(score(report_runs, best))}")


def main(tracker, tune, report):
    (tune_runs, tune_traced), (report_runs, report_traced) = series(tune, tracker), series(report, tracker)
    traced = tune_traced and report_traced
    conf_rules = [(t, k) for t in CONFIDENCE_THRESHOLDS for k in CONFIDENCE_AFTER]
    verify_rules = [(vi, vk) for vi in range(len(VERIFY_THRESHOLDS)) for vk in VERIFY_AFTER] if traced else []

    # The confidence rule alone (the rule before the verifier).
    alone = {(t, k, OFF, OFF): score(tune_runs, (t, k, OFF, OFF)) for t, k in conf_rules}
    best_alone = choose(alone)
    table("lost_confidence  lost_after | tuning recall  false alarms | report recall  false alarms",
          [r for r in alone if r[1] in (1, best_alone[1])], lambda r: f"{r[0]:15.2f} {r[1]:11d}", best_alone,
          tune_runs, report_runs)
    summary(f"confidence alone, chosen on {tune}", alone, best_alone, report_runs)
    best = best_alone
    if traced:
        # The verifier alone, then beside the confidence rule, all chosen on the tuning set.
        only = {(OFF, OFF, vi, vk): score(tune_runs, (OFF, OFF, vi, vk)) for vi, vk in verify_rules}
        best_only = choose(only)
        table("\nverify_threshold  verify_after | tuning recall  false alarms | report recall  false alarms  (verifier alone)",
              [r for r in only if r[3] in (1, best_only[3])], lambda r: f"{VERIFY_THRESHOLDS[r[2]]:16.2f} {r[3]:13d}",
              best_only, tune_runs, report_runs)
        summary(f"verifier alone, chosen on {tune}", only, best_only, report_runs)
        # The verifier beside the confidence rule chosen above (the rule ECO flies): its threshold
        # and run length chosen on the tuning set, "off" among the choices.
        t, k = best_alone[0], best_alone[1]
        beside = {best_alone: alone[best_alone]}
        for vi, vk in verify_rules:
            beside[(t, k, vi, vk)] = score(tune_runs, (t, k, vi, vk))
        best = choose(beside)
        summary(f"\nconfidence rule OR verifier, the verifier chosen on {tune}", beside, best, report_runs)
        # For information: both rules chosen together (not what is flown).
        joint = dict(alone)
        joint.update(only)
        for ct, ck in conf_rules:
            for vi, vk in verify_rules:
                joint[(ct, ck, vi, vk)] = score(tune_runs, (ct, ck, vi, vk))
        best_joint = choose(joint)
        summary(f"both chosen together on {tune} among {len(joint)} rules (for information)", joint, best_joint,
                report_runs)
        print("  every verifier threshold beside the confidence rule, at the chosen verify_after, on both sets:")
        vk = best[3] if best[3] is not None else 1
        table("  verify_threshold | tuning recall  false alarms | report recall  false alarms",
              [(t, k, vi, vk) for vi in range(len(VERIFY_THRESHOLDS))], lambda r: f"  {VERIFY_THRESHOLDS[r[2]]:16.2f}",
              best, tune_runs, report_runs)
    print(f"  re-acquisition, tuning set : {reacquisition(tune_runs)}")
    print(f"  re-acquisition, report set : {reacquisition(report_runs)}")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(5.5, 4.5))
        for runs, label, colour in ((tune_runs, f"tuning ({os.path.basename(tune.rstrip('/'))})", "C0"),
                                    (report_runs, f"report ({os.path.basename(report.rstrip('/'))})", "C1")):
            kk = best_alone[1]
            pts = [rates(score(runs, (th, kk, OFF, OFF))) for th in CONFIDENCE_THRESHOLDS]
            ax.plot([p[1] for p in pts], [p[0] for p in pts], "o-", color=colour,
                    label=f"{label}: confidence {CONFIDENCE_THRESHOLDS[0]}..{CONFIDENCE_THRESHOLDS[-1]}, lost_after {kk}")
            if traced and best[2] is not None:
                pts = [rates(score(runs, (best[0], best[1], vi, best[3]))) for vi in range(len(VERIFY_THRESHOLDS))]
                ax.plot([p[1] for p in pts], [p[0] for p in pts], "s--", color=colour,
                        label=f"{label}: + verifier {VERIFY_THRESHOLDS[0]}..{VERIFY_THRESHOLDS[-1]}, after {best[3]}")
            for rule, marker in ((best_alone, "*"), (best, "X")):
                p = rates(score(runs, rule))
                ax.plot([p[1]], [p[0]], marker, color=colour, ms=12, mec="k")
        ax.set_xlim(-0.005, min(ax.get_xlim()[1], 0.15))  # the region of the targets; higher thresholds run off
        ax.axvline(0.02, color="grey", ls=":")
        ax.axhline(0.9, color="grey", ls=":")
        ax.set_xlabel("false-alarm rate (frames with IoU > 0.5 flagged)")
        ax.set_ylabel("recall (episodes flagged within 5 frames)")
        ax.set_title(f"{tracker}: LOST flag (* confidence rule, X combined; chosen on tuning)", fontsize=9)
        ax.legend(fontsize=6)
        fig.tight_layout()
        fig.savefig(os.path.join(report, f"lost_rule_{tracker}.png"), dpi=100)
    except ImportError:
        pass
    return 0


if __name__ == "__main__":
    if sys.argv[1:] == ["grid"]:
        sys.exit(grid())
    sys.exit(main(*sys.argv[1:4]) if len(sys.argv) == 4 else print(__doc__) or 2)

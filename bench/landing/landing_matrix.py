#!/usr/bin/python3
"""One markdown table over any number of aerie-bench-landing CSVs: a row per tracker, controller,
world and vibration, a column per wind, each cell "success % / mean touchdown error (cm)" of
the landings of that configuration (the mean over the landed runs, as in summary.md), with the
number of runs when the configurations differ in it.
   landing_matrix.py LANDINGS.csv [LANDINGS.csv ...] > matrix.md
A configuration that appears in two files (the same seed twice) is refused."""
import sys
from collections import defaultdict

from plot_landing import mean, rows, success_and_errors


def main(paths):
    runs = defaultdict(list)
    winds = set()
    seen = set()
    for path in paths:
        for r in rows(path):
            conf = (r["tracker"], r["controller"], r["world"], r["vibration"])
            wind = float(r["wind_m_s"])
            run = conf + (wind, r["seed"])
            if run in seen:
                sys.exit(f"landing_matrix.py: {path}: seed {r['seed']} of {' '.join(conf)} wind {wind:g} "
                         "appears twice")
            seen.add(run)
            runs[conf + (wind,)].append(r)
            winds.add(wind)
    winds = sorted(winds)
    counts = {len(rs) for rs in runs.values()}
    print("| tracker | controller | world | vibration | "
          + " | ".join(f"wind {w:g} m/s" for w in winds) + " |")
    print("|---|---|---|---|" + "---|" * len(winds))
    for conf in sorted({k[:4] for k in runs}):
        cells = []
        for w in winds:
            rs = runs.get(conf + (w,))
            if not rs:
                cells.append("–")
                continue
            ok, err = success_and_errors(rs)
            cells.append(f"{100 * ok / len(rs):.0f} % / {mean(err):.1f}" + (f" ({len(rs)} runs)" if len(counts) > 1 else ""))
        print(f"| {' | '.join(conf)} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] in ("-h", "--help"):
        print(__doc__)
        sys.exit(0)
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])

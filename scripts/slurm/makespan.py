#!/usr/bin/python3
"""A simulation of aerie-bench-landing's MPI hand-out (tools/study, docs/scale.md) over measured
run times: every rank (rank 0 too) takes the next run in index order when it is free, each
hand-out costing OVERHEAD seconds; prints, for each number of ranks, the makespan, the parallel
efficiency (total run time / (ranks x makespan)) and, for comparison, those of a static split
into equal contiguous blocks of runs. The run times are the wall_s column of landings CSVs, put
in the study's index order (world, tracker, controller, via, wind, vibration, then seed).
   makespan.py [--ranks 16,64,256] [--overhead S] LANDINGS.csv [LANDINGS.csv ...]
This is a simulation with those times, not a measurement on a cluster."""
import csv
import heapq
import sys


def runs_in_index_order(paths):
    rows = []
    for path in paths:
        with open(path, newline="") as f:
            rows += list(csv.DictReader(f))
    key = lambda r: (r["world"], r["tracker"], r["controller"], r.get("via", "direct"), float(r["wind_m_s"]),
                     r["vibration"] == "off", int(r["seed"]))
    return [float(r["wall_s"]) for r in sorted(rows, key=key)]


def dynamic(times, ranks, overhead):
    free = [0.0] * ranks  # when each rank is next free
    heapq.heapify(free)
    end = 0.0
    for t in times:
        start = heapq.heappop(free)
        done = start + overhead + t
        end = max(end, done)
        heapq.heappush(free, done)
    return end


def static(times, ranks):
    n = len(times)
    return max(sum(times[n * k // ranks: n * (k + 1) // ranks]) for k in range(ranks))


def main(argv):
    ranks, overhead, paths = [16, 64, 256], 0.0, []
    it = iter(argv)
    for a in it:
        if a == "--ranks":
            ranks = [int(x) for x in next(it).split(",")]
        elif a == "--overhead":
            overhead = float(next(it))
        elif a in ("-h", "--help"):
            print(__doc__)
            return 0
        elif a.startswith("-"):
            print(f"makespan.py: unknown option {a}", file=sys.stderr)
            return 2
        else:
            paths.append(a)
    if not paths:
        print(__doc__, file=sys.stderr)
        return 2
    times = runs_in_index_order(paths)
    total = sum(times)
    s = sorted(times)
    print(f"{len(times)} runs, {total / 3600:.2f} h of one core; run time median {s[len(s) // 2]:.2f} s, "
          f"p95 {s[int(0.95 * (len(s) - 1))]:.2f} s, max {s[-1]:.2f} s; hand-out overhead {overhead * 1e3:.2f} ms/run")
    print("| ranks | dynamic makespan | efficiency | static split makespan | efficiency | bound max(total/ranks, longest run) |")
    print("|---|---|---|---|---|---|")
    for r in ranks:
        d, st = dynamic(times, r, overhead), static(times, r)
        bound = max(total / r, s[-1])
        print(f"| {r} | {d / 60:.1f} min | {100 * total / (r * d):.1f} % | {st / 60:.1f} min | "
              f"{100 * total / (r * st):.1f} % | {bound / 60:.1f} min |")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

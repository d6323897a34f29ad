#!/usr/bin/env python3
"""Turns bench/arm/arm-cost.sh's raw.tsv into per_frame.tsv and table.md.

usage: summarise.py RAW_TSV OUT_DIR

For every (arch, case) the two most recent rows with different frame counts N1 < N2 give
instructions per frame = (insns(N2) - insns(N1)) / (N2 - N1). Heap figures come from the
driver's output line of the N2 run (node_heap = heap peak - heap after the frames were
prepared). x86-native rows give CPU seconds per frame = (cpu(N2) - cpu(N1)) / (N2 - N1) and
the max RSS of the N2 run (CPU time: the driver's loop_cpu_s where it prints one, else
/usr/bin/time's user + sys, in the raw file's wall_s column for these rows).

The frames/s estimates: fps = clock x IPC / (instructions per frame), for the board cores below
with an IPC range (low, high) each; see docs/arm.md for where the ranges come from.
"""
import csv
import os
import sys
from collections import defaultdict

# name, arch whose counts are used, clock GHz, IPC low, IPC high
BOARDS = [
    ("Pi 4 (Cortex-A72, 1.5 GHz)", "arm64", 1.5, 0.7, 1.4),
    ("Pi 4 (Cortex-A72, 1.8 GHz)", "arm64", 1.8, 0.7, 1.4),
    ("Pi 5 (Cortex-A76, 2.4 GHz)", "arm64", 2.4, 1.0, 2.1),
    ("U3 (Cortex-A9, 1.7 GHz), armhf build", "armhf", 1.7, 0.5, 0.9),
]
HOST_GHZ = 2.6  # /proc/cpuinfo "cpu MHz" of this VM's AMD EPYC (its boost clock is not visible)


def parse_line(s):
    d = {}
    for tok in (s or "").split():
        if "=" in tok:
            k, v = tok.split("=", 1)
            d[k] = v
    return d


def main():
    raw, out = sys.argv[1], sys.argv[2]
    rows = list(csv.DictReader(open(raw), delimiter="\t"))
    by = defaultdict(list)
    for r in rows:
        by[(r["arch"], r["case"])].append(r)
    res = {}
    order = []
    for key, rs in by.items():
        # the most recent row per frame count, then the two most recent frame counts
        latest = {}
        for r in rs:
            latest[int(r["frames"])] = r
        if len(latest) < 2:
            continue
        ns = sorted(latest, key=lambda n: latest[n]["date"])[-2:]
        n1, n2 = sorted(ns)
        r1, r2 = latest[n1], latest[n2]
        info = parse_line(r2["program_output"])
        e = {"n1": n1, "n2": n2, "info": info, "rss_kb": r2["qemu_maxrss_kb"]}
        if key[0] == "x86-native":
            # the driver's own CPU time of its processing loop (clock_gettime) where there is one,
            # else /usr/bin/time's user + sys of the whole process (10 ms resolution)
            l1, l2 = parse_line(r1["program_output"]).get("loop_cpu_s"), info.get("loop_cpu_s")
            if l1 and l2:
                e["cpu_per_frame"] = (float(l2) - float(l1)) / (n2 - n1)
            else:
                e["cpu_per_frame"] = (float(r2["wall_s"]) - float(r1["wall_s"])) / (n2 - n1)
        else:
            if not r1["insns"] or not r2["insns"]:
                continue
            e["insns"] = (int(r2["insns"]) - int(r1["insns"])) / (n2 - n1)
            e["threads"] = r2["threads"]
        res[key] = e
        if key[1] not in order:
            order.append(key[1])
    case_order = [r["case"] for r in rows]
    order.sort(key=lambda c: case_order.index(c))

    def g(arch, case, f, default=None):
        return res.get((arch, case), {}).get(f, default)

    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "per_frame.tsv"), "w") as f:
        f.write("case\tarch\tN1\tN2\tinsns_per_frame\tthreads\tnode_heap_MB\tqemu_or_native_maxrss_MB\tcpu_ms_per_frame\n")
        for c in order:
            for a in ("arm64", "armhf", "x86", "x86-native"):
                e = res.get((a, c))
                if not e:
                    continue
                heap = e["info"].get("node_heap_bytes")
                f.write("\t".join(str(x) for x in [
                    c, a, e["n1"], e["n2"], f"{e['insns']:.0f}" if "insns" in e else "", e.get("threads", ""),
                    f"{int(heap) / 2**20:.1f}" if heap else "", f"{int(e['rss_kb']) / 1024:.0f}" if e["rss_kb"] else "",
                    f"{e['cpu_per_frame'] * 1e3:.2f}" if "cpu_per_frame" in e else ""]) + "\n")

    L = []
    L.append("Instructions per frame (millions; difference of two runs / frames), the node's heap, x86 native time\n")
    L.append("| case | arm64 (NEON, cortex-a72) | armhf (scalar, cortex-a9) | x86 (qemu max: AVX2) | arm64 / x86 | "
             "node heap arm64 / armhf (MB) | x86 native max RSS (MB) | of it prepared frames (MB) | "
             "x86 native CPU ms/frame | x86 G instr/s (IPC at %.1f GHz) |" % HOST_GHZ)
    L.append("|---|---|---|---|---|---|---|---|---|---|")
    for c in order:
        a64, ahf, x = g("arm64", c, "insns"), g("armhf", c, "insns"), g("x86", c, "insns")
        cpu = g("x86-native", c, "cpu_per_frame")
        def heap(arch):
            h = (g(arch, c, "info") or {}).get("node_heap_bytes")
            return f"{int(h) / 2**20:.1f}" if h else "–"
        ninfo = g("x86-native", c, "info") or {}
        rss = g("x86-native", c, "rss_kb")
        prep = (int(ninfo["heap_prepared_bytes"]) - int(ninfo["heap_start_bytes"])) if "heap_prepared_bytes" in ninfo else None
        rate = x / cpu if x and cpu and cpu > 0 else None
        L.append("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
            c, f"{a64 / 1e6:.2f}" if a64 else "–", f"{ahf / 1e6:.2f}" if ahf else "–", f"{x / 1e6:.2f}" if x else "–",
            f"{a64 / x:.2f}" if a64 and x else "–", heap("arm64") + " / " + heap("armhf"),
            f"{int(rss) / 1024:.0f}" if rss else "–", f"{prep / 2**20:.0f}" if prep is not None else "–",
            f"{cpu * 1e3:.2f}" if cpu else "–", f"{rate / 1e9:.1f} ({rate / (HOST_GHZ * 1e9):.1f})" if rate else "–"))
    L.append("")
    L.append("Estimated frames/s per core = clock x IPC / instructions per frame (IPC low – high)\n")
    L.append("| case | " + " | ".join(b[0] for b in BOARDS) + " |")
    L.append("|---|" + "---|" * len(BOARDS))
    for c in order:
        cells = []
        for name, arch, ghz, lo, hi in BOARDS:
            n = g(arch, c, "insns")
            cells.append(f"{ghz * 1e9 * lo / n:.0f} – {ghz * 1e9 * hi / n:.0f}" if n else "–")
        L.append(f"| {c} | " + " | ".join(cells) + " |")
    # Budget: capture + tracking + VO + control at 376x240, 20 Hz, on a 4-core board. One thread
    # each (the VO's bundle adjustment on a thread of its own): each must fit in one core, the
    # sum in four.
    chain = [("capture (EuRoC pair -> 376x240)", "capture-euroc-376", 1.0),
             ("tracking (amcmr-ct, 376x240)", "track-amcmr-david-376", 1.0),
             ("VO front end (sim 376x240)", "vo-sim-376-noba", 1.0),
             ("VO bundle adjustment (its own thread)", ("vo-sim-376", "vo-sim-376-noba"), 1.0),
             ("control (one command per pose)", "control", 1.0)]
    rate_hz = 20.0
    for arch, boards in (("arm64", [b for b in BOARDS if b[1] == "arm64"]), ("armhf", [b for b in BOARDS if b[1] == "armhf"])):
        per = []
        for label, cs, _ in chain:
            if isinstance(cs, tuple):
                a_, b_ = g(arch, cs[0], "insns"), g(arch, cs[1], "insns")
                n = a_ - b_ if a_ and b_ else None
            else:
                n = g(arch, cs, "insns")
            per.append((label, n))
        if any(n is None for _, n in per):
            continue
        L.append("")
        L.append(f"Budget at {rate_hz:.0f} Hz, {arch} counts: cores used per thread and in all (IPC low – high)\n")
        L.append("| thread | M instr/frame | " + " | ".join(b[0] for b in boards) + " |")
        L.append("|---|---|" + "---|" * len(boards))
        for label, n in per + [("**sum (of 4 cores)**", sum(n for _, n in per))]:
            cells = []
            for name, _, ghz, lo, hi in boards:
                cells.append(f"{n * rate_hz / (ghz * 1e9 * hi):.2f} – {n * rate_hz / (ghz * 1e9 * lo):.2f}")
            L.append(f"| {label} | {n / 1e6:.1f} | " + " | ".join(cells) + " |")
    text = "\n".join(L) + "\n"
    open(os.path.join(out, "table.md"), "w").write(text)
    print(text)


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""The soak's summary (scripts/soak.sh runs it at the end):  soak_report.py --out DIR [--warmup-minutes M]

Reads what soak.sh and tools/soak/soak_monitor.py wrote in DIR (run.json, flights.csv,
samples.csv, counters.csv, host.csv, events.csv, monitor.json, log-info.json) and writes
DIR/soak.md, DIR/summary.json, DIR/rss.png, DIR/cpu.png and DIR/heap.png.

Per process: RSS after the warm-up (the median over the window that starts when the warm-up
ends) and at the end (the median over the run's last window); the window is 60 s (two
flights or more), shorter in short runs; growth = end / after warm-up - 1 (target < 5 %);
also the slope of a least-squares line through every sample after the warm-up, and the growth
of the per-flight floor (the least RSS of each flight: the last three flights' median against
the first three's after the warm-up). The warm-up
is --warmup-minutes (default 3) or a third of the run, whichever is shorter. Processes
restarted every flight (aerie-pilot, aerie-flightsim) are compared by each run's median RSS:
the median of the first three runs after the warm-up against that of the last three (a run's
peak is its start-up, which the 1-s samples catch or miss by their phase; the peaks are
reported beside). CPU: percent of one core, mean
and 95th percentile of the 1-s samples after the warm-up.

Exit status: 0 every flight landed within the success bounds and the logger lost nothing;
1 otherwise; 2 when the inputs are missing.
"""
import argparse
import csv
import json
import math
import os
import sys
from collections import defaultdict

TARGET_GROWTH = 0.05
# What each procman command of config/demo.pmd runs (for the tables).
PROGRAM = {"flightsim": "aerie-flightsim", "track": "aerie-track", "pilot": "aerie-pilot", "vo": "aerie-vo",
           "map": "aerie-map", "logger": "aerie-log record", "viewer": "aerie-viewer", "deputy": "aerie-deputy",
           "xvfb": "Xvfb", "soak-monitor": "soak_monitor.py"}
ORDER = ["flightsim", "pilot", "track", "vo", "map", "logger", "viewer", "deputy", "xvfb", "soak-monitor"]
# Counters worth a column: errors, drops and skips (cumulative, per process).
BAD = ("malformed", "handler_errors", "sequence_gaps", "publish_errors", "errors", "decode_errors",
       "command_errors", "refused", "dropped", "lost", "time_held", "time_jumps")


def read_csv(path):
    if not os.path.exists(path):
        return []
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def median(v):
    v = sorted(v)
    n = len(v)
    if n == 0:
        return math.nan
    return v[n // 2] if n % 2 else 0.5 * (v[n // 2 - 1] + v[n // 2])


def percentile(v, p):
    v = sorted(v)
    if not v:
        return math.nan
    return v[min(len(v) - 1, int(round(p / 100.0 * (len(v) - 1))))]


def fit(ts, ys):
    """Least-squares slope and intercept."""
    n = len(ts)
    if n < 2:
        return math.nan, math.nan
    mt, my = sum(ts) / n, sum(ys) / n
    sxx = sum((t - mt) ** 2 for t in ts)
    if sxx == 0:
        return math.nan, math.nan
    slope = sum((t - mt) * (y - my) for t, y in zip(ts, ys)) / sxx
    return slope, my - slope * mt


def pct(v):
    return "–" if v is None or math.isnan(v) else f"{v * 100:+.1f} %"


def floor_growth(s, flights, warm, t_end):
    """The growth of a whole-run process's floor: the least RSS of each flight that starts after the
    warm-up, the median of the last three flights' against the first three's (fewer in short runs).
    Flights leave aerie-map in the same state (empty after MAP_CMD CLEAR), so its floor compares
    like with like where a window's median follows the size of the map being built."""
    floors = []
    for f in flights:
        a, b = float(f["start_s"]), min(float(f["end_s"]), t_end)
        v = [x[2] for x in s if a <= x[0] <= b]
        if a >= warm and v:
            floors.append(min(v))
    if len(floors) < 2:
        return math.nan
    k = max(1, min(3, len(floors) // 3))
    return median(floors[-k:]) / median(floors[:k]) - 1


def floor_cell(r):
    """The per-flight floor's growth; for a process restarted each flight, that of its runs' peaks."""
    return f"peaks {pct(r['peak_growth'])}" if "peak_growth" in r else pct(r.get("floor_growth", math.nan))


def fmt(v, spec=".1f", none="–"):
    return none if v is None or (isinstance(v, float) and math.isnan(v)) else format(v, spec)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", required=True)
    ap.add_argument("--warmup-minutes", type=float, default=3.0)
    a = ap.parse_args()
    d = a.out
    samples = read_csv(os.path.join(d, "samples.csv"))
    flights = read_csv(os.path.join(d, "flights.csv"))
    if not samples:
        print(f"soak_report: no samples in {d}/samples.csv", file=sys.stderr)
        return 2
    run = json.load(open(os.path.join(d, "run.json"))) if os.path.exists(os.path.join(d, "run.json")) else {}
    log = json.load(open(os.path.join(d, "log-info.json"))) if os.path.exists(os.path.join(d, "log-info.json")) else None
    mon = json.load(open(os.path.join(d, "monitor.json"))) if os.path.exists(os.path.join(d, "monitor.json")) else {}
    host = read_csv(os.path.join(d, "host.csv"))
    counters = read_csv(os.path.join(d, "counters.csv"))

    # The monitor's clock starts a moment before soak.sh's (flights.csv): one time axis.
    offset = mon["start_utime"] * 1e-6 - run["t0_epoch"] if "start_utime" in mon and "t0_epoch" in run else 0.0
    for rows_ in (samples, host, counters):
        for r in rows_:
            r["time_s"] = float(r["time_s"]) + offset

    # --- Per process ---------------------------------------------------------------------
    series = defaultdict(list)  # node -> [(t, pid, rss_kb, cpu, threads)]
    udp = defaultdict(dict)     # node -> pid -> datagrams dropped (cumulative)
    for r in samples:
        series[r["node"]].append((r["time_s"], int(r["pid"]), int(r["rss_kb"]), float(r["cpu_percent"]),
                                  int(r["threads"])))
        if r.get("udp_drops") not in (None, ""):
            udp[r["node"]][r["pid"]] = max(udp[r["node"]].get(r["pid"], 0), int(r["udp_drops"]))
    # The run's end: the last flight's (the monitor samples on while the chain stops).
    t_end = max(float(r["time_s"]) for r in samples)
    if flights:
        t_end = min(t_end, max(float(f["end_s"]) for f in flights))
    warm = min(a.warmup_minutes * 60.0, t_end / 3.0)
    window = max(5.0, min(60.0, (t_end - warm) / 4.0))
    nodes = [n for n in ORDER if n in series] + sorted(n for n in series if n not in ORDER)
    rows = []
    for node in nodes:
        s = series[node]
        pids = []
        for _, pid, *_ in s:
            if not pids or pids[-1] != pid:
                pids.append(pid)
        restarted = len(set(pids)) > 1
        after = [x for x in s if warm <= x[0] <= t_end]
        cpu = [x[3] for x in after[1:]] if after else []
        row = {"node": node, "program": PROGRAM.get(node, node), "instances": len(set(pids)), "samples": len(s),
               "cpu_mean": sum(cpu) / len(cpu) if cpu else math.nan, "cpu_p95": percentile(cpu, 95),
               "threads_max": max(x[4] for x in s), "rss_peak_mb": max(x[2] for x in s) / 1024.0,
               "udp_drops": sum(udp[node].values()) if node in udp else None}
        if restarted:
            runs = defaultdict(list)
            first_t = {}
            for t, pid, rss, *_ in s:
                runs[pid].append(rss)
                first_t.setdefault(pid, t)
            # The runs that started after the warm-up: the median of the first k runs' median RSS
            # against the last k's; the same for their peaks (start-up transients, sampled or not).
            later = [p for p in pids if first_t[p] >= warm] or pids
            k = max(1, min(3, len(later) // 3))
            level = [median(runs[p]) for p in later]
            peak = [max(runs[p]) for p in later]
            base, last = median(level[:k]), median(level[-k:])
            row.update(mode="restarted each flight", rss_base_mb=base / 1024.0, rss_end_mb=last / 1024.0,
                       growth=last / base - 1 if base else math.nan, slope_mb_h=math.nan,
                       peak_growth=median(peak[-k:]) / median(peak[:k]) - 1)
        else:
            base = [x[2] for x in after if x[0] < warm + window]
            t_last = max(x[0] for x in s if x[0] <= t_end) if any(x[0] <= t_end for x in s) else t_end
            end = [x[2] for x in s if t_last - window <= x[0] <= t_last]
            b, e = median(base), median(end)
            slope, _ = fit([x[0] for x in after], [x[2] for x in after])
            row.update(mode="whole run", rss_base_mb=b / 1024.0, rss_end_mb=e / 1024.0,
                       growth=e / b - 1 if b else math.nan, slope_mb_h=slope * 3600 / 1024.0 if not math.isnan(slope) else math.nan,
                       floor_growth=floor_growth(s, flights, warm, t_end))
        rows.append(row)

    # --- Status counters: errors, drops (summed over a node's processes) -----------------
    # A status message is the node's whose pid it carries (samples.csv knows every pid's name;
    # the monitor names a status by its channel until it has the deputy's report of the pid).
    pid_node = {r["pid"]: r["node"] for r in samples}
    last = {}  # (node, pid, counter) -> value
    for r in counters:
        last[(pid_node.get(r["pid"], r["node"]), r["pid"], r["counter"])] = int(r["value"])
    node_counters = defaultdict(lambda: defaultdict(int))
    for (node, _, c), v in last.items():
        node_counters[node][c] += v
    status_nodes = sorted(node_counters)

    # --- Flights ---------------------------------------------------------------------------
    done = [f for f in flights if not f["result"].startswith("NOT FINISHED (interrupted)")]
    landed = sum(int(f["landed"]) for f in done)
    success = sum(int(f["success"]) for f in done)
    errs = [float(f["touchdown_error_m"]) for f in done if f["touchdown_error_m"]]
    ftimes = [float(f["flight_time_s"]) for f in done if f["flight_time_s"]]
    cycle = [float(f["end_s"]) - float(f["start_s"]) for f in done]
    failures = [f for f in done if f["success"] != "1"]

    # The pilot's states and the operator's INIT during each flight (events.csv).
    events = read_csv(os.path.join(d, "events.csv"))
    for f in flights:
        f["holds"], f["holds_stale"], f["init_s"], f["states"] = 0, 0, None, []
    for e in events:
        t = float(e["time_s"]) + offset
        f = next((f for f in flights if float(f["start_s"]) <= t <= float(f["end_s"]) + 1.0), None)
        if f is None:
            continue
        if e["event"] == "pilot":
            name = e["detail"].split(":")[0]
            f["states"].append(name)
            f["holds"] += name == "HOLD"
            f["holds_stale"] += name == "HOLD" and "stale" in e["detail"]
        elif e["event"] == "TRACK_CMD INIT" and f["init_s"] is None:
            f["init_s"] = t - float(f["start_s"])

    # --- The logger ------------------------------------------------------------------------
    logger_lost = log["logger_lost"] if log else None
    lost_by_channel = {c["channel"]: c["logger_lost"] for c in log["channels"] if c.get("logger_lost")} if log else {}
    loads = [float(h["load1"]) for h in host if h["time_s"] <= t_end]
    host_cpu = [float(h["cpu_percent"]) for h in host if h["time_s"] <= t_end]

    ok_flights = bool(done) and success == len(done)
    ok_logger = logger_lost == 0
    ok_rss = all(not (r["growth"] >= TARGET_GROWTH) for r in rows if r["node"] not in ("xvfb", "soak-monitor"))
    summary = {"duration_s": t_end, "warmup_s": warm, "window_s": window, "flights": len(flights),
               "flights_finished": len(done), "landed": landed, "success": success,
               "holds": sum(f["holds"] for f in done),
               "touchdown_error_mean_m": sum(errs) / len(errs) if errs else None,
               "logger_lost": logger_lost, "logger_lost_by_channel": lost_by_channel,
               "log_events": log["events"] if log else None, "log_mb": log["file_size"] / 1e6 if log else None,
               "producer_skipped": log["producer_skipped"] if log else None,
               "load1_mean": sum(loads) / len(loads) if loads else None, "load1_max": max(loads) if loads else None,
               "host_cpu_mean_percent": sum(host_cpu) / len(host_cpu) if host_cpu else None,
               "rss_growth_below_target": ok_rss,
               "rss_floor_growth_below_target": all(not (r.get("floor_growth", math.nan) >= TARGET_GROWTH) for r in rows
                                                    if r["node"] not in ("xvfb", "soak-monitor")),
               "nodes": rows,
               "status_counters": {n: dict(node_counters[n]) for n in status_nodes}}

    # --- Plots -----------------------------------------------------------------------------
    plotted = plots(d, series, nodes, warm, host)
    heap_plotted = plotted and heap_plot(d, series, counters, warm)

    # --- soak.md -------------------------------------------------------------------------------
    L = []
    L.append("# Soak: the demo flight, repeated in real time\n")
    if run:
        L.append(f"`{run.get('command', 'scripts/soak.sh')}` — started {run.get('started_utc', '?')} UTC, "
                 f"{t_end / 60:.1f} min, {len(flights)} flights from seed {run.get('first_seed', '?')}"
                 f"{' (every flight the same seed)' if run.get('same_seed') else ''}"
                 f"{' (interrupted)' if run.get('interrupted') else ''}; {run.get('host_cpus', '?')} CPUs; "
                 f"load average {run.get('load_start', '?')} at the start, {run.get('load_end', '?')} at the end"
                 + (f", 1-min load {summary['load1_mean']:.1f} mean / {summary['load1_max']:.1f} max during the run"
                    if loads else "")
                 + (f", host CPU {summary['host_cpu_mean_percent']:.0f} % of one core mean" if host_cpu else "")
                 + (f"; network namespace `{run['netns']}`" if run.get("netns") else "") + ".\n")
    L.append("## Verdict\n")
    L.append(f"* Landings: **{success}/{len(done)}** within the success bounds ({landed} landed)"
             + (f", touchdown error {sum(errs) / len(errs) * 100:.1f} cm mean / {percentile(errs, 95) * 100:.1f} cm p95"
                if errs else "")
             + (f", flight {sum(ftimes) / len(ftimes):.1f} s mean (simulated)" if ftimes else "")
             + (f", {sum(cycle) / len(cycle):.1f} s per cycle with the restarts" if cycle else "")
             + f"; the pilot held (HOLD) {summary['holds']} times in {sum(1 for f in done if f['holds'])} flights, "
               f"{sum(f['holds_stale'] for f in done)} of them for a stale tracker (no TRACK for 0.5 s).")
    if log:
        L.append(f"* Logger: **{logger_lost} messages lost** of {log['events']} events ({log['file_size'] / 1e9:.2f} GB); "
                 f"{log['producer_skipped']} frames skipped by producers by design (aerie-log info)"
                 + (": " + ", ".join(f"{c} {v}" for c, v in sorted(lost_by_channel.items())) if lost_by_channel else "") + ".")
    else:
        L.append("* Logger: **no log summary** (log-info.json missing).")
    backlog = [int(h["backlog_drops"]) for h in host if h.get("backlog_drops") not in (None, "") and h["time_s"] <= t_end]
    summary["backlog_drops"] = backlog[-1] - backlog[0] if backlog else None
    dropping = [r for r in rows if r.get("udp_drops")]
    L.append("* UDP datagrams dropped in the receive buffers: " + (", ".join(f"{r['node']} {r['udp_drops']}" for r in dropping)
             if dropping else "none") + (f"; the host's input queues (softnet backlog, host-wide) dropped "
             f"{summary['backlog_drops']} packets during the run" if backlog else "") + ".")
    worst = max((r for r in rows if r["node"] not in ("xvfb", "soak-monitor") and not math.isnan(r["growth"])),
                key=lambda r: r["growth"], default=None)
    floors = [r for r in rows if r["node"] not in ("xvfb", "soak-monitor") and not math.isnan(r.get("floor_growth", math.nan))]
    worst_floor = max(floors, key=lambda r: r["floor_growth"], default=None)
    if worst:
        L.append(f"* RSS after the warm-up ({warm / 60:.1f} min), target < 5 %: largest growth {worst['growth'] * 100:+.1f} % "
                 f"({worst['node']}): **{'met' if ok_rss else 'not met'}**"
                 + (f"; of the per-flight floors {worst_floor['floor_growth'] * 100:+.1f} % ({worst_floor['node']}): "
                    f"**{'met' if summary['rss_floor_growth_below_target'] else 'not met'}**" if worst_floor else "") + ".")
    L.append("")
    L.append("## Processes\n")
    L.append("| process | program | runs | RSS after warm-up (MB) | RSS at the end (MB) | growth | slope after warm-up (MB/h) "
             "| growth of the per-flight floor | peak RSS (MB) | CPU mean / p95 (% of a core) | threads | UDP datagrams dropped |")
    L.append("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        L.append(f"| {r['node']} | {r['program']} | {r['instances']} | {fmt(r['rss_base_mb'])} | {fmt(r['rss_end_mb'])} "
                 f"| {pct(r['growth'])} "
                 f"| {fmt(r['slope_mb_h'], '+.2f')} | {floor_cell(r)} | {fmt(r['rss_peak_mb'])} | {fmt(r['cpu_mean'])} / {fmt(r['cpu_p95'])} "
                 f"| {r['threads_max']} | {fmt(r['udp_drops'], 'd')} |")
    L.append("")
    L.append(f"Growth, for the processes that run the whole soak (runs = 1): the median RSS of the {window:.0f} s after "
             f"the warm-up ({warm / 60:.1f} min) against the median of the last {window:.0f} s; the slope is a least-squares "
             "line through every 1-s sample after the warm-up; the per-flight floor: the least RSS of each flight after the "
             "warm-up, the median of the last three flights' against the first three's. Processes restarted each flight (runs > 1): the "
             "median RSS of each run, the first three runs' after the warm-up against the last three's (in the floor's column, "
             "the same for each run's peak: its start-up, which the 1-s samples catch or miss). CPU: 1-s samples of /proc/PID/stat (utime + stime) "
             "after the warm-up, in % of one core. UDP datagrams dropped: by the kernel, for a full receive buffer of "
             "the process's sockets (/proc/net/udp; every LCM socket receives every channel of the multicast group).\n")
    if status_nodes:
        L.append("## Status counters at the end (errors, drops, skips; summed over a node's runs)\n")
        L.append("| node | counters |")
        L.append("|---|---|")
        for n in status_nodes:
            bad = {c: v for c, v in sorted(node_counters[n].items()) if any(k in c for k in BAD) and v}
            L.append(f"| {n} | {', '.join(f'{c} {v}' for c, v in bad.items()) if bad else 'all 0'} |")
        L.append("")
        gaps = {c: v["seq_gaps"] for c, v in mon.get("status_messages", {}).items() if v["seq_gaps"]}
        L.append(f"Status messages received by the monitor: {sum(v['received'] for v in mon.get('status_messages', {}).values())}"
                 f", of which missed by the monitor itself: {sum(gaps.values())}"
                 + (" (" + ", ".join(f"{c} {v}" for c, v in gaps.items()) + ")" if gaps else "")
                 + ". Operator commands sent between flights: "
                 + ", ".join(f"{k} {v}" for k, v in mon.get("track_cmd_sent", {}).items()) + ".\n")
    faulted = [f for f in done if f.get("kill")]
    if faulted:
        # soak.sh --kill: one air node kill -9'd per flight, respawned by procman (issue 19 §4).
        L.append("## Faults: an air node killed in flight (kill -9, procman's respawn)\n")
        L.append("| node killed | flights | killed at (s after the vehicle's start) | respawned | respawn (s) mean / max "
                 "| safe (no collision) | completed (landed within the bounds) | pilot HOLDs |")
        L.append("|---|---|---|---|---|---|---|---|")
        by_node = defaultdict(list)
        for f in faulted:
            by_node[f["kill"]].append(f)
        summary["faults"] = {}
        for node, fs in sorted(by_node.items()):
            at = [float(f["kill_at_s"]) for f in fs]
            killed = [f for f in fs if f.get("killed_pid")]
            resp = [float(f["respawn_s"]) for f in killed if f.get("respawn_s")]
            safe = sum("collision" not in f["result"] for f in fs)
            completed = sum(f["success"] == "1" for f in fs)
            summary["faults"][node] = {"flights": len(fs), "killed": len(killed), "respawned": len(resp), "safe": safe,
                                       "completed": completed, "holds": sum(f["holds"] for f in fs)}
            L.append(f"| aerie-{node} | {len(fs)} | {min(at):.1f}–{max(at):.1f} | {len(resp)} of {len(killed)} killed "
                     f"| {fmt(sum(resp) / len(resp) if resp else math.nan, '.2f')} / {fmt(max(resp) if resp else math.nan, '.2f')} "
                     f"| {safe}/{len(fs)} | {completed}/{len(fs)} | {sum(f['holds'] for f in fs)} |")
        L.append("")
    L.append("## Flights\n")
    L.append("| flight | seed | start (s) | cycle (s) | operator INIT (s into the cycle) | pilot states | result |")
    L.append("|---|---|---|---|---|---|---|")
    for f in flights:
        states = " → ".join(dedupe(f["states"]))
        L.append(f"| {f['flight']} | {f['seed']} | {float(f['start_s']):.0f} | {float(f['end_s']) - float(f['start_s']):.1f} "
                 f"| {fmt(f['init_s'])} | {states} | {f['result']}"
                 + (f" (aerie-{f['kill']} killed at {f['kill_at_s']} s)" if f.get("kill") else "") + " |")
    L.append("")
    if failures:
        L.append("Failed: " + ", ".join(f"flight {f['flight']} (seed {f['seed']})" for f in failures) + ".\n")
    if plotted:
        L.append("![RSS](rss.png)\n\n![CPU](cpu.png)\n")
    if heap_plotted:
        L.append("![heap](heap.png)\n")
    with open(os.path.join(d, "soak.md"), "w") as f:
        f.write("\n".join(L))
    with open(os.path.join(d, "summary.json"), "w") as f:
        json.dump(clean(summary), f, indent=1)
    print(f"soak: {success}/{len(done)} landings within the bounds; logger lost {logger_lost}; "
          f"RSS growth after the warm-up " + ", ".join(f"{r['node']} {r['growth'] * 100:+.1f} %" for r in rows
                                                         if not math.isnan(r["growth"])))
    return 0 if ok_flights and ok_logger else 1


def plots(d, series, nodes, warm, host):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("soak_report: matplotlib is missing (apt-get install python3-matplotlib): no plots", file=sys.stderr)
        return False
    n = len(nodes)
    cols = 3
    nrows = (n + cols - 1) // cols
    for what, idx, ylabel, fname in (("RSS", 2, "RSS (MB)", "rss.png"), ("CPU", 3, "CPU (% of one core, 10-s mean)", "cpu.png")):
        extra = 1 if what == "CPU" and host else 0
        rows = (n + extra + cols - 1) // cols
        fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 2.6 * rows), squeeze=False, sharex=True)
        for i, node in enumerate(nodes):
            ax = axes[i // cols][i % cols]
            s = series[node]
            # One line per process run (restarts leave gaps rather than joins).
            runs = defaultdict(list)
            for x in s:
                runs[x[1]].append(x)
            for pts in runs.values():
                t = [p[0] / 60.0 for p in pts]
                y = [p[idx] / 1024.0 for p in pts] if what == "RSS" else smooth([p[idx] for p in pts], 10)
                ax.plot(t, y, lw=0.8, color="C0")
            ax.axvline(warm / 60.0, color="grey", ls="--", lw=0.7)
            ax.set_title(f"{node} ({PROGRAM.get(node, node)})", fontsize=9)
            ax.set_ylim(0, max(1e-3, ax.get_ylim()[1]) * 1.15)
            ax.tick_params(labelsize=8)
            if i % cols == 0:
                ax.set_ylabel(ylabel, fontsize=8)
        if extra:
            ax = axes[n // cols][n % cols]
            t = [float(h["time_s"]) / 60.0 for h in host]
            ax.plot(t, smooth([float(h["cpu_percent"]) for h in host], 10), lw=0.8, color="C3", label="host CPU (%)")
            ax2 = ax.twinx()
            ax2.plot(t, [float(h["load1"]) for h in host], lw=0.8, color="C2", label="load (1 min)")
            ax.set_title("host: CPU (red, % of one core) and load (green)", fontsize=9)
            ax.set_ylim(bottom=0)
            ax2.set_ylim(bottom=0)
            ax.tick_params(labelsize=8)
            ax2.tick_params(labelsize=8)
        for j in range(n + extra, rows * cols):
            axes[j // cols][j % cols].axis("off")
        for c in range(cols):  # the lowest plot of each column carries the time axis
            last = max(j for j in range(c, n + extra, cols)) if c < n + extra else None
            if last is not None:
                axes[last // cols][c].set_xlabel("time (min)", fontsize=8)
                axes[last // cols][c].tick_params(labelbottom=True)
        fig.suptitle(f"Soak: {what} per process (dashed: end of the warm-up)", fontsize=10)
        fig.tight_layout()
        fig.savefig(os.path.join(d, fname), dpi=90)
        plt.close(fig)
    return True


def heap_plot(d, series, counters, warm):
    """heap.png: for each node whose status reports its heap (heap_in_use_kb, heap_free_kb: today
    the viewer), its RSS, the heap in use, and in use + free (what malloc holds), as 60-s
    medians: a leak raises the heap in use; fragmentation raises what malloc holds around it."""
    import matplotlib.pyplot as plt
    heap = defaultdict(lambda: defaultdict(dict))  # node -> time -> counter -> kB
    for r in counters:
        if r["counter"] in ("heap_in_use_kb", "heap_free_kb"):
            heap[r["node"]][r["time_s"]][r["counter"]] = int(r["value"])
    nodes = [n for n in heap if n in series]
    if not nodes:
        return False

    def minute_medians(points):
        by = defaultdict(list)
        for t, v in points:
            by[int(t // 60)].append(v)
        return [k + 0.5 for k in sorted(by)], [median(by[k]) / 1024.0 for k in sorted(by)]

    fig, axes = plt.subplots(1, len(nodes), figsize=(5.5 * len(nodes), 3.2), squeeze=False)
    for ax, node in zip(axes[0], sorted(nodes)):
        full = sorted((t, c) for t, c in heap[node].items() if len(c) == 2)
        for label, pts in (("RSS", [(x[0], x[2]) for x in series[node]]),
                           ("heap in use + free (held by malloc)", [(t, c["heap_in_use_kb"] + c["heap_free_kb"]) for t, c in full]),
                           ("heap in use", [(t, c["heap_in_use_kb"]) for t, c in full])):
            t, y = minute_medians(pts)
            ax.plot(t, y, lw=1.0, marker=".", ms=3, label=label)
        ax.axvline(warm / 60.0, color="grey", ls="--", lw=0.7)
        ax.set_title(f"{node} ({PROGRAM.get(node, node)})", fontsize=9)
        ax.set_xlabel("time (min)", fontsize=8)
        ax.set_ylabel("MB (medians of 1 min)", fontsize=8)
        ax.set_ylim(bottom=0)
        ax.tick_params(labelsize=8)
        ax.legend(fontsize=7)
    fig.suptitle("Soak: heap of the nodes that report it (dashed: end of the warm-up)", fontsize=10)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "heap.png"), dpi=90)
    plt.close(fig)
    return True


def clean(x):
    """NaN as null (JSON has no NaN)."""
    if isinstance(x, float) and math.isnan(x):
        return None
    if isinstance(x, dict):
        return {k: clean(v) for k, v in x.items()}
    if isinstance(x, list):
        return [clean(v) for v in x]
    return x


def dedupe(v):
    out = []
    for x in v:
        if not out or out[-1] != x:
            out.append(x)
    return out


def smooth(v, k):
    out, acc = [], 0.0
    for i, x in enumerate(v):
        acc += x
        if i >= k:
            acc -= v[i - k]
        out.append(acc / min(i + 1, k))
    return out


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/python3
"""Plots and page of aerie-log report: one PNG per section present in the log and DIR/index.html
(the summary table, the plots, the CSVs, the sections left out and the channels they lack).
   report_plots.py DIR  (reads the CSVs aerie-log report wrote in DIR: sections.csv, summary.csv
   and one or more per section; writes DIR/<section>.png and DIR/index.html)"""
import csv
import html
import os
import sys
from collections import defaultdict

# pilot_state_t's constants (lcmtypes/aerie_pilot_state_t.lcm), for the timeline's axis.
PILOT_STATES = ["IDLE", "TAKEOFF", "SURVEY", "ACQUIRE", "APPROACH", "DESCEND", "TOUCHDOWN", "LANDED", "HOLD",
                "ABORT", "ABORTED"]
TRACK_STATUS = {0: "IDLE", 1: "TRACKING", 2: "LOST", 3: "REDETECTED"}
VO_LOST = 2  # pose_t.LOST
# STATUS_VO counters worth a line: the frames VO did not turn into a pose, and why.
VO_SKIP_WORDS = ("skip", "drop", "overflow", "queue", "gap", "stale", "malformed", "refused", "lost", "duplicate",
                 "out_of_order")


def rows(out, name):
    path = os.path.join(out, name)
    if not os.path.exists(path):
        return []
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def fnum(s):
    try:
        return float(s)
    except (TypeError, ValueError):
        return float("nan")


def draw_views(axes, views, tracks, vmap, pad, frame):
    """Top and side views of `tracks` (channel -> [(x, y, z)]) over the map's voxels and the pad.
    views: (i, j, x label, y label, sign of j) per panel; the axes are the frame's own."""
    for ax, (i, j, xl, yl, sj) in zip(axes, views):
        if vmap:
            ax.scatter([m[i] for m in vmap], [sj * m[j] for m in vmap], s=1, c="0.7",
                       label=f"map ({len(vmap)} occupied voxels)", rasterized=True)
        for ch, pts in sorted(tracks.items()):
            ax.plot([p[i] for p in pts], [sj * p[j] for p in pts], lw=1, label=ch)
            ax.plot(pts[0][i], sj * pts[0][j], "o", color="green", ms=4)
            ax.plot(pts[-1][i], sj * pts[-1][j], "x", color="red", ms=6)
        if pad:
            ax.plot(pad[i], sj * pad[j], "s", color="black", ms=7, mfc="none", label="helipad")
        ax.set_xlabel(xl)
        ax.set_ylabel(yl)
        ax.set_title(f"{frame}: {'top' if ax is axes[0] else 'side'} view (o start, x end)", fontsize=9)
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(True, lw=0.3)
    axes[0].legend(fontsize=7)


def plot_trajectory(plt, out):
    """The world (SIM_STATE, GT_POSE, NAV_STATE: x east, y north, z up) in one row; VO_POSE and
    the map, which aerie-map builds from VO's poses, in VO's own frame (the first left camera's:
    x right, y down, z forward) in another."""
    by = defaultdict(list)
    for r in rows(out, "trajectory.csv"):
        by[r["channel"]].append((fnum(r["x"]), fnum(r["y"]), fnum(r["z"])))
    vmap = [(fnum(r["x"]), fnum(r["y"]), fnum(r["z"])) for r in rows(out, "map.csv")]
    pad = [(fnum(r["x"]), fnum(r["y"]), fnum(r["z"])) for r in rows(out, "pad.csv")]
    world = {ch: pts for ch, pts in by.items() if ch != "VO_POSE"}
    vo = {ch: pts for ch, pts in by.items() if ch == "VO_POSE"}
    panels = [p for p in (world, vo or vmap) if p]
    fig, axes = plt.subplots(len(panels), 2, figsize=(11, 5 * len(panels)), squeeze=False)
    row = 0
    if world:
        draw_views(axes[row], [(0, 1, "x (m, east)", "y (m, north)", 1), (0, 2, "x (m, east)", "z (m, up)", 1)],
                   world, [], pad[0] if pad else None, "World")
        row += 1
    if vo or vmap:
        draw_views(axes[row], [(0, 2, "x (m, right)", "z (m, forward)", 1), (2, 1, "z (m, forward)", "-y (m, up)", -1)],
                   vo, vmap, None, "VO frame (first left camera)")
    fig.tight_layout()
    return save(fig, out, "trajectory")


def plot_pilot(plt, out):
    p = rows(out, "pilot.csv")
    t = [fnum(r["t"]) for r in p]
    fig, ax = plt.subplots(figsize=(10, 3.5))
    ax.step(t, [int(r["state"]) for r in p], where="post", color="tab:blue")
    ax.set_yticks(range(len(PILOT_STATES)))
    ax.set_yticklabels(PILOT_STATES, fontsize=7)
    ax.set_xlabel("log time (s)")
    ax.set_title("Pilot state (PILOT_STATE) and height above the target")
    ax.grid(True, lw=0.3)
    h = ax.twinx()
    h.plot(t, [fnum(r["height_m"]) for r in p], color="tab:orange", lw=0.8)
    h.set_ylabel("height (m, vision)", color="tab:orange")
    fig.tight_layout()
    return save(fig, out, "pilot")


def plot_track(plt, out):
    tr = rows(out, "track.csv")
    fig, ax = plt.subplots(figsize=(10, 3.5))
    for code, name in TRACK_STATUS.items():
        sel = [r for r in tr if int(r["status"]) == code]
        if sel:
            ax.scatter([fnum(r["t"]) for r in sel], [fnum(r["confidence"]) for r in sel], s=4, label=name)
    last = None
    for r in tr:
        s = int(r["status"])
        if s == 2 and last != 2:
            ax.axvline(fnum(r["t"]), color="red", lw=0.6, ls="--")
        last = s
    ax.set_ylim(-0.05, 1.05)
    ax.set_xlabel("log time (s)")
    ax.set_ylabel("confidence")
    ax.set_title("Tracker confidence (TRACK; dashed: a loss)")
    ax.legend(fontsize=7, markerscale=3)
    fig.tight_layout()
    return save(fig, out, "track")


def plot_vo(plt, out):
    vo, st = rows(out, "vo.csv"), rows(out, "vo_status.csv")
    fig, axes = plt.subplots(2, 1, figsize=(10, 5), sharex=True)
    if vo:
        t = [fnum(r["t"]) for r in vo]
        axes[0].plot(t, [int(r["inliers"]) for r in vo], lw=0.8, label="inliers")
        axes[0].plot(t, [int(r["features_3d"]) for r in vo], lw=0.6, label="3D features")
        lost = [fnum(r["t"]) for r in vo if int(r["status"]) == VO_LOST]
        if lost:
            axes[0].plot(lost, [0] * len(lost), "x", color="red", label="LOST")
        seq = [int(r["seq"]) for r in vo]
        missed = [0]
        for k in range(1, len(seq)):
            missed.append(missed[-1] + max(0, seq[k] - seq[k - 1] - 1))
        if missed[-1]:
            axes[1].step(t, missed, where="post", color="tab:red", lw=1.2,
                         label="frames without a pose (VO_POSE seq gaps)")
    axes[0].set_ylabel("features")
    axes[0].set_title("VO inliers (VO_POSE) and skips (VO_POSE seq gaps, STATUS_VO counters)")
    axes[0].legend(fontsize=7)
    counters = defaultdict(list)
    for r in st:
        if any(w in r["counter"] for w in VO_SKIP_WORDS):
            counters[r["counter"]].append((fnum(r["t"]), int(r["value"])))
    for name, pts in sorted(counters.items()):
        axes[1].step([p[0] for p in pts], [p[1] for p in pts], where="post", lw=0.8, label=name)
    axes[1].set_ylabel("frames (cumulative)")
    axes[1].set_xlabel("log time (s)")
    axes[1].legend(fontsize=6)
    fig.tight_layout()
    return save(fig, out, "vo")


def plot_nav_error(plt, out, truth):
    ne = rows(out, "nav_error.csv")
    t = [fnum(r["t"]) for r in ne]
    fig, ax = plt.subplots(figsize=(10, 3.5))
    ax.plot(t, [100 * fnum(r["error_m"]) for r in ne], lw=0.8, label="in NAV's world")
    ax.plot(t, [100 * fnum(r["aligned_error_m"]) for r in ne], lw=0.8, label="after SE(3) alignment (Umeyama)")
    ax.set_xlabel("log time (s)")
    ax.set_ylabel("position error (cm)")
    ax.set_title(f"NAV_STATE position against {truth}")
    ax.legend(fontsize=7)
    ax.grid(True, lw=0.3)
    fig.tight_layout()
    return save(fig, out, "nav_error")


def plot_latency(plt, out):
    lat = [r for r in rows(out, "latency.csv") if int(r["count"]) > 0]
    ch = [r for r in lat if r["kind"] == "channel"]
    hops = [r for r in lat if r["kind"] == "hop_age"]
    items = [(r["name"], fnum(r["median_ms"]), fnum(r["p99_ms"])) for r in ch] + \
            [("hop " + r["name"] + " (age)", fnum(r["median_ms"]), fnum(r["p99_ms"])) for r in hops]
    fig, ax = plt.subplots(figsize=(9, 0.3 * len(items) + 1.5))
    y = list(range(len(items)))
    ax.barh(y, [i[2] for i in items], color="tab:orange", label="p99")
    ax.barh(y, [i[1] for i in items], color="tab:blue", label="median")
    ax.set_yticks(y)
    ax.set_yticklabels([i[0] for i in items], fontsize=7)
    ax.invert_yaxis()
    ax.set_xlabel("latency (ms): log receive time - message utime; hops from STATUS_<NODE>")
    ax.set_title("Latency per channel and per hop")
    ax.legend(fontsize=7)
    fig.tight_layout()
    return save(fig, out, "latency")


def plot_link(plt, out):
    ln = rows(out, "link.csv")
    by = defaultdict(list)
    for r in ln:
        by[r["direction"]].append(r)
    fig, axes = plt.subplots(2, 1, figsize=(10, 5), sharex=True)
    for name, rs in sorted(by.items()):
        t = [fnum(r["t"]) for r in rs]
        drop = [int(r["dropped_loss"]) + int(r["dropped_queue"]) + int(r["dropped_other"]) for r in rs]
        axes[0].plot(t, drop, lw=0.8, label=f"{name} dropped")
        axes[1].plot(t, [fnum(r["delay_p50_ms"]) for r in rs], lw=0.8, label=f"{name} p50")
        axes[1].plot(t, [fnum(r["delay_p99_ms"]) for r in rs], lw=0.6, ls="--", label=f"{name} p99")
    axes[0].set_ylabel("messages (cumulative)")
    axes[0].set_title("Link (LINK_STATS): drops and delay")
    axes[1].set_ylabel("delay (ms)")
    axes[1].set_xlabel("log time (s)")
    for a in axes:
        a.legend(fontsize=7)
    fig.tight_layout()
    return save(fig, out, "link")


def plot_rates(plt, out):
    """Mean rate of every channel (channels.csv), and messages per second of the busiest over time."""
    chans = sorted(rows(out, "channels.csv"), key=lambda r: r["channel"])
    by = defaultdict(list)
    for r in rows(out, "rates.csv"):
        by[r["channel"]].append((int(r["t"]), int(r["messages"])))
    busiest = sorted(by, key=lambda c: -sum(n for _, n in by[c]))[:12]
    fig, axes = plt.subplots(2, 1, figsize=(10, 4 + 0.22 * len(chans)),
                             gridspec_kw={"height_ratios": [max(1, 0.22 * len(chans)), 3]})
    y = list(range(len(chans)))
    axes[0].barh(y, [fnum(r["rate_hz"]) for r in chans], color="tab:blue")
    axes[0].set_yticks(y)
    axes[0].set_yticklabels([f"{r['channel']} ({r['messages']})" for r in chans], fontsize=7)
    axes[0].invert_yaxis()
    axes[0].set_xscale("log")
    axes[0].set_xlabel("mean rate (Hz; messages in brackets)")
    axes[0].set_title("Message rates per channel")
    for ch in sorted(busiest):
        pts = by[ch]
        axes[1].step([p[0] for p in pts], [p[1] for p in pts], where="post", lw=0.8, label=ch)
    axes[1].set_yscale("log")
    axes[1].set_xlabel("log time (s)")
    axes[1].set_ylabel("messages per second")
    axes[1].set_title(f"Over time (the {len(busiest)} busiest)" if len(by) > len(busiest) else "Over time", fontsize=9)
    axes[1].legend(fontsize=6, ncol=3)
    fig.tight_layout()
    return save(fig, out, "rates")


def save(fig, out, name):
    fig.savefig(os.path.join(out, f"{name}.png"), dpi=110)
    return f"{name}.png"


def summary_table(summary):
    label = {"duration_s": "duration (s)", "distance_m": "distance flown (m)", "final_pilot_state": "final pilot state",
             "landing_error_m": "landing error (m, touchdown to pad centre, horizontal)",
             "track_losses": "tracker losses (TRACK entering LOST)", "pilot_losses": "losses the pilot counted",
             "vo_lost": "VO poses LOST", "vo_frames_skipped": "frames without a VO pose (seq gaps)",
             "link_loss_pct": "link loss (%, dropped / received)", "events": "events", "log": "log",
             "undecodable": "messages that did not decode as their channel's type"}
    out = []
    for k, v in summary:
        if k in ("damage", "note", "nav_truth", "distance_source"):
            continue
        if k == "distance_m" and v:
            v = f"{fnum(v):.2f} (from {dict(summary).get('distance_source', '')})"
        elif k in ("duration_s", "landing_error_m", "link_loss_pct") and v:
            v = f"{fnum(v):.3f}" if k == "landing_error_m" else f"{fnum(v):.1f}"
        out.append(f"<tr><th>{html.escape(label.get(k, k))}</th><td>{html.escape(v) if v else '&ndash;'}</td></tr>")
    return "<table class=\"summary\">\n" + "\n".join(out) + "\n</table>"


def main(out):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sections = rows(out, "sections.csv")
    summary = [(r["key"], r["value"]) for r in rows(out, "summary.csv")]
    truth = dict(summary).get("nav_truth", "") or "the ground truth"
    draw = {"trajectory": plot_trajectory, "pilot": plot_pilot, "track": plot_track, "vo": plot_vo,
            "nav_error": lambda p, o: plot_nav_error(p, o, truth), "latency": plot_latency, "link": plot_link,
            "rates": plot_rates}
    body = []
    for s in sections:
        if s["present"] != "1":
            continue
        png = draw[s["section"]](plt, out)
        plt.close("all")
        links = " ".join(f"<a href=\"{html.escape(c)}\">{html.escape(c)}</a>" for c in s["csv"].split())
        note = f"<p class=\"partial\">Not in the log: {html.escape(s['missing'])}</p>" if s["missing"] else ""
        body.append(f"<section id=\"{s['section']}\">\n<h2>{html.escape(s['title'])}</h2>\n{note}\n"
                    f"<a href=\"{png}\"><img src=\"{png}\" alt=\"{html.escape(s['title'])}\"></a>\n"
                    f"<p class=\"data\">Data: {links}</p>\n</section>")
    missing = [f"<li id=\"missing-{s['section']}\">{html.escape(s['title'])}: the log has no "
               f"{html.escape(' or '.join(s['missing'].split()) or 'such data')}</li>"
               for s in sections if s["present"] != "1"]
    problems = [f"<li>{html.escape(k)}: {html.escape(v)}</li>" for k, v in summary if k in ("damage", "note")]
    log = dict(summary).get("log", "")
    page = f"""<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>Flight report: {html.escape(os.path.basename(log))}</title>
<style>body{{font-family:sans-serif;max-width:1150px;margin:auto}} img{{max-width:100%}}
table.summary th{{text-align:left;padding-right:1em;font-weight:normal;color:#444}}
.damage{{color:#a00}} .partial{{color:#666}}</style></head>
<body>
<h1>Flight report: {html.escape(log)}</h1>
{summary_table(summary)}
{('<ul class="damage">' + chr(10).join(problems) + '</ul>') if problems else ''}
{chr(10).join(body)}
<section id="missing"><h2>Sections not in this log</h2>
<ul>{chr(10).join(missing) if missing else '<li>none: every section is present</li>'}</ul></section>
<p class="data">Also: <a href="summary.csv">summary.csv</a> <a href="sections.csv">sections.csv</a>.
Written by aerie-log report (docs/logs.md, "Flight report").</p>
</body></html>
"""
    with open(os.path.join(out, "index.html"), "w") as f:
        f.write(page)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])

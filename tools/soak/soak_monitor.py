#!/usr/bin/env python3
"""The soak's sampler and operator (scripts/soak.sh starts it; docs/results/soak.md).

  soak_monitor.py --out DIR --types PYDIR [--deputy-pid PID] [--pid NAME=PID ...]
                  [--parent PID] [--period S] [--image-size WxH]

Once a period (1 s) it reads, for every process of the chain, /proc/PID/status (VmRSS,
Threads) and /proc/PID/stat (utime + stime), and appends a row per process to
DIR/samples.csv:  time_s, utime, node, pid, rss_kb, cpu_percent, threads, udp_drops
(cpu_percent: of one core, over the last period; udp_drops: datagrams the kernel dropped
because the process's UDP receive buffers were full, from /proc/net/udp, cumulative: with
LCM's UDP multicast every node's socket receives every channel, so a node that falls
behind loses datagrams here, whole messages or fragments of images), and a row for the host to DIR/host.csv:
  time_s, load1, cpu_percent (of one core: 100 x cores = all busy), mem_used_kb,
  backlog_drops (/proc/net/softnet_stat: packets dropped for a full per-CPU input queue,
  which loopback traffic goes through; host-wide, cumulative since boot). The processes are the deputy's commands
(their names and pids from the deputy's PMD_INFO2 reports) and the ones given with
--deputy-pid / --pid (Xvfb, ...); the monitor samples itself as "soak-monitor".

It listens to the chain's LCM network (LCM_DEFAULT_URL, UDP multicast; small messages
only, which every status message is) and writes the counters of the newest STATUS_*
message of each node once a period to DIR/counters.csv:
  time_s, node, pid, status_seq, health, counter, value
(node: the procman command whose pid the status message carries, else the channel's name
in lower case). Gaps in the status messages' seq as this monitor received them are
counted in DIR/monitor.json (the monitor's own losses, not the logger's).

Events (DIR/events.csv): pids of the commands, the pilot's state changes (PILOT_STATE, with
the reason), what the operator below sent.

Operator (the operator's box of the demo, for every flight after the first): SIGUSR1 means
"a flight has ended": the monitor sends TRACK_CMD STOP (the tracker goes IDLE) and MAP_CMD
CLEAR (aerie-vo restarts its odometry, and so its world frame, with every flight: the last
flight's map would be in another frame, and the map would grow by a room a flight). During the
next flight, when TRACK says IDLE and GT_TRACK has a visible box, it sends TRACK_CMD INIT on
that box (cut to the image, --image-size), again after 0.5 s until TRACK leaves IDLE. The
tracker initialises itself from GT_TRACK only once per process (config/track_landing.yaml,
init_from_gt), so without this the flights after the first would have no target.

Stops on SIGTERM, SIGINT (unless --ignore-sigint), or when --parent has gone, writing
everything collected.
"""
import argparse
import csv
import json
import os
import re
import select
import signal
import socket
import struct
import sys
import time

LC02 = 0x4C433032  # LCM short message: magic, seqno, channel\0, payload
CLK_TCK = os.sysconf("SC_CLK_TCK")
PAGE_KB = os.sysconf("SC_PAGE_SIZE") // 1024


def parse_url(url):
    m = re.match(r"udpm://([0-9.]+):([0-9]+)", url or "")
    if not m:
        raise SystemExit(f"soak_monitor: need a udpm:// LCM URL, not '{url}'")
    return m.group(1), int(m.group(2))


class Lcm:
    """Just enough of LCM's UDP multicast transport: receive and send short messages."""

    def __init__(self, url):
        self.group, self.port = parse_url(url)
        self.rx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
        self.rx.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            self.rx.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4 << 20)
        except OSError:
            pass
        self.rx.bind(("", self.port))
        mreq = struct.pack("4s4s", socket.inet_aton(self.group), socket.inet_aton("0.0.0.0"))
        self.rx.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, mreq)
        self.rx.setblocking(False)
        self.tx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
        self.tx.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 0)
        self.tx.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
        self.seqno = 0

    def receive(self):
        """Every pending short message as (channel, payload)."""
        out = []
        while True:
            try:
                data = self.rx.recv(65536)
            except (BlockingIOError, InterruptedError):
                return out
            if len(data) < 9 or struct.unpack_from(">I", data, 0)[0] != LC02:
                continue  # a fragment of a large message (images): not ours
            end = data.find(b"\0", 8)
            if end < 0:
                continue
            out.append((data[8:end].decode("ascii", "replace"), data[end + 1:]))

    def publish(self, channel, payload):
        packet = struct.pack(">II", LC02, self.seqno) + channel.encode() + b"\0" + payload
        self.seqno = (self.seqno + 1) & 0xFFFFFFFF
        self.tx.sendto(packet, (self.group, self.port))


def proc_sample(pid):
    """(rss_kb, cpu_ticks, threads, start_ticks) of a live pid, or None."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            stat = f.read()
        fields = stat[stat.rindex(")") + 2:].split()
        # fields[0] is field 3 (state): utime 14, stime 15, num_threads 20, starttime 22, rss 24
        ticks = int(fields[11]) + int(fields[12])
        threads = int(fields[17])
        start = int(fields[19])
        rss_kb = int(fields[21]) * PAGE_KB
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    rss_kb = int(line.split()[1])
                    break
        return rss_kb, ticks, threads, start
    except (OSError, ValueError, IndexError):
        return None


def udp_drops():
    """Socket inode -> packets the kernel dropped for it (a full receive buffer), /proc/net/udp."""
    out = {}
    try:
        with open("/proc/net/udp") as f:
            next(f)
            for line in f:
                v = line.split()
                out[v[9]] = int(v[12])  # inode, drops
    except (OSError, IndexError, ValueError, StopIteration):
        pass
    return out


def socket_inodes(pid):
    inodes = []
    try:
        for fd in os.listdir(f"/proc/{pid}/fd"):
            try:
                link = os.readlink(f"/proc/{pid}/fd/{fd}")
            except OSError:
                continue
            if link.startswith("socket:["):
                inodes.append(link[8:-1])
    except OSError:
        pass
    return inodes


def host_sample():
    """(load1, busy jiffies, total jiffies, mem_used_kb, backlog drops) of the host."""
    with open("/proc/loadavg") as f:
        load1 = float(f.read().split()[0])
    with open("/proc/stat") as f:
        v = [int(x) for x in f.readline().split()[1:]]
    idle = v[3] + (v[4] if len(v) > 4 else 0)
    mem = {}
    with open("/proc/meminfo") as f:
        for line in f:
            k, _, rest = line.partition(":")
            mem[k] = int(rest.split()[0])
    backlog_drops = 0  # packets dropped for a full per-CPU input queue (loopback goes through it)
    try:
        with open("/proc/net/softnet_stat") as f:
            backlog_drops = sum(int(line.split()[1], 16) for line in f)
    except (OSError, IndexError, ValueError):
        pass
    return load1, sum(v) - idle, sum(v), mem.get("MemTotal", 0) - mem.get("MemAvailable", 0), backlog_drops


def uptime_s():
    with open("/proc/uptime") as f:
        return float(f.read().split()[0])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", required=True)
    ap.add_argument("--types", required=True, help="lcm-gen -p output of lcmtypes/")
    ap.add_argument("--deputy-pid", type=int, default=0)
    ap.add_argument("--pid", action="append", default=[], help="NAME=PID, sampled too")
    ap.add_argument("--parent", type=int, default=0, help="exit when this process has gone")
    ap.add_argument("--period", type=float, default=1.0)
    ap.add_argument("--ignore-sigint", action="store_true", help="stop on SIGTERM only (a Ctrl-C meant for the flights)")
    ap.add_argument("--image-size", default="376x240", help="CAM_DOWN's size, to cut INIT boxes")
    ap.add_argument("--lcm-url", default=os.environ.get("LCM_DEFAULT_URL", "udpm://239.255.76.67:7667?ttl=0"))
    a = ap.parse_args()
    sys.path.insert(0, a.types)
    from aerie import gt_box_t, map_cmd_t, pilot_state_t, process_status_t, track_cmd_t, track_t  # noqa: E402
    from bot_procman import info2_t  # noqa: E402

    img_w, img_h = (float(v) for v in a.image_size.lower().split("x"))
    os.makedirs(a.out, exist_ok=True)
    lcm = Lcm(a.lcm_url)
    fixed = {"deputy": a.deputy_pid} if a.deputy_pid else {}
    for p in a.pid:
        name, _, pid = p.partition("=")
        fixed[name] = int(pid)
    fixed["soak-monitor"] = os.getpid()

    stop = [False]
    flight_ended = [0]

    def on_stop(*_):
        stop[0] = True

    def on_usr1(*_):
        flight_ended[0] += 1

    signal.signal(signal.SIGINT, signal.SIG_IGN if a.ignore_sigint else on_stop)
    signal.signal(signal.SIGTERM, on_stop)
    signal.signal(signal.SIGUSR1, on_usr1)

    samples_f = open(os.path.join(a.out, "samples.csv"), "w", newline="")
    counters_f = open(os.path.join(a.out, "counters.csv"), "w", newline="")
    events_f = open(os.path.join(a.out, "events.csv"), "w", newline="")
    host_f = open(os.path.join(a.out, "host.csv"), "w", newline="")
    host = csv.writer(host_f)
    host.writerow(["time_s", "load1", "cpu_percent", "mem_used_kb", "backlog_drops"])
    ncpu = os.cpu_count() or 1
    last_host = None
    samples = csv.writer(samples_f)
    counters = csv.writer(counters_f)
    events = csv.writer(events_f)
    samples.writerow(["time_s", "utime", "node", "pid", "rss_kb", "cpu_percent", "threads", "udp_drops"])
    counters.writerow(["time_s", "node", "pid", "status_seq", "health", "counter", "value"])
    events.writerow(["time_s", "event", "detail"])

    t0 = time.time()
    commands = {}        # procman command name -> pid (0: not running)
    last_ticks = {}      # (name, pid) -> (ticks, wall)
    status = {}          # channel -> newest process_status_t
    status_fresh = set()
    status_seen = {}     # channel -> [messages, seq gaps, last seq]
    undecodable = 0
    track_idle = None    # the newest TRACK's status is IDLE
    pilot_state = None   # the newest PILOT_STATE's state name
    armed = False        # STOP sent; INIT due on the next visible GT_TRACK box
    last_init = 0.0
    cmd_seq = 0
    sent = {"STOP": 0, "INIT": 0, "MAP_CLEAR": 0}

    def event(kind, detail=""):
        events.writerow([f"{time.time() - t0:.3f}", kind, detail])
        events_f.flush()

    def send_track(command, box=None):
        nonlocal cmd_seq
        m = track_cmd_t()
        m.utime = int(time.time() * 1e6)
        m.seq = cmd_seq
        cmd_seq += 1
        m.command = command
        if box:
            m.x, m.y, m.width, m.height = box
        lcm.publish("TRACK_CMD", m.encode())

    next_tick = time.time() + a.period
    while not stop[0]:
        timeout = max(0.0, next_tick - time.time())
        try:
            select.select([lcm.rx], [], [], timeout)
        except InterruptedError:
            pass
        now = time.time()
        for channel, payload in lcm.receive():
            try:
                if channel.startswith("STATUS_"):
                    m = process_status_t.decode(payload)
                    seen = status_seen.setdefault(channel, [0, 0, None])
                    if seen[2] is not None and m.seq > seen[2] + 1:
                        seen[1] += m.seq - seen[2] - 1
                    seen[0] += 1
                    seen[2] = m.seq
                    status[channel] = m
                    status_fresh.add(channel)
                elif channel == "PMD_INFO2":
                    m = info2_t.decode(payload)
                    for c in m.cmds:
                        name = c.cmd.command_name
                        if commands.get(name) != c.pid:
                            event("pid", f"{name} {commands.get(name, 0)} -> {c.pid}")
                        commands[name] = c.pid
                elif channel == "PILOT_STATE":
                    m = pilot_state_t.decode(payload)
                    if m.state_name != pilot_state:
                        pilot_state = m.state_name
                        event("pilot", f"{m.state_name}: {m.reason}")
                elif channel == "TRACK":
                    track_idle = track_t.decode(payload).status == track_t.IDLE
                    if not track_idle and armed:
                        armed = False
                        event("tracking", "TRACK left IDLE")
                elif channel == "GT_TRACK" and armed and track_idle and now - last_init >= 0.5:
                    g = gt_box_t.decode(payload)
                    if g.visible:
                        x0, y0 = max(0.0, g.x), max(0.0, g.y)
                        x1, y1 = min(img_w, g.x + g.width), min(img_h, g.y + g.height)
                        if x1 - x0 >= 2 and y1 - y0 >= 2:
                            send_track(track_cmd_t.INIT, (x0, y0, x1 - x0, y1 - y0))
                            sent["INIT"] += 1
                            last_init = now
                            event("TRACK_CMD INIT", f"{x0:.1f} {y0:.1f} {x1 - x0:.1f} {y1 - y0:.1f} (GT_TRACK seq {g.seq})")
            except (ValueError, struct.error, UnicodeDecodeError):
                undecodable += 1
        while flight_ended[0] > 0:
            flight_ended[0] -= 1
            send_track(track_cmd_t.STOP)
            sent["STOP"] += 1
            c = map_cmd_t()
            c.utime, c.seq, c.command = int(time.time() * 1e6), sent["MAP_CLEAR"], map_cmd_t.CLEAR
            lcm.publish("MAP_CMD", c.encode())
            sent["MAP_CLEAR"] += 1
            event("MAP_CMD CLEAR", "flight ended")
            armed, track_idle, last_init = True, None, 0.0
            event("TRACK_CMD STOP", "flight ended")
        if now < next_tick:
            continue
        next_tick += a.period
        if next_tick < now:  # fell behind (a loaded machine): no burst of catch-up ticks
            next_tick = now + a.period
        if a.parent and not os.path.exists(f"/proc/{a.parent}"):
            event("parent gone", str(a.parent))
            break
        t = now - t0
        load1, busy, total, mem_used, backlog = host_sample()
        if last_host and total > last_host[1]:
            host.writerow([f"{t:.3f}", load1, f"{100.0 * ncpu * (busy - last_host[0]) / (total - last_host[1]):.1f}",
                           mem_used, backlog])
        last_host = (busy, total)
        procs = dict(fixed)
        for name, pid in commands.items():
            if pid > 0:
                procs[name] = pid
        drops = udp_drops()
        for name, pid in sorted(procs.items()):
            s = proc_sample(pid)
            if s is None:
                continue
            rss_kb, ticks, threads, start = s
            prev = last_ticks.get((name, pid))
            if prev:
                cpu = 100.0 * (ticks - prev[0]) / CLK_TCK / max(1e-3, now - prev[1])
            else:  # a new process: its mean since it started
                cpu = 100.0 * ticks / CLK_TCK / max(1e-3, uptime_s() - start / CLK_TCK)
            last_ticks[(name, pid)] = (ticks, now)
            dropped = sum(drops.get(i, 0) for i in socket_inodes(pid))
            samples.writerow([f"{t:.3f}", int(now * 1e6), name, pid, rss_kb, f"{cpu:.2f}", threads, dropped])
        by_pid = {pid: name for name, pid in procs.items()}
        for channel in sorted(status_fresh):
            m = status[channel]
            node = by_pid.get(m.pid, channel[len("STATUS_"):].lower())
            for cname, value in zip(m.counter_names, m.counter_values):
                counters.writerow([f"{t:.3f}", node, m.pid, m.seq, m.health, cname, value])
        status_fresh.clear()
        samples_f.flush()
        counters_f.flush()
        host_f.flush()

    for f in (samples_f, counters_f, events_f, host_f):
        f.close()
    with open(os.path.join(a.out, "monitor.json"), "w") as f:
        json.dump({"start_utime": int(t0 * 1e6), "end_utime": int(time.time() * 1e6),
                   "status_messages": {c: {"received": v[0], "seq_gaps": v[1]} for c, v in sorted(status_seen.items())},
                   "undecodable": undecodable, "track_cmd_sent": sent}, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())

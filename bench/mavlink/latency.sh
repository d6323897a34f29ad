#!/usr/bin/env bash
# Latency from a camera frame's exposure to the setpoint it causes leaving on the wire, through
# the whole live chain (flightsim -> track -> pilot -> aerie-mavlink -> UDP -> the simulated PX4),
# in real time: runs the demo through MAVLink and prints aerie-mavlink's p50/p99 (it measures
# every setpoint a CTRL_CMD causes: the node's clock at the write minus the camera frame's utime).
#   bash bench/mavlink/latency.sh [--precland] [--seed N]
set -euo pipefail
cd "$(dirname "$0")/../.."
case "${1:-}" in -h|--help) sed -n '2,6p' "$0"; exit 0 ;; esac
mode=--mavlink
args=()
while [ $# -gt 0 ]; do
  case "$1" in
    --precland) mode=--precland; shift ;;
    --seed) args+=(--seed "$2"); shift 2 ;;
    *) echo "latency.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
done
out=$(bash scripts/demo.sh "$mode" "${args[@]}" 2>&1) || true
echo "$out" | grep '^demo: LANDED\|^demo: NOT LANDED\|^demo: the flight' || true
log=$(echo "$out" | sed -n 's/^demo: wrote \(logs\/demo-[0-9-]*\.lcm\)$/\1/p' | head -n 1)
[ -n "$log" ] || { echo "latency.sh: the demo wrote no log" >&2; exit 1; }
# aerie-mavlink's exit line travels in the log as procman output (PMD_PRINTF).
/usr/bin/python3 - "$log" <<'PY'
import struct, sys
data = open(sys.argv[1], 'rb').read()
i = 0
while i + 28 <= len(data):
    _, _, _, cl, dl = struct.unpack('>IqqII', data[i:i + 28]); i += 28
    ch = data[i:i + cl].decode(); i += cl
    body = data[i:i + dl]; i += dl
    if ch == 'PMD_PRINTF':
        text = ''.join(chr(c) for c in body if 32 <= c < 127 or c == 10)
        for line in text.split('\n'):
            if 'camera frame to setpoint' in line:
                print('latency.sh:', line[line.index('camera'):])
PY
echo "latency.sh: machine load $(cut -d' ' -f1-3 /proc/loadavg) (1, 5, 15 min)"

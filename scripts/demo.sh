#!/usr/bin/env bash
# The demo flight (README's first command):
#   bash scripts/demo.sh [--duration SECONDS] [-- extra aerie-capture options]
# Installs missing packages and builds (scripts/build.sh), then flies the simulated
# stereo drone through the textured room (take-off, survey loop, approach, descent
# onto the helipad; 376x240 stereo at 20 Hz, real time, about a minute). aerie-capture
# publishes it over LCM, the stock lcm-logger records everything into
# logs/demo-YYYYmmdd-HHMMSS.lcm, and `aerie-log info` summarises the log at the end
# (channels, counts, rates, duration, dropped messages). Ctrl-C ends the flight early;
# the log is still closed properly and summarised.
set -euo pipefail
cd "$(dirname "$0")/.."

duration=0   # seconds of flight; 0 = the whole trajectory
capture_extra=()
while [ $# -gt 0 ]; do
  case "$1" in
    --duration) duration="$2"; shift 2 ;;
    --) shift; capture_extra=("$@"); break ;;
    -h|--help) sed -n '2,10p' "$0"; exit 0 ;;
    *) echo "demo: unknown option '$1' (see --help)" >&2; exit 1 ;;
  esac
done

bash scripts/build.sh
BIN=build/default/bin

# --- LCM on this host: UDP multicast that never leaves it (ttl=0) -----------------
export LCM_DEFAULT_URL='udpm://239.255.76.67:7667?ttl=0'
# lcm-logger gets a 4 MB socket receive buffer (bounded by net.core.rmem_max): stereo
# frames arrive as bursts of fragments that overflow the kernel default (docs/logs.md).
LOGGER_URL="$LCM_DEFAULT_URL&recv_buf_size=4194304"
if ! ip route show 224.0.0.0/4 2>/dev/null | grep -q .; then
  if [ "$(id -u)" -eq 0 ]; then
    ip route add 224.0.0.0/4 dev lo
    echo "demo: added the multicast route 224.0.0.0/4 on lo (ip route add 224.0.0.0/4 dev lo)"
  else
    echo "demo: no multicast route; as root run: ip route add 224.0.0.0/4 dev lo" >&2
  fi
fi
rmem_max=$(sysctl -n net.core.rmem_max 2>/dev/null || echo 0)
if [ "$rmem_max" -lt 4194304 ] && [ "$(id -u)" -eq 0 ]; then
  sysctl -q -w net.core.rmem_max=4194304
  echo "demo: raised net.core.rmem_max from $rmem_max to 4194304 (UDP receive buffers for images)"
fi

# --- Processes ---------------------------------------------------------------------
mkdir -p logs
LOG="logs/demo-$(date +%Y%m%d-%H%M%S).lcm"
# The viewer renders off-screen but needs an X server: a private Xvfb unless one is set.
xvfb_pid=""
DEMO_DISPLAY=${DISPLAY:-}
if [ -z "$DEMO_DISPLAY" ]; then
  DEMO_DISPLAY=:$((90 + RANDOM % 100))
  Xvfb "$DEMO_DISPLAY" -screen 0 1280x1024x24 -nolisten tcp >/dev/null 2>&1 &
  xvfb_pid=$!
fi
capture=("$BIN/aerie-capture" --source sim --sim-trajectory demo --width 376 --height 240 --fps 20 --rate 1)
[ "$duration" != 0 ] && capture+=(--duration "$duration")
capture+=("${capture_extra[@]}")

# ===== EXTRA PROCESSES ==============================================================
# Later capabilities add their nodes here, one command per entry (they inherit
# LCM_DEFAULT_URL). They start after the logger and before the flight, and are
# stopped with SIGINT after it, e.g.:
#   "$BIN/aerie-track --config config/track.yaml"
#   "$BIN/aerie-vo --config config/vo.yaml"
EXTRA_PROCESSES=(
  # air: track the helipad (initialised on its ground-truth box after 20 frames; 1 m pad)
  "$BIN/aerie-track --camera CAM_LEFT --init-from-gt 20 --target-size 1.0"
  # air: stereo visual odometry and compact depth for the map
  "$BIN/aerie-vo --config config/vo.yaml"
  # air: the fuzzy heading controller, on the simulator's ground-truth heading
  "$BIN/aerie-control --input gt"
  # ground: the occupancy map, saved next to the log at the end
  "$BIN/aerie-map --config config/map.yaml --save ${LOG%.lcm}-map.bt"
  # ground: the dashboard, off-screen; its snapshot is written next to the log at the end
  "env DISPLAY=$DEMO_DISPLAY $BIN/aerie-viewer --snapshot ${LOG%.lcm}-dashboard.png"
)
# ====================================================================================

pids=()      # extra processes
logger_pid=""
capture_pid=""
interrupted=0

stop_pid() {  # stop_pid PID NAME: SIGINT, then SIGKILL after 5 s
  local pid=$1 name=$2
  kill -0 "$pid" 2>/dev/null || return 0
  kill -INT "$pid" 2>/dev/null || true
  for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
  if kill -0 "$pid" 2>/dev/null; then
    echo "demo: $name did not stop on SIGINT; killing it" >&2
    kill -KILL "$pid" 2>/dev/null || true
  fi
  wait "$pid" 2>/dev/null || true
}

cleanup() {
  [ -n "$capture_pid" ] && stop_pid "$capture_pid" aerie-capture
  for ((i = ${#pids[@]} - 1; i >= 0; i--)); do stop_pid "${pids[$i]}" "extra process $i"; done
  if [ -n "$logger_pid" ]; then
    sleep 0.5  # let the last datagrams reach the logger
    stop_pid "$logger_pid" lcm-logger
    logger_pid=""
  fi
  if [ -n "$xvfb_pid" ]; then
    kill "$xvfb_pid" 2>/dev/null || true
    xvfb_pid=""
  fi
}
trap cleanup EXIT
trap 'interrupted=1; echo; echo "demo: interrupted, landing early"; [ -n "$capture_pid" ] && kill -INT "$capture_pid" 2>/dev/null || true' INT TERM

echo "demo: recording $LOG (lcm-logger on $LCM_DEFAULT_URL)"
lcm-logger --quiet --lcm-url="$LOGGER_URL" "$LOG" &
logger_pid=$!
for _ in $(seq 100); do [ -f "$LOG" ] && break; sleep 0.05; done
sleep 0.3
[ -f "$LOG" ] || { echo "demo: lcm-logger did not start" >&2; exit 1; }

for cmd in "${EXTRA_PROCESSES[@]}"; do
  bash -c "exec $cmd" &
  pids+=($!)
done

echo "demo: flying: ${capture[*]}"
"${capture[@]}" &
capture_pid=$!
status=0
while kill -0 "$capture_pid" 2>/dev/null; do
  wait "$capture_pid" && status=0 || status=$?
done
capture_pid=""
cleanup
trap - EXIT

echo
"$BIN/aerie-log" info "$LOG" || true
if [ "$status" -ne 0 ] && [ "$interrupted" -eq 0 ]; then
  echo "demo: aerie-capture failed (exit status $status)" >&2
  exit "$status"
fi
"$BIN/aerie-latency" "$LOG" || true
for f in "${LOG%.lcm}-dashboard.png" "${LOG%.lcm}-map.bt"; do
  [ -f "$f" ] && echo "demo: wrote $f"
done
echo "demo: replay with: lcm-logplayer $LOG   (inspect: $BIN/aerie-log info $LOG)"

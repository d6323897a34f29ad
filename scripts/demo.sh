#!/usr/bin/env bash
# The autonomous demo flight (README's first command):
#   bash scripts/demo.sh [--seed N] [--mavlink | --precland]
# Installs missing packages and builds what it flies (scripts/build.sh, CMake target
# "demo"; scripts/test.sh builds everything), then flies the closed loop in
# real time under procman, as config/demo.pmd writes it: the simulated drone takes off in
# the textured room, surveys, finds the helipad with its down camera, approaches, descends
# on the tracker's 3D estimate and lands; VO and the map run on the forward stereo pair,
# aerie-log record records everything into logs/demo-YYYYmmdd-HHMMSS.lcm, the viewer writes a
# dashboard snapshot. It ends with one line (landed or not, touchdown error, time), the
# log's summary (aerie-log info) and the files written. Ctrl-C stops the flight early; the
# log is still closed and summarised. About a minute.
#   --mavlink   the pilot's commands go through aerie-mavlink (signed MAVLink 2 over UDP) to the
#               simulator's PX4 autopilot, which Aerie flies in OFFBOARD (docs/mavlink.md)
#   --precland  the same, and the autopilot lands itself on Aerie's LANDING_TARGET (AUTO.PRECLAND)
set -euo pipefail
cd "$(dirname "$0")/.."

seed=1
script=fly
export AERIE_LANDING=aerie
while [ $# -gt 0 ]; do
  case "$1" in
    --seed) seed="$2"; shift 2 ;;
    --mavlink) script=fly_mavlink; shift ;;
    --precland) script=fly_mavlink; AERIE_LANDING=autopilot; shift ;;
    -h|--help) sed -n '2,15p' "$0"; exit 0 ;;
    *) echo "demo: unknown option '$1' (see --help)" >&2; exit 1 ;;
  esac
done

bash scripts/build.sh default --target demo
BIN=build/default/bin

# --- LCM on this host: UDP multicast that never leaves it (ttl=0) -----------------
# (the multicast route on lo and 4 MiB receive buffers, as root: scripts/local-lcm.sh)
source scripts/local-lcm.sh
aerie_local_lcm demo

# --- What the deputy expands in config/demo.pmd ------------------------------------
mkdir -p logs
stem="logs/demo-$(date +%Y%m%d-%H%M%S)"
export AERIE_LOG="$stem.lcm" AERIE_MAP="$stem-map.bt" AERIE_RESULT="$stem-result.txt"
export AERIE_SNAPSHOT="$stem-dashboard.png" AERIE_SEED="$seed"
# The viewer renders off-screen but needs an X server: a private Xvfb unless one is set.
aerie_start_xvfb

deputy_pid=""
cleanup() {
  if [ -n "$deputy_pid" ] && kill -0 "$deputy_pid" 2>/dev/null; then
    kill -INT "$deputy_pid" 2>/dev/null || true  # the deputy stops what still runs
    wait "$deputy_pid" 2>/dev/null || true
  fi
  [ -n "$xvfb_pid" ] && kill "$xvfb_pid" 2>/dev/null || true
}
trap cleanup EXIT
trap 'echo; echo "demo: interrupted; stopping the flight"' INT

# Keyed procman (docs/procman.md "Keyed mode"): this run's own mission key (logs/ is not committed).
mission_key="${AERIE_MISSION_KEY:-$stem-mission.key}"
[ -f "$mission_key" ] || "$BIN/aerie-keys" generate --out "$mission_key" >/dev/null
# The MAVLink signing key shared by aerie-mavlink and the simulated autopilot (--mavlink, --precland).
export AERIE_MAVLINK_KEY="$stem-mavlink.key"
[ "$script" = fly ] || "$BIN/aerie-keys" generate --out "$AERIE_MAVLINK_KEY" >/dev/null
"$BIN/aerie-deputy" --name local --key "$mission_key" --state "$stem-deputy.counters" >"$stem-deputy.log" 2>&1 &
deputy_pid=$!
via="directly"; [ "$script" = fly_mavlink ] && via="through MAVLink ($([ "$AERIE_LANDING" = autopilot ] && echo "the autopilot's precision landing" || echo "Aerie flies in OFFBOARD"))"
echo "demo: flying $via (procman: config/demo.pmd, script $script, seed $seed); recording $AERIE_LOG"
status=0
"$BIN/aerie-sheriff" config/demo.pmd --key "$mission_key" --script "$script" --on-script-complete exit --no-table --wait-timeout 300 \
  >"$stem-sheriff.log" 2>&1 || status=$?
cleanup
trap - EXIT INT

echo
if [ -f "$AERIE_RESULT" ]; then
  echo "demo: $(cat "$AERIE_RESULT")"
else
  echo "demo: the flight did not finish (no result; sheriff exit status $status, see $stem-sheriff.log)"
fi
[ -f "$AERIE_LOG" ] && { "$BIN/aerie-log" info "$AERIE_LOG" || true; }
# The flight report (docs/logs.md "Flight report"): a failure only warns, the result stands.
if [ -f "$AERIE_LOG" ]; then
  "$BIN/aerie-log" report "$AERIE_LOG" --out "$stem-report" --force >"$stem-report.log" 2>&1 ||
    echo "demo: warning: the flight report failed or the log is damaged (see $stem-report.log)"
  [ -f "$stem-report/index.html" ] || echo "demo: warning: no report page: $(tail -n 1 "$stem-report.log")"
fi
for f in "$AERIE_LOG" "$AERIE_MAP" "$AERIE_SNAPSHOT" "$stem-report/index.html" "$stem-sheriff.log" "$stem-deputy.log"; do
  [ -f "$f" ] && echo "demo: wrote $f"
done
echo "demo: replay with: lcm-logplayer $AERIE_LOG   (inspect: $BIN/aerie-log info $AERIE_LOG)"
[ -f "$AERIE_RESULT" ] && grep -q "^LANDED" "$AERIE_RESULT"

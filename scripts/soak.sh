#!/usr/bin/env bash
# The soak: the autonomous demo flight (scripts/demo.sh, config/demo.pmd) flown again and
# again in real time by one long-running chain, its processes sampled once a second.
#   bash scripts/soak.sh [--minutes N | --flights N] [--seed N] [--same-seed] [--out DIR] [--warmup-minutes M]
#                        [--netns] [--keep-log] [--bin DIR] [--recv-buf-size BYTES]
#                        [--kill NODES] [--kill-window A:B]
# One deputy and one logger (aerie-log record), aerie-map, aerie-viewer, aerie-vo and
# aerie-track run the whole time; each flight restarts aerie-pilot (its mission ends LANDED)
# and aerie-flightsim with the next seed (--seed, then +1 per flight; with --same-seed every
# flight is --seed's: the same room and pad, so RSS compares like with like), through a headless
# sheriff per flight. Between flights the tracker gets TRACK_CMD STOP, and INIT on the pad's
# box when it comes into view (the operator's box), and the map MAP_CMD CLEAR (VO restarts
# its frame with each flight): tools/soak/soak_monitor.py, which also samples RSS, CPU and
# STATUS_* counters. Flights start until N minutes (default 30, fractions allowed) have
# passed, or N flights have flown; the last one lands first. At the end: the logger's losses
# (aerie-log info on the whole log), per-node RSS growth after the warm-up (default 3 min,
# at most a third of the run), CPU, landings, and rss.png / cpu.png, in OUT/soak.md
# (OUT default logs/soak-YYYYmmdd-HHMMSS). The log (~0.3 GB a minute) is deleted once
# summarised unless --keep-log. --netns runs it all in a private network namespace (root),
# away from any other LCM traffic of the host. Ctrl-C stops early and still summarises.
# --recv-buf-size gives every node's LCM socket another receive buffer (recv_buf_size in
# LCM_DEFAULT_URL; scripts/local-lcm.sh gives 4 MiB), to compare the drops.
# --kill track,pilot,vo: a fault per flight, the nodes in turn: kill -9 of that air node at a
# time drawn from the flight's seed in A:B seconds after the vehicle starts (--kill-window,
# default 4:16); procman respawns it (auto_respawn, config/demo.pmd). flights.csv then says
# which node died when, and how soon its new process ran (docs/faults.md).
# Builds nothing when the binaries exist (else scripts/build.sh); --bin takes the nodes from
# another build's bin/ (the suite's smoke test). Exit 0 when every flight landed within the
# success bounds and the logger lost nothing.
set -euo pipefail
self="$(readlink -f "$0")"
caller_pwd="${AERIE_SOAK_PWD:-$PWD}"  # paths in the options are relative to it
cd "$(dirname "$0")/.."
args=("$@")

minutes=30 flights=0 seed=1 same_seed=0 out="" warmup=3 netns=0 keep_log=0 BIN="" recv_buf="" kill_nodes=() kill_window=4:16
number() { [[ "$2" =~ ^[0-9]+([.][0-9]+)?$ ]] || { echo "soak: $1 needs a number, not '$2'" >&2; exit 2; }; }
while [ $# -gt 0 ]; do
  case "$1" in
    --minutes) number "$1" "${2:-}"; minutes="$2"; shift 2 ;;
    --flights) [[ "${2:-}" =~ ^[1-9][0-9]*$ ]] || { echo "soak: --flights needs a count" >&2; exit 2; }; flights="$2"; shift 2 ;;
    --seed) [[ "${2:-}" =~ ^[0-9]+$ ]] || { echo "soak: --seed needs an integer" >&2; exit 2; }; seed="$2"; shift 2 ;;
    --same-seed) same_seed=1; shift ;;
    --out) out="${2:-}"; [ -n "$out" ] || { echo "soak: --out needs a folder" >&2; exit 2; }; shift 2 ;;
    --warmup-minutes) number "$1" "${2:-}"; warmup="$2"; shift 2 ;;
    --netns) netns=1; shift ;;
    --keep-log) keep_log=1; shift ;;
    --recv-buf-size) [[ "${2:-}" =~ ^[1-9][0-9]*$ ]] || { echo "soak: --recv-buf-size needs bytes" >&2; exit 2; }
                     recv_buf="$2"; shift 2 ;;
    --kill) IFS=, read -r -a kill_nodes <<<"${2:-}"
            [ ${#kill_nodes[@]} -gt 0 ] || { echo "soak: --kill needs air nodes (track, pilot, vo)" >&2; exit 2; }
            for k in "${kill_nodes[@]}"; do
              [[ "$k" =~ ^(track|pilot|vo)$ ]] || { echo "soak: --kill: '$k' is not an air node of config/demo.pmd (track, pilot, vo)" >&2; exit 2; }
            done; shift 2 ;;
    --kill-window) [[ "${2:-}" =~ ^[0-9]+([.][0-9]+)?:[0-9]+([.][0-9]+)?$ ]] && awk "BEGIN{split(\"$2\", w, \":\"); exit !(w[1] <= w[2])}" ||
                     { echo "soak: --kill-window needs A:B seconds with A <= B, not '${2:-}'" >&2; exit 2; }
                   kill_window="$2"; shift 2 ;;
    --bin) BIN="${2:-}"; [[ "$BIN" = /* ]] || BIN="$caller_pwd/$BIN"
           [ -d "$BIN" ] || { echo "soak: --bin needs a folder of binaries, not '${2:-}'" >&2; exit 2; }; shift 2 ;;
    -h|--help) awk 'NR > 1 && /^#/ {sub(/^# ?/, ""); print; next} NR > 1 {exit}' "$self"; exit 0 ;;
    *) echo "soak: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
done
awk "BEGIN{exit !($minutes > 0)}" || { echo "soak: --minutes must be > 0" >&2; exit 2; }
[ -z "$out" ] || [[ "$out" = /* ]] || out="$caller_pwd/$out"  # --out is relative to where soak.sh was called

need=(aerie-deputy aerie-sheriff aerie-flightsim aerie-track aerie-pilot aerie-vo aerie-map aerie-viewer aerie-log)
if [ -n "$BIN" ]; then
  BIN="$(cd "$BIN" && pwd)"
  for b in "${need[@]}"; do [ -x "$BIN/$b" ] || { echo "soak: $BIN has no $b" >&2; exit 2; }; done
else
  BIN=build/default/bin
  for b in "${need[@]}"; do
    if [ ! -x "$BIN/$b" ]; then bash scripts/build.sh; break; fi
  done
fi
# Python with matplotlib (scripts/setup.sh installs Debian's): /usr/bin/python3 before another on PATH.
PY=python3
[ -x /usr/bin/python3 ] && PY=/usr/bin/python3
for tool in lcm-gen "$PY" Xvfb; do
  command -v "$tool" >/dev/null || { echo "soak: '$tool' is missing (bash scripts/setup.sh)" >&2; exit 1; }
done

# --- A private network namespace (--netns): run this script again inside one ---------
if [ "$netns" = 1 ] && [ -z "${AERIE_SOAK_NETNS:-}" ]; then
  [ "$(id -u)" -eq 0 ] || { echo "soak: --netns needs root (ip netns add)" >&2; exit 2; }
  # A namespace left by a run that was killed (SIGKILL, e.g. a test's timeout, runs no trap):
  # its shell is gone and nothing runs in it any more.
  for old in $(ip netns list | awk '/^aerie-soak-[0-9]+( |$)/ {print $1}'); do
    kill -0 "${old#aerie-soak-}" 2>/dev/null || [ -n "$(ip netns pids "$old" 2>/dev/null)" ] ||
      { ip netns del "$old" && echo "soak: removed $old, left by a run that was killed"; }
  done
  ns="aerie-soak-$$"
  ip netns add "$ns"
  trap 'ip netns del "$ns" 2>/dev/null || true' EXIT
  ip netns exec "$ns" ip link set lo up
  status=0
  AERIE_SOAK_PWD="$caller_pwd" AERIE_SOAK_COMMAND="scripts/soak.sh ${args[*]}" AERIE_SOAK_NETNS="$ns" ip netns exec "$ns" bash "$self" "${args[@]}" || status=$?
  exit "$status"
fi

[ -n "$out" ] || out="logs/soak-$(date +%Y%m%d-%H%M%S)"
mkdir -p "$out/flights" "$out/pmd" "$out/sheriff"
out="$(cd "$out" && pwd)"

# The log grows by ~5 MB/s (the stereo pair, the down camera): refuse to fill the disk.
need_mb=$(awk "BEGIN{m = $flights > 0 ? $flights * 0.6 : $minutes; printf \"%d\", (m + 2) * 400}")
free_mb=$(df -Pm "$out" | awk 'NR == 2 {print $4}')
if [ "$free_mb" -lt "$need_mb" ]; then
  echo "soak: the log needs about $need_mb MB, only $free_mb MB free under $out" >&2
  exit 1
fi

# --- LCM on this host (or in the namespace), an X server for the viewer ----------------
source scripts/local-lcm.sh
aerie_local_lcm soak
[ -z "$recv_buf" ] || export LCM_DEFAULT_URL="$LCM_DEFAULT_URL&recv_buf_size=$recv_buf"
aerie_start_xvfb

# --- What the deputy expands in config/demo.pmd -----------------------------------------
export AERIE_LOG="$out/soak.lcm" AERIE_MAP="$out/map.bt" AERIE_SNAPSHOT="$out/dashboard.png"
export AERIE_RESULT="$out/flights/unused-result.txt" AERIE_SEED="$seed"
# The demo's commands with this flight's seed and result file, and the soak's scripts. A new
# sheriff adopts the running commands (docs/procman.md): only what a script names restarts,
# and a changed exec string (flightsim's seed) takes effect at its next start.
flight_pmd() {  # SEED RESULT
  sed -E -e "s|\\\$\\{AERIE_SEED(:-[^}]*)?\\}|$1|g" -e "s|\\\$\\{AERIE_RESULT(:-[^}]*)?\\}|$2|g" config/demo.pmd
  cat <<'EOF'

# --- scripts/soak.sh ---------------------------------------------------------------------
# Everything but the vehicle and the pilot, recorder first (as start_all).
script "soak_start" {
    start group "ground" wait "running";
    start group "operator" wait "running";
    start cmd "track" wait "running";
    start cmd "vo" wait "running";
}
# One flight: a new pilot (its mission ends LANDED), then the vehicle with this seed.
script "soak_flight" {
    restart cmd "pilot" wait "running";
    wait ms 1000;
    restart cmd "flightsim" wait "running";
    wait cmd "flightsim" status "stopped";
    wait ms 500;
}
EOF
}
# The monitor's LCM types (Python, generated like the C++ ones).
lcm-gen -p --ppath "$out/lcmtypes-py" lcmtypes/*.lcm >/dev/null
down_size=$(awk '/^down_camera:/ {s = 1; next} /^[^ #]/ {s = 0} s && $1 == "width:" {w = $2} s && $1 == "height:" {h = $2}
                 END {print (w ? w : 376) "x" (h ? h : 240)}' config/sim/landing_room.yaml)

deputy_pid="" monitor_pid="" sheriff_pid="" interrupted=0

# of_deputy NAME: the pid of the deputy's child named NAME, from /proc (procps is not a
# dependency of Aerie: a fresh Debian 12 may have no pgrep).
of_deputy() {
  local comm stat ppid d
  for d in /proc/[0-9]*; do  # read builtins, no fork per process
    read -r comm 2>/dev/null <"$d/comm" && [ "$comm" = "$1" ] || continue
    read -r stat 2>/dev/null <"$d/stat" || continue
    read -r _ ppid _ <<<"${stat##*) }"  # "state ppid ...", after the name whatever it holds
    [ "$ppid" = "$deputy_pid" ] && { echo "${d#/proc/}"; return 0; }
  done
  return 0
}
# --kill: waits for this flight's vehicle (an aerie-flightsim of the deputy other than
# OLD_VEHICLE), kill -9s aerie-NODE AT seconds later and times until the deputy runs a new
# one; writes "killed_pid,respawn_s" to FILE (empty fields: no vehicle, no node, no respawn).
kill_during_flight() {  # NODE AT FILE OLD_VEHICLE
  local node=$1 at=$2 file=$3 old=$4 sim="" victim="" new="" t_kill respawn=""
  for _ in $(seq 600); do
    sim=$(of_deputy aerie-flightsim)
    [ -n "$sim" ] && [ "$sim" != "$old" ] && break
    sim=""; sleep 0.1
  done
  [ -n "$sim" ] || { echo "soak: --kill: the deputy ran no new aerie-flightsim within 60 s" >&2; echo "," >"$file"; return 0; }
  sleep "$at"
  victim=$(of_deputy "aerie-$node")
  [ -n "$victim" ] || { echo "soak: --kill: the deputy runs no aerie-$node at $at s" >&2; echo "," >"$file"; return 0; }
  kill -9 "$victim" 2>/dev/null || true
  t_kill=$(date +%s.%N)
  for _ in $(seq 200); do
    new=$(of_deputy "aerie-$node")
    [ -n "$new" ] && [ "$new" != "$victim" ] && break
    new=""; sleep 0.05
  done
  [ -z "$new" ] || respawn=$(awk "BEGIN{printf \"%.2f\", $(date +%s.%N) - $t_kill}")
  echo "$victim,$respawn" >"$file"
}
stop_chain() {
  if [ -n "$deputy_pid" ] && kill -0 "$deputy_pid" 2>/dev/null && [ "$interrupted" = 0 ]; then
    # In order (recorder last), then the deputy stops whatever still runs. (A Ctrl-C reached the
    # deputy too: it is already stopping everything.)
    flight_pmd "$seed" "$out/flights/unused-result.txt" >"$out/pmd/stop.pmd"
    timeout 60 "$BIN/aerie-sheriff" "$out/pmd/stop.pmd" --key "$out/mission.key" --sheriff-id 1 --script stop_all --on-script-complete exit --no-table \
      --wait-timeout 30 --deputy-wait 5 >"$out/sheriff/stop.log" 2>&1 || true
  fi
  if [ -n "$deputy_pid" ]; then
    kill -INT "$deputy_pid" 2>/dev/null || true
    wait "$deputy_pid" 2>/dev/null || true
  fi
  deputy_pid=""
  if [ -n "$monitor_pid" ] && kill -0 "$monitor_pid" 2>/dev/null; then
    kill -TERM "$monitor_pid" 2>/dev/null || true
    wait "$monitor_pid" 2>/dev/null || true
  fi
  monitor_pid=""
  if [ -n "$xvfb_pid" ]; then kill "$xvfb_pid" 2>/dev/null || true; wait "$xvfb_pid" 2>/dev/null || true; fi
  xvfb_pid=""
}
trap stop_chain EXIT
trap 'interrupted=1; echo; echo "soak: interrupted; stopping the chain and summarising"' INT TERM

# Keyed procman (docs/procman.md "Keyed mode"): this soak's mission key; every sheriff of the soak
# (one per flight) is one sheriff to the deputy: --sheriff-id 1, its counters rise across them.
[ -f "$out/mission.key" ] || "$BIN/aerie-keys" generate --out "$out/mission.key" >/dev/null
"$BIN/aerie-deputy" --name local --key "$out/mission.key" --sheriff-id 1 --state "$out/deputy.counters" >"$out/deputy.log" 2>&1 &
deputy_pid=$!
# The monitor ignores SIGINT: a Ctrl-C stops the flights, not the sampling (SIGTERM at the end).
xvfb_arg=()
[ -n "$xvfb_pid" ] && xvfb_arg=(--pid "xvfb=$xvfb_pid")
"$PY" tools/soak/soak_monitor.py --out "$out" --types "$out/lcmtypes-py" --deputy-pid "$deputy_pid" \
  "${xvfb_arg[@]}" --parent $$ --image-size "$down_size" --ignore-sigint >"$out/monitor.log" 2>&1 &
monitor_pid=$!

load0=$(cut -d' ' -f1-3 /proc/loadavg)
if [ "$flights" -gt 0 ]; then span="$flights flight(s)"; else span="$minutes min"; fi
echo "soak: $span from seed $seed in real time (procman: config/demo.pmd); load average $load0; writing $out"
echo "flight,seed,start_s,end_s,landed,success,touchdown_error_m,flight_time_s,result,kill,kill_at_s,killed_pid,respawn_s" >"$out/flights.csv"
t0=$(date +%s.%N)
elapsed() { awk "BEGIN{printf \"%.3f\", $(date +%s.%N) - $t0}"; }

flight_pmd "$seed" "$out/flights/unused-result.txt" >"$out/pmd/start.pmd"
if ! "$BIN/aerie-sheriff" "$out/pmd/start.pmd" --key "$out/mission.key" --sheriff-id 1 --script soak_start --on-script-complete exit --no-table \
     --wait-timeout 60 >"$out/sheriff/start.log" 2>&1; then
  [ "$interrupted" = 1 ] || echo "soak: the chain did not start (see $out/sheriff/start.log)" >&2
  interrupted=1
fi

n=0 landed=0 succeeded=0
while [ "$interrupted" = 0 ]; do
  if [ "$flights" -gt 0 ]; then
    [ "$n" -lt "$flights" ] || break
  else
    awk "BEGIN{exit !($(elapsed) < $minutes * 60)}" || break
  fi
  n=$((n + 1))
  s=$((same_seed ? seed : seed + n - 1))
  tag=$(printf "%04d" "$n")
  result="$out/flights/$tag-result.txt"
  flight_pmd "$s" "$result" >"$out/pmd/flight-$tag.pmd"
  kill_node="" kill_at="" killer_pid=""
  if [ ${#kill_nodes[@]} -gt 0 ]; then
    kill_node=${kill_nodes[$(( (n - 1) % ${#kill_nodes[@]} ))]}
    kill_at=$(awk -v s="$s" -v w="$kill_window" 'BEGIN{split(w, a, ":"); srand(s); printf "%.2f", a[1] + rand() * (a[2] - a[1])}')
    kill_during_flight "$kill_node" "$kill_at" "$out/flights/$tag-kill.txt" \
      "$(of_deputy aerie-flightsim)" &
    killer_pid=$!
  fi
  start=$(elapsed)
  status=0
  # flightsim ends the flight itself (landed, or 120 s of simulated flight); the sheriff's
  # wait is only a backstop for a hung one, long enough for a sanitizer build's slower sim.
  "$BIN/aerie-sheriff" "$out/pmd/flight-$tag.pmd" --key "$out/mission.key" --sheriff-id 1 --script soak_flight --on-script-complete exit --no-table \
    --wait-timeout 900 >"$out/sheriff/flight-$tag.log" 2>&1 || status=$?
  end=$(elapsed)
  kill_row=",,,"
  if [ -n "$killer_pid" ]; then
    kill "$killer_pid" 2>/dev/null || true  # a flight that ended before its fault
    wait "$killer_pid" 2>/dev/null || true
    kill_row="$kill_node,$kill_at,$(cat "$out/flights/$tag-kill.txt" 2>/dev/null || echo ",")"
  fi
  [ -n "$monitor_pid" ] && kill -USR1 "$monitor_pid" 2>/dev/null || true  # tracker: STOP, re-arm the INIT
  deputy_gone=0
  kill -0 "$deputy_pid" 2>/dev/null || deputy_gone=1
  if [ "$interrupted" = 1 ]; then  # a result written as the vehicle was stopped is no landing
    line="NOT FINISHED (interrupted)"
  elif [ -f "$result" ]; then
    line=$(head -n1 "$result")
  elif [ "$deputy_gone" = 1 ]; then
    line="NOT FINISHED (the deputy has gone, see deputy.log)"
  else
    line="NOT FINISHED (no result; sheriff exit status $status, see sheriff/flight-$tag.log)"
  fi
  is_landed=0 is_success=0 err="" ftime=""
  [[ "$line" == LANDED* ]] && is_landed=1 && landed=$((landed + 1))
  [[ "$line" == "LANDED (success)"* ]] && is_success=1 && succeeded=$((succeeded + 1))
  [[ "$line" =~ touchdown\ error\ ([0-9.]+)\ m ]] && err="${BASH_REMATCH[1]}"
  [[ "$line" =~ after\ ([0-9.]+)\ s ]] && ftime="${BASH_REMATCH[1]}"
  echo "$n,$s,$start,$end,$is_landed,$is_success,$err,$ftime,\"$line\",$kill_row" >>"$out/flights.csv"
  printf "soak: flight %d (seed %d) at %5.0f s: %s%s\n" "$n" "$s" "$start" "$line" \
    "${kill_node:+ (aerie-$kill_node killed at $kill_at s: $kill_row)}"
  if [ "$deputy_gone" = 1 ] && [ "$interrupted" = 0 ]; then
    echo "soak: the deputy has gone (see $out/deputy.log); stopping" >&2
    break
  fi
done

t_end=$(elapsed)
stop_chain
trap - EXIT INT TERM
load1=$(cut -d' ' -f1-3 /proc/loadavg)
echo "soak: $n flight(s) in $t_end s, $succeeded successful landings; load average $load1"

# --- The logger's losses, the report ---------------------------------------------------------
log_ok=0
if [ -f "$AERIE_LOG" ]; then
  if "$BIN/aerie-log" info "$AERIE_LOG" --json >"$out/log-info.json" 2>"$out/log-info.err" &&
     "$BIN/aerie-log" info "$AERIE_LOG" >"$out/log-info.txt" 2>>"$out/log-info.err"; then
    log_ok=1
  fi
else
  echo "soak: no log was written ($AERIE_LOG)" >&2
fi
cat >"$out/run.json" <<EOF
{"minutes": $minutes, "flights_requested": $flights, "first_seed": $seed, "same_seed": $same_seed, "flights": $n, "duration_s": $t_end,
 "warmup_minutes": $warmup, "interrupted": $interrupted, "netns": "${AERIE_SOAK_NETNS:-}",
 "t0_epoch": $t0, "lcm_url": "$LCM_DEFAULT_URL", "load_start": "$load0", "load_end": "$load1", "host_cpus": $(nproc),
 "command": "${AERIE_SOAK_COMMAND:-scripts/soak.sh ${args[*]}}", "started_utc": "$(date -u -d "@${t0%.*}" '+%Y-%m-%d %H:%M:%S')"}
EOF
report_status=0
"$PY" tools/soak/soak_report.py --out "$out" --warmup-minutes "$warmup" || report_status=$?
if [ "$keep_log" = 0 ] && [ "$log_ok" = 1 ]; then
  rm -f "$AERIE_LOG"
  echo "soak: deleted the log once summarised (log-info.txt; --keep-log keeps it)"
fi
for f in soak.md samples.csv counters.csv flights.csv rss.png cpu.png log-info.txt; do
  [ -f "$out/$f" ] && echo "soak: wrote $out/$f"
done
[ "$report_status" = 0 ] && [ "$n" -gt 0 ] && [ "$succeeded" = "$n" ]

#!/usr/bin/env bash
# live-chain.sh: the live stereo chain on this host, measured (issue 49; docs/stereo.md
# "Keeping up on a small board", figures in docs/results/stereo.md "Live chain").
#
#   scripts/live-chain.sh --dataset euroc:DIR|sim [--out DIR] [--duration S] [--viewer]
#                         [--width W --height H] [--downscale F] [--queue N]
#                         [--encoding raw|jpeg] [--log-channels REGEX] [--vo-config FILE]
#
# Starts aerie-log record, aerie-map, aerie-vo (and aerie-viewer under xvfb-run -a with
# --viewer) on a private LCM URL (this host only, its own port), then aerie-capture in real
# time: a EuRoC folder looped for --duration seconds (the excerpt is short and static), or the
# simulator's stereo rig flying the survey at --width x --height (default 752x480) with its
# GT_POSE. When capture ends it stops every node with SIGINT, replays the log through aerie-vo
# (aerie-replay --nodes vo: every pair, in order) and prints frames published, frames VO
# processed, queue overflows, upstream gaps, the live and the replayed ATE (aerie-eval-traj,
# SE(3) alignment, against the log's GT_POSE), their ratio and the log size.
# Exit status: 0 done, 1 a step failed, 2 usage error.
set -euo pipefail

usage() { sed -n '2,17p' "$0" | sed 's/^# \{0,1\}//'; }
die_usage() { echo "live-chain: $1 (see --help)" >&2; exit 2; }

repo=$(cd "$(dirname "$0")/.." && pwd)
BIN=${AERIE_BIN:-$repo/build/default/bin}
dataset="" out="" duration=30 viewer=0 width=752 height=480 queue="" encoding=raw downscale=1
log_channels=".*" vo_config="$repo/config/vo.yaml"
while [ $# -gt 0 ]; do
  case "$1" in
    -h|--help) usage; exit 0 ;;
    --dataset) [ $# -ge 2 ] || die_usage "--dataset needs euroc:DIR or sim"; dataset=$2; shift 2 ;;
    --out) [ $# -ge 2 ] || die_usage "--out needs a folder"; out=$2; shift 2 ;;
    --duration) [ $# -ge 2 ] || die_usage "--duration needs seconds"; duration=$2; shift 2 ;;
    --width) [ $# -ge 2 ] || die_usage "--width needs pixels"; width=$2; shift 2 ;;
    --height) [ $# -ge 2 ] || die_usage "--height needs pixels"; height=$2; shift 2 ;;
    --queue) [ $# -ge 2 ] || die_usage "--queue needs a number of pairs"; queue=$2; shift 2 ;;
    --encoding) [ $# -ge 2 ] || die_usage "--encoding needs raw or jpeg"; encoding=$2; shift 2 ;;
    --downscale) [ $# -ge 2 ] || die_usage "--downscale needs a factor"; downscale=$2; shift 2 ;;
    --log-channels) [ $# -ge 2 ] || die_usage "--log-channels needs a regex"; log_channels=$2; shift 2 ;;
    --vo-config) [ $# -ge 2 ] || die_usage "--vo-config needs a file"; vo_config=$2; shift 2 ;;
    --viewer) viewer=1; shift ;;
    *) die_usage "unknown option '$1'" ;;
  esac
done
case "$dataset" in
  euroc:?*) dir=${dataset#euroc:}
            [ -d "$dir" ] || die_usage "no folder $dir"
            src=(-s euroc -p "$dir" --loop true --duration "$duration")
            # A TUM ground truth beside mav0/ when it has no state_groundtruth_estimate0/data.csv.
            if [ ! -f "$dir/mav0/state_groundtruth_estimate0/data.csv" ]; then
              tum=$(find "$dir/groundtruth" -maxdepth 1 -name "*.txt" 2>/dev/null | sort | head -1 || true)
              [ -z "$tum" ] || src+=(--groundtruth "$tum")
            fi ;;
  sim) src=(-s sim --sim-trajectory survey --width "$width" --height "$height" --duration "$duration"
            --sim-start-utime 1000000000000) ;;
  "") die_usage "--dataset is required" ;;
  *) die_usage "--dataset must be euroc:DIR or sim, got '$dataset'" ;;
esac
[[ "$duration" =~ ^[0-9]+([.][0-9]+)?$ ]] || die_usage "--duration must be seconds, got '$duration'"
[[ "$downscale" =~ ^[0-9]+([.][0-9]+)?$ ]] || die_usage "--downscale must be a factor, got '$downscale'"
[[ "$encoding" =~ ^(raw|jpeg)$ ]] || die_usage "--encoding must be raw or jpeg, got '$encoding'"
[ -z "$queue" ] || [[ "$queue" =~ ^[1-9][0-9]*$ ]] || die_usage "--queue must be a positive number, got '$queue'"
out=${out:-$repo/logs/live-chain-$(date +%Y%m%d-%H%M%S)}
for b in aerie-capture aerie-vo aerie-map aerie-log aerie-replay aerie-eval-traj; do
  [ -x "$BIN/$b" ] || { echo "live-chain: $BIN/$b missing (build it)" >&2; exit 1; }
done
[ "$viewer" = 0 ] || [ -x "$BIN/aerie-viewer" ] || { echo "live-chain: $BIN/aerie-viewer missing" >&2; exit 1; }
mkdir -p "$out"

# shellcheck source=scripts/local-lcm.sh
source "$repo/scripts/local-lcm.sh"
aerie_local_lcm live-chain
# A port of our own: other chains on this host must not mix with this one.
port=$((7700 + $$ % 200))
export LCM_DEFAULT_URL="udpm://239.255.76.67:$port?ttl=0&recv_buf_size=4194304"

vo_args=(--config "$vo_config")
if [ -n "$queue" ]; then
  sed "s/^\(  queue: *\)[0-9]*/\1$queue/" "$vo_config" >"$out/vo.yaml"
  vo_args=(--config "$out/vo.yaml")
fi

pids=() viewer_pid=""
stop_all() {
  local p
  if [ -n "$viewer_pid" ]; then
    # The viewer first (it writes its snapshot at exit), then what is left of its session.
    for p in $(pgrep -s "$viewer_pid" -x aerie-viewer || true); do kill -INT "$p" 2>/dev/null || true; done
    for _ in $(seq 50); do kill -0 "$viewer_pid" 2>/dev/null || break; sleep 0.1; done
    kill -INT -- "-$viewer_pid" 2>/dev/null || true
    wait "$viewer_pid" 2>/dev/null || true
    viewer_pid=""
  fi
  for p in "${pids[@]}"; do kill -INT "$p" 2>/dev/null || true; done
  for p in "${pids[@]}"; do wait "$p" 2>/dev/null || true; done
  pids=()
}
trap stop_all EXIT

uptime >"$out/uptime-start.txt"
"$BIN/aerie-log" record --force --channels "$log_channels" "$out/live.lcm" >"$out/log.txt" 2>&1 & pids+=($!)
"$BIN/aerie-map" --save "" >"$out/map.txt" 2>&1 & pids+=($!)
"$BIN/aerie-vo" "${vo_args[@]}" >"$out/vo.txt" 2>&1 & pids+=($!)
if [ "$viewer" = 1 ]; then
  # Its own session, so that SIGINT reaches xvfb-run, Xvfb and the viewer together.
  setsid xvfb-run -a -s "-screen 0 1280x1024x24" "$BIN/aerie-viewer" --image-channel CAM_STEREO \
    --snapshot "$out/viewer.png" >"$out/viewer.txt" 2>&1 & viewer_pid=$!
fi
sleep 2  # the subscribers are up before the first frame
echo "live-chain: $dataset ${duration}s in real time on $LCM_DEFAULT_URL -> $out"
"$BIN/aerie-capture" "${src[@]}" --encoding "$encoding" --downscale "$downscale" --rate 1 >"$out/capture.txt" 2>&1 ||
  { echo "live-chain: aerie-capture failed:" >&2; tail -3 "$out/capture.txt" >&2; exit 1; }
sleep 2  # the last pairs through VO and into the log
uptime >"$out/uptime-end.txt"
stop_all
trap - EXIT

# The replay: the same log through aerie-vo, every pair in order.
"$BIN/aerie-replay" "$out/live.lcm" --out "$out/replay.lcm" --nodes vo >"$out/replay.txt" 2>&1 ||
  { echo "live-chain: aerie-replay failed:" >&2; tail -3 "$out/replay.txt" >&2; exit 1; }

# TUM trajectories and the ATE of each against the log's GT_POSE.
export_tum() {  # LOG CHANNEL DIR -> the TUM file written
  "$BIN/aerie-log" export "$1" --channel "$2" --out "$3" --force >/dev/null 2>&1 || return 1
  [ -s "$3/$2.tum" ] && echo "$3/$2.tum"
}
ate() {  # EST_TUM -> ATE RMSE (m)
  "$BIN/aerie-eval-traj" --ref "$gt" --est "$1" --align se3 --json "$1.json" >"$1.eval.txt" 2>&1 || { echo nan; return; }
  python3 -c 'import json,sys; a=json.load(open(sys.argv[1]))["ate_m"]; print(a["rmse"] if isinstance(a, dict) else a)' "$1.json" 2>/dev/null || echo nan
}
gt=$(export_tum "$out/live.lcm" GT_POSE "$out/gt") || { echo "live-chain: no GT_POSE in the log" >&2; exit 1; }
live_tum=$(export_tum "$out/live.lcm" VO_POSE "$out/live-pose") || { echo "live-chain: no VO_POSE in the log" >&2; exit 1; }
replay_tum=$(export_tum "$out/replay.lcm" VO_POSE "$out/replay-pose") || { echo "live-chain: no VO_POSE in the replay" >&2; exit 1; }
live_ate=$(ate "$live_tum")
replay_ate=$(ate "$replay_tum")

published=$(grep -o 'published [0-9]* frames' "$out/capture.txt" | grep -o '[0-9]*' | tail -1)
vo_line=$(grep 'stopped after' "$out/vo.txt" | tail -1)
processed=$(sed -n 's/.*stopped after \([0-9]*\) stereo pairs.*/\1/p' <<<"$vo_line")
overflows=$(sed -n 's/.*: \([0-9]*\) dropped here.*/\1/p' <<<"$vo_line")
gaps=$(sed -n 's/.*full), \([0-9]*\) missing upstream.*/\1/p' <<<"$vo_line")
replayed=$(grep -c . "$replay_tum" || true)
log_mb=$(python3 -c 'import os,sys; print(f"{os.path.getsize(sys.argv[1])/1e6:.1f}")' "$out/live.lcm")
ratio=$(python3 -c 'import sys; a,b=map(float,sys.argv[1:]); print(f"{a/b:.2f}" if b > 0 else "nan")' "$live_ate" "$replay_ate")
{
  echo "dataset:            $dataset (${duration} s, ${encoding}, downscale ${downscale}, viewer $([ "$viewer" = 1 ] && echo on || echo off), VO queue ${queue:-from $(basename "$vo_config")})"
  echo "load:               start $(sed 's/.*load average: //' "$out/uptime-start.txt"); end $(sed 's/.*load average: //' "$out/uptime-end.txt")"
  echo "frames published:   ${published:-?}"
  echo "frames VO processed: ${processed:-?}  (replay: ${replayed})"
  echo "queue overflows:    ${overflows:-?}  (pairs VO dropped, its input queue full)"
  echo "upstream gaps:      ${gaps:-?}  (pairs that never reached VO)"
  echo "live ATE:           $live_ate m"
  echo "replay ATE:         $replay_ate m"
  echo "ratio live/replay:  $ratio"
  echo "log:                $log_mb MB ($out/live.lcm)"
} | tee "$out/summary.txt"

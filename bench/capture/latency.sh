#!/usr/bin/env bash
# LCM loopback latency of 752x480 stereo at 20 Hz: aerie-capture publishes the EuRoC
# excerpt (752x480, rectified; looped) stamped with the wall clock (--stamp wall), and
# aerie-bench-capture-latency receives it in another process over UDP multicast inside a
# network namespace. Latency = LCM receive time - utime.
#   bash bench/capture/latency.sh [SECONDS=60] [OUT_DIR]
source "$(dirname "$0")/common.sh"
SECS=${1:-60}
OUT=${2:-$ROOT/build/default/bench/capture}
mkdir -p "$OUT"
make_namespace aerie-bench-lat
echo "# $(machine_note)" | tee "$OUT/latency-machine.txt"
ip netns exec "$NS" "$BIN/aerie-bench-capture-latency" --lcm-url "$RECV_URL" --duration "$SECS" --out "$OUT/latency.csv" \
  > "$OUT/latency.json" 2> "$OUT/latency-probe.txt" &
probe=$!
sleep 1
in_ns "$BIN/aerie-capture" --lcm-url "$URL" --source euroc --path "$EUROC" --loop true --rate 1 --stamp wall \
  --duration "$((SECS + 2))" > "$OUT/latency-capture.txt" 2>&1
wait $probe
cat "$OUT/latency.json"
grep -o 'published.*' "$OUT/latency-capture.txt"
$PY "$(dirname "$0")/plot_latency.py" "$OUT/latency.csv" "$OUT/latency.png"

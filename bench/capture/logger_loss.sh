#!/usr/bin/env bash
# Messages lost by the stock lcm-logger over a 20 Hz 752x480 stereo recording
# (CAM_LEFT + CAM_RIGHT + CAM_STEREO raw + GT_POSE, ~29 MB/s), UDP multicast in a
# network namespace. The logger's socket buffer comes from the LCM URL
# (recv_buf_size=4194304, capped by net.core.rmem_max). Dropped = sequence gaps
# counted by aerie-log info. Target: 0.
#   bash bench/capture/logger_loss.sh [SECONDS=120] [OUT_DIR] [LOGGER_URL]
source "$(dirname "$0")/common.sh"
SECS=${1:-120}
OUT=${2:-$ROOT/build/default/bench/capture}
LOGGER_URL=${3:-$RECV_URL}
mkdir -p "$OUT"
make_namespace aerie-bench-log
LOG=$OUT/logger-loss.lcm
echo "# $(machine_note); rmem_max $(cat /proc/sys/net/core/rmem_max); logger URL $LOGGER_URL" | tee "$OUT/logger-loss-machine.txt"
ip netns exec "$NS" lcm-logger -f --quiet --lcm-url="$LOGGER_URL" "$LOG" &
logger=$!
sleep 1
in_ns "$BIN/aerie-capture" --lcm-url "$URL" --source euroc --path "$EUROC" \
  --groundtruth "$EUROC/groundtruth/V101_gt.txt" --loop true --rate 1 --duration "$SECS" \
  > "$OUT/logger-loss-capture.txt" 2>&1
sleep 1
kill -INT $logger
wait $logger
"$BIN/aerie-log" info --json "$LOG" > "$OUT/logger-loss.json" || true
published=$(grep -o 'published [0-9]* frames' "$OUT/logger-loss-capture.txt" | awk '{print $2}')
$PY - "$OUT/logger-loss.json" "$published" <<'PYEOF'
import json, sys
s = json.load(open(sys.argv[1])); published = int(sys.argv[2])
lost = {c["channel"]: published - c["count"] for c in s["channels"] if c["channel"].startswith(("CAM_", "GT_"))}
print(f"frames published: {published}; recorded per channel: " +
      ", ".join(f'{c["channel"]} {c["count"]}' for c in s["channels"]))
print(f"duration {s['duration_s']:.1f} s, {s['file_size'] / 1e6:.0f} MB; max gap per channel: " +
      ", ".join(f'{c["channel"]} {c["max_gap_s"]:.3f} s' for c in s["channels"]))
print(f"messages lost (published - recorded): {lost}; sequence gaps: {s['dropped']}")
PYEOF
rm -f "$LOG"   # ~3.5 GB for 2 minutes; the summary stays in $OUT

#!/usr/bin/env bash
# aerie-capture throughput, frames/s as fast as possible (--rate 0), per source:
#   bash bench/capture/throughput.sh [OUT_DIR]
# memq:// (no network: the cost of reading, rectifying, converting and encoding), and
# EuRoC over UDP multicast in a namespace (adds the LCM send). Writes OUT_DIR/throughput.csv
# and .json (default OUT_DIR: build/default/bench/capture).
source "$(dirname "$0")/common.sh"
OUT=${1:-$ROOT/build/default/bench/capture}
mkdir -p "$OUT"
csv=$OUT/throughput.csv
echo "case,size,frames,seconds,frames_per_s" > "$csv"

run() {  # run NAME SIZE URL_OR_NS ARGS...
  local name=$1 size=$2 where=$3; shift 3
  local log=$OUT/throughput-$name.txt
  if [ "$where" = ns ]; then
    in_ns "$BIN/aerie-capture" --lcm-url "$URL" --rate 0 "$@" > "$log" 2>&1
  else
    "$BIN/aerie-capture" --lcm-url memq:// --rate 0 "$@" > "$log" 2>&1
  fi
  # "published N frames in T s (F frames/s)"
  local line; line=$(grep -o 'published [0-9]* frames in [0-9.]* s ([0-9.]* frames/s)' "$log")
  local n t f
  n=$(echo "$line" | awk '{print $2}'); t=$(echo "$line" | awk '{print $5}'); f=$(echo "$line" | tr -d '(' | awk '{print $7}')
  echo "$name,$size,$n,$t,$f" | tee -a "$csv"
}

echo "# $(machine_note)" | tee "$OUT/throughput-machine.txt"
run sim_376x240 376x240 memq --source sim --sim-start-utime 0 --stop 200
run sim_752x480 752x480 memq --source sim --sim-start-utime 0 --width 752 --height 480 --stop 100
run euroc_752x480_rectified 752x480 memq --source euroc --path "$EUROC"
run euroc_752x480_jpeg 752x480 memq --source euroc --path "$EUROC" --encoding jpeg
run kitti_1226x370 1226x370 memq --source kitti --path "$KITTI"
make_namespace aerie-bench-tp
run euroc_752x480_udpm 752x480 ns --source euroc --path "$EUROC"

$PY - "$csv" "$OUT/throughput.json" <<'PYEOF'
import csv, json, sys
rows = list(csv.DictReader(open(sys.argv[1])))
json.dump(rows, open(sys.argv[2], "w"), indent=1)
PYEOF
echo "wrote $csv"

#!/usr/bin/env bash
# The viewer's display rate and CPU in the cases of docs/results/viewer.md, one JSON each,
# then a plot:  bash bench/viewer/run_cases.sh [OUT_DIR] [SECONDS]
set -euo pipefail
cd "$(dirname "$0")/../.."
out=${1:-build/bench-viewer}
seconds=${2:-15}
bench=build/default/bin/bench_viewer
mkdir -p "$out"
run() {  # name, options...
  local name=$1
  shift
  xvfb-run -a "$bench" --seconds "$seconds" --out "$out/$name.json" "$@" > /dev/null 2>&1
  echo "$name: $(cat "$out/$name.json")"
}
uptime
run no-map --voxels 0
run floor --map floor
run rough --map rough
run rough-poses --map rough --poses
run rough-poses-full-res --map rough --poses --map-max-quads 0
run full-redraw-no-map --voxels 0 --always-redraw
run full-redraw-rough-full-res --map rough --always-redraw --map-max-quads 0
run full-redraw-rough-full-res-msaa8 --map rough --always-redraw --map-max-quads 0 --multisamples 8
uptime
/usr/bin/python3 bench/viewer/plot_viewer.py "$out" "$out/viewer_rates.png"

#!/usr/bin/env bash
# Smoke test of scripts/lcm-spy.sh and scripts/lcm-logplayer-gui.sh (the JDK 17
# replacements of Debian's lcm-spy / lcm-logplayer-gui, which fail on -Xincgc).
#   lcm_java_tools_smoke.sh SOURCE_DIR TYPES_JAR WORK_DIR
# Each tool runs under `xvfb-run -a` for a few seconds on udpm://239.255.76.67:7699?ttl=0
# (loopback only), must still be running, must have found Aerie's types (lcm-spy), and
# its output must hold no "Exception" and no "Unrecognized option"; then it is killed.
# Exit 77 (skipped) without java or xvfb-run, or when the build made no jar (no javac).
set -uo pipefail
src="$1" jar="$2" work="$3"
url='udpm://239.255.76.67:7699?ttl=0'
seconds="${AERIE_SMOKE_SECONDS:-5}"

command -v java >/dev/null 2>&1 || { echo "SKIP: java is not installed (apt-get install default-jre)"; exit 77; }
command -v xvfb-run >/dev/null 2>&1 || { echo "SKIP: xvfb-run is not installed (apt-get install xvfb xauth)"; exit 77; }
[[ -f "$jar" ]] || { echo "SKIP: $jar was not built (needs javac: apt-get install default-jdk-headless)"; exit 77; }
mkdir -p "$work"

# A 2-second log for the log player: 50 events, LCM event-log format (big-endian).
# (with a log of two 8-byte events, lcm-logplayer-gui 1.3.1 printed an EOFException.)
log="$work/smoke.lcm"
python3 - "$log" <<'PY'
import struct, sys
with open(sys.argv[1], "wb") as f:
    for i in range(50):
        ch, data = b"SMOKE_TEST", bytes(100)
        f.write(struct.pack(">IqqII", 0xEDA1DA01, i, 40_000 * i, len(ch), len(data)) + ch + data)
PY

pid=""
cleanup() { [[ -n "$pid" ]] && kill -- "-$pid" 2>/dev/null; }
trap cleanup EXIT

failures=0
run() {  # NAME SCRIPT ARGS...
  local name="$1" script="$2"
  shift 2
  local out="$work/$name.out" err="$work/$name.err"
  # Its own process group (setsid), so that xvfb-run, Xvfb and java go together.
  AERIE_LCMTYPES_JAR="$jar" setsid xvfb-run -a "$script" "$@" >"$out" 2>"$err" &
  pid=$!
  sleep "$seconds"
  local alive=1
  kill -0 "$pid" 2>/dev/null || alive=0
  kill -- "-$pid" 2>/dev/null
  wait "$pid" 2>/dev/null
  pid=""
  local ok=1
  if ((alive == 0)); then echo "FAIL $name: exited within $seconds s"; ok=0; fi
  if grep -q -e "Exception" -e "Unrecognized option" "$out" "$err"; then echo "FAIL $name: exception in its output"; ok=0; fi
  if [[ "$name" == spy ]] && ! grep -q "Found [1-9][0-9]* LCM types" "$out"; then
    echo "FAIL $name: it found none of Aerie's LCM types"; ok=0
  fi
  if ((ok)); then echo "ok   $name"; else
    echo "--- $name stdout:"; cat "$out"; echo "--- $name stderr:"; cat "$err"; failures=$((failures + 1))
  fi
}

run spy "$src/scripts/lcm-spy.sh" --lcm-url "$url"
run logplayer "$src/scripts/lcm-logplayer-gui.sh" --lcm-url "$url" --paused "$log"
exit $((failures > 0))

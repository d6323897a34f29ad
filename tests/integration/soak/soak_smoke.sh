#!/usr/bin/env bash
# Smoke test of scripts/soak.sh: one flight (--flights 1), in a private network namespace
# (--netns), with the nodes of the build under test (--bin), and a fault in it: aerie-track
# killed with kill -9 in mid-flight (--kill track), which procman must respawn.
#   soak_smoke.sh SOURCE_DIR BIN_DIR WORK_DIR
# Passes when the soak ran to its summary: a finished flight's result line in flights.csv,
# samples.csv with rows for every process of the chain, counters.csv with the STATUS_*
# counters of every Aerie node, the logger's losses counted (log-info.json), soak.md with its
# tables, and the plots when matplotlib is there. The landing itself is not required (a
# loaded machine may miss frames; tests/integration/landing checks landings in lock-step),
# but is printed; the kill and the respawn are. Exit 77 (skipped) without root, ip or Xvfb.
set -uo pipefail
src="$1" bin="$2" work="$3"
[ "$(id -u)" -eq 0 ] || { echo "SKIP: the soak's --netns needs root (ip netns add)"; exit 77; }
for t in ip Xvfb lcm-gen; do
  command -v "$t" >/dev/null 2>&1 || { echo "SKIP: '$t' is not installed (scripts/setup.sh)"; exit 77; }
done
rm -rf "$work"
mkdir -p "$(dirname "$work")"

status=0
bash "$src/scripts/soak.sh" --flights 1 --netns --warmup-minutes 0.1 --kill track --kill-window 6:8 --bin "$bin" --out "$work" >"$work.out" 2>&1 || status=$?
cat "$work.out"
fail=0
check() {  # DESCRIPTION COMMAND...
  local what="$1"
  shift
  if "$@"; then echo "ok   $what"; else echo "FAIL $what"; fail=1; fi
}
for f in soak.md summary.json samples.csv counters.csv host.csv flights.csv log-info.json run.json; do
  check "$f written" test -s "$work/$f"
done
check "flights.csv has one finished flight" \
  awk -F, 'NR == 2 && $9 ~ /^"(LANDED|NOT LANDED)/ {ok = 1} END {exit !(ok && NR == 2)}' "$work/flights.csv"
check "aerie-track was killed 6-8 s into the flight and respawned by the deputy" /usr/bin/python3 -c '
import csv, sys
f = next(csv.DictReader(open(sys.argv[1])))
ok = f["kill"] == "track" and 6 <= float(f["kill_at_s"]) <= 8 and f["killed_pid"] and 0 < float(f["respawn_s"] or 0) < 5
print("   kill:", f["kill"], "at", f["kill_at_s"], "s, pid", f["killed_pid"], "respawned after", f["respawn_s"], "s")
sys.exit(not ok)' "$work/flights.csv"
check "soak.md has the faults table" grep -q '^| aerie-track | 1 | ' "$work/soak.md"
for node in flightsim pilot track vo map logger viewer deputy; do
  check "samples.csv has $node" awk -F, -v n="$node" '$3 == n && $5 > 0 {found = 1} END {exit !found}' "$work/samples.csv"
done
for node in flightsim pilot track vo map deputy; do
  check "counters.csv has $node's status" awk -F, -v n="$node" '$2 == n {found = 1} END {exit !found}' "$work/counters.csv"
done
check "the logger's losses are counted" grep -q '"logger_lost": [0-9]' "$work/log-info.json"
check "soak.md has the process table" grep -q '^| vo | aerie-vo |' "$work/soak.md"
check "soak.md has the verdict" grep -q '^\* Logger: \*\*[0-9]* messages lost' "$work/soak.md"
if /usr/bin/python3 -c 'import matplotlib' 2>/dev/null; then
  check "rss.png and cpu.png" test -s "$work/rss.png" -a -s "$work/cpu.png"
fi
check "the log was deleted once summarised" test ! -e "$work/soak.lcm"
ns=$(sed -n 's/.*"netns": "\([^"]*\)".*/\1/p' "$work/run.json" 2>/dev/null)
check "ran in a namespace ($ns), removed at the end" sh -c "[ -n '$ns' ] && ! ip netns list | grep -q '^$ns\b'"
echo "soak.sh exit status $status (0: every flight landed within the bounds and the logger lost nothing)"
exit "$fail"

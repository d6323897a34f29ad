#!/usr/bin/env bash
# Smoke test of scripts/fuzz.sh without clang: the fuzz binaries of a scratch --build-dir are
# fake_libfuzzer.sh, which prints excerpts of real libFuzzer logs (logs/). Checks what the
# script makes of them (the figures row of results.md, the exit status, the crash report)
# and what it passes to libFuzzer, and that bad arguments are refused with a message.
#   fuzz_script_smoke.sh SOURCE_DIR WORK_DIR
set -uo pipefail
src="$1" work="$2"
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work"
mkdir -p "$work/fuzz"
for t in config node_track; do cp "$here/fake_libfuzzer.sh" "$work/fuzz/fuzz_$t"; done
export FAKE_ARGS="$work/args"

fail=0
check() {  # DESCRIPTION COMMAND...
  local what="$1"
  shift
  if "$@"; then echo "ok   $what"; else echo "FAIL $what"; fail=1; fi
}
fuzz() {  # EXPECTED-STATUS LOG RC ARTIFACT FUZZ.SH-ARGS...: runs fuzz.sh, checks its exit
  local expected=$1 log=$2 code=$3 artifact=$4        # status; its output is left in $out
  shift 4
  out=$(FAKE_LOG="$here/logs/$log" FAKE_RC=$code FAKE_ARTIFACT=$artifact \
        bash "$src/scripts/fuzz.sh" --no-build --build-dir "$work" "$@" 2>&1)
  local rc=$?
  echo "$out" | sed 's/^/    /'
  check "exit $expected" test "$rc" -eq "$expected"
}
row() { grep "^| $1 |" "$work/results.md"; }
passed() { local a; for a in "$@"; do grep -qx -- "$a" "$FAKE_ARGS" || return 1; done; }
says() { [[ "$out" == *"$1"* ]]; }

echo "-- a run to its end (-runs reached)"
fuzz 0 done.log 0 "" --runs 1000 --seconds 5 --target config
check "row: the final stat:: count and rate, cov/ft/corpus of the last status line" \
  test "$(row config)" = "| config | 1000000 | 3278 | 1741 | 2783 | 213 | 0 | ok |"
check "passes -runs, -max_total_time, leak checks for a non-node target" \
  passed -runs=1000 -max_total_time=5 -detect_leaks=1 -max_len=65536
check "reads the corpus it grows, then the seeds" passed "$work/corpus/config" "$src/fuzz/corpus/config"

echo "-- fork mode, interrupted: the parent's count, not the job's stat:: lines after it"
fuzz 0 fork_interrupted.log 72 "" --fork 2 --seconds 5 --target node_track
check "row: 1,077,884 executions, cov 20431, ft 17947, corpus 1141, interrupted" \
  test "$(row node_track)" = "| node_track | 1077884 | 202 | 20431 | 17947 | 1141 | 0 | interrupted (SIGINT), no crash |"
check "passes -fork=2 and -ignore_crashes=0, no leak checks for a node target" \
  passed -fork=2 -ignore_crashes=0 -detect_leaks=0

echo "-- a crash"
fuzz 1 crash.log 1 crash-5f3a9c --seconds 5 --target config
check "row: the sanitizer's first line and the input" \
  eval '[[ "$(row config)" == "| config | 1530 | "*" | 2402 | 7104 | 374 | 1 | CRASH: ERROR: AddressSanitizer: heap-buffer-overflow"*"(crash-5f3a9c) |" ]]'
check "names the target on stderr" says "crashes in: config"

echo "-- bad arguments"
fuzz 2 done.log 0 "" --fork two --target config
check "--fork two refused" says "--fork must be a number"
fuzz 2 done.log 0 "" --target no_such_target
check "an unknown target refused" says "no target 'no_such_target'"
fuzz 2 done.log 0 "" --target node_vo
check "a target not built refused" says "fuzz_node_vo is not built"
fuzz 2 done.log 0 "" --seconds 0 --target config
check "--seconds 0 refused" says "--seconds must be a positive integer"

exit $fail

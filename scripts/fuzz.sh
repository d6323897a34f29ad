#!/usr/bin/env bash
# Builds the libFuzzer targets of fuzz/ with clang, ASan and UBSan (AERIE_BUILD_FUZZ=ON) into
# build/fuzz and runs each for a while on its seed corpus and regression inputs; writes the
# figures to build/fuzz/results.md (docs/fuzz.md). Exit status 1 when a target found a crash.
set -euo pipefail

usage() {
  cat <<'EOF'
usage: scripts/fuzz.sh [--seconds N] [--runs R] [--fork F] [--target NAME]... [--jobs J] [--no-build]
                       [--build-dir DIR]

  --seconds N    fuzzing time per target (default 600; with --runs, a ceiling)
  --runs R       stop each target after R executions (libFuzzer's -runs) or N seconds
  --fork F       F fuzzing processes per target (libFuzzer's -fork; it ignores --runs, so
                 stop on --seconds; the executions are the sum over the processes)
  --target NAME  run only this target (repeatable; default: every fuzz/targets/*.cpp)
  --jobs J       parallel compile jobs (default: nproc; use 1 on a shared machine)
  --no-build     run the targets already built in build/fuzz
  --build-dir D  the fuzz build folder instead of build/fuzz (below, build/fuzz stands for it)
  --help         this text

Per target: new inputs go to build/fuzz/corpus/NAME/ (fuzz/corpus/NAME/ and
fuzz/regressions/NAME/ are read, never written), crashing inputs to
build/fuzz/artifacts/NAME/, libFuzzer's output to build/fuzz/logs/NAME.log.
Figures (executions, exec/s, cov and ft of libFuzzer's last stats line, crashes):
build/fuzz/results.md. Reproduce a crash: build/fuzz/fuzz/fuzz_NAME ARTIFACT.
Needs clang with libFuzzer (Debian 12: apt-get install clang libclang-rt-14-dev).
EOF
}

root=$(cd "$(dirname "$0")/.." && pwd)
build=$root/build/fuzz
seconds=600
runs=-1
fork=0
jobs=$(nproc)
do_build=1
targets=()
while [ $# -gt 0 ]; do
  case $1 in
    --seconds) seconds=${2:?--seconds needs a value}; shift 2 ;;
    --target) targets+=("${2:?--target needs a name}"); shift 2 ;;
    --runs) runs=${2:?--runs needs a value}; shift 2 ;;
    --fork) fork=${2:?--fork needs a value}; shift 2 ;;
    --jobs) jobs=${2:?--jobs needs a value}; shift 2 ;;
    --no-build) do_build=0; shift ;;
    --build-dir) build=${2:?--build-dir needs a folder}; shift 2 ;;
    -h|--help) usage; exit 0 ;;
    *) echo "fuzz.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
[[ $seconds =~ ^[0-9]+$ && $seconds -gt 0 ]] || { echo "fuzz.sh: --seconds must be a positive integer" >&2; exit 2; }
[[ $runs = -1 || ( $runs =~ ^[0-9]+$ && $runs -gt 0 ) ]] || { echo "fuzz.sh: --runs must be a positive integer" >&2; exit 2; }
[[ $fork =~ ^[0-9]+$ ]] || { echo "fuzz.sh: --fork must be a number of processes (0: no fork)" >&2; exit 2; }
fork_args=()
[ "$fork" -gt 0 ] && fork_args=(-fork="$fork" -ignore_crashes=0)
if [ ${#targets[@]} -eq 0 ]; then
  for f in "$root"/fuzz/targets/*.cpp; do targets+=("$(basename "$f" .cpp)"); done
fi
for t in "${targets[@]}"; do
  [ -f "$root/fuzz/targets/$t.cpp" ] || { echo "fuzz.sh: no target '$t' (fuzz/targets/$t.cpp)" >&2; exit 2; }
done

if [ $do_build = 1 ]; then
  command -v clang++ >/dev/null || { echo "fuzz.sh: clang++ not found (apt-get install clang)" >&2; exit 2; }
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DAERIE_BUILD_FUZZ=ON \
    -DAERIE_BUILD_TESTS=OFF -DAERIE_BUILD_BENCH=OFF -DAERIE_BUILD_VIEWER=OFF >/dev/null
  cmake --build "$build" -j "$jobs" --target "${targets[@]/#/fuzz_}"
fi

# Inputs longer than this are truncated when read: room for the largest seeds (a VO_DEPTH
# sequence, a flight log excerpt, the reliability issue's 250 KB payloads) where they matter.
max_len() {
  case $1 in
    node_map|event_log|lcm_messages|node_control) echo 262144 ;;
    *) echo 65536 ;;
  esac
}
# LCM 1.3 leaves a 40-byte mutex of glib behind for every lcm_t that handled a message, so each
# input of a node target frees fewer blocks than it allocates, and libFuzzer would run a full
# leak check after every one (3x slower). Node targets run without it; the others keep it.
detect_leaks() {
  case $1 in
    node_*) echo 0 ;;
    *) echo 1 ;;
  esac
}

# libFuzzer's status lines: "#123<TAB>DONE   cov: 456 ft: 789 corp: 12/3Kb ..."; in fork mode the
# parent's are "#123: cov: ... exec/s 45 ... time: 67s" (sums over its jobs), and a job's own lines
# and final stat:: lines can follow them in the log (a job interrupted with the parent prints
# its own), so only the parent's count there.
status_re='^#[0-9]+:?[[:space:]]'
[ "$fork" -gt 0 ] && status_re='^#[0-9]+:[[:space:]]'
# Field $1 of the last status line with "cov:"; empty when the target stopped before one.
stat_after() { { grep -E "$status_re.*cov: " "$2" || true; } | tail -1 | sed -nE "s|.* $1:? ([0-9]+).*|\1|p"; }
final_stat() { [ "$fork" -gt 0 ] || sed -nE "s/^stat::$1: *([0-9]+).*/\1/p" "$2" | tail -1; }

# Inputs libFuzzer saved as crash, leak, timeout or out-of-memory (not its slow-unit-* notes).
crashes_in() { find "$1" -type f \( -name 'crash-*' -o -name 'leak-*' -o -name 'timeout-*' -o -name 'oom-*' \) | wc -l; }

export ASAN_OPTIONS=${ASAN_OPTIONS:-abort_on_error=1:detect_leaks=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
mkdir -p "$build/logs"
rows=()
failed=()
for t in "${targets[@]}"; do
  bin=$build/fuzz/fuzz_$t
  [ -x "$bin" ] || { echo "fuzz.sh: $bin is not built" >&2; exit 2; }
  work=$build/corpus/$t
  artifacts=$build/artifacts/$t
  log=$build/logs/$t.log
  mkdir -p "$work" "$artifacts"
  corpora=("$work" "$root/fuzz/corpus/$t")
  [ -d "$root/fuzz/regressions/$t" ] && corpora+=("$root/fuzz/regressions/$t")
  before=$(crashes_in "$artifacts")
  echo "== $t: ${seconds} s$([ "$runs" = -1 ] || echo " or $runs executions")"
  set +e
  "$bin" -max_total_time="$seconds" -runs="$runs" -max_len="$(max_len "$t")" -detect_leaks="$(detect_leaks "$t")" \
    "${fork_args[@]}" -timeout=25 -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$artifacts/" "${corpora[@]}" >"$log" 2>&1
  rc=$?
  set -e
  found=$(( $(crashes_in "$artifacts") - before ))
  execs=$(final_stat number_of_executed_units "$log")
  if [ -z "$execs" ]; then  # fork mode, or stopped by a crash: the last status line has the count
    execs=$({ grep -E "$status_re" "$log" || true; } | tail -1 | sed -nE 's/^#([0-9]+):?[[:space:]].*/\1/p')
  fi
  rate=$(final_stat average_exec_per_sec "$log")
  if [ -z "$rate" ] && [ "$fork" -gt 0 ] && [ -n "$execs" ]; then  # the parent's: executions / its time
    secs=$(stat_after time "$log")
    [ -n "$secs" ] && [ "$secs" -gt 0 ] && rate=$(( execs / secs ))
  fi
  [ -n "$rate" ] || rate=$(stat_after exec/s "$log")
  status=ok
  if [ "$found" -eq 0 ] && grep -q 'libFuzzer: run interrupted' "$log"; then
    status="interrupted (SIGINT), no crash"  # Ctrl-C or kill -INT: libFuzzer exits non-zero
  elif [ $rc -ne 0 ] || [ "$found" -gt 0 ]; then
    why=$({ grep -m1 -E 'ERROR: (AddressSanitizer|LeakSanitizer|libFuzzer)|runtime error:|what\(\):' "$log" || true; } \
      | sed -E 's/^==[0-9]+==//; s/^ +//' | cut -c1-100)
    status="CRASH: ${why:-see the log} ($(ls -t "$artifacts" | grep -v '^slow-unit-' | head -1))"
    failed+=("$t")
  fi
  rows+=("| $t | ${execs:-?} | ${rate:-?} | $(stat_after cov "$log") | $(stat_after ft "$log") | $(stat_after corp "$log") | $found | $status |")
  echo "   ${execs:-?} executions, ${rate:-?} exec/s, cov $(stat_after cov "$log"), ft $(stat_after ft "$log"): $status"
done

{
  echo "# Fuzzing results"
  echo
  echo "$(date -u '+%Y-%m-%d %H:%M UTC'), ${seconds} s per target, $(nproc) cores (load average" \
       "$(cut -d' ' -f1-3 /proc/loadavg)), clang $(clang++ --version | sed -nE '1s/.*version ([0-9.]+).*/\1/p')," \
       "-fsanitize=fuzzer,address,undefined."
  echo
  echo "| target | executions | exec/s | cov | ft | corpus | crashes | status |"
  echo "|---|---:|---:|---:|---:|---:|---:|---|"
  printf '%s\n' "${rows[@]}"
} >"$build/results.md"
echo "figures: $build/results.md"
if [ ${#failed[@]} -gt 0 ]; then
  echo "crashes in: ${failed[*]} (inputs in $build/artifacts/<target>/, logs in $build/logs/)" >&2
  exit 1
fi

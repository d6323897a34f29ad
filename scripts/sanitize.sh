#!/usr/bin/env bash
# Builds and runs the test suite under the sanitizers (README "Sanitizers"): the asan preset
# (AddressSanitizer + LeakSanitizer + UBSan, whole suite) or the tsan preset (ThreadSanitizer,
# the multithreaded parts). Exit status 0 only when every test passed and no process -- the
# tests and every node, deputy or tool they start -- wrote a sanitizer report.
set -euo pipefail

usage() {
  cat <<'EOF'
usage: scripts/sanitize.sh [asan|tsan] [--jobs J] [--no-build] [-- CTEST_ARGS...]

  asan          (default) AddressSanitizer + LeakSanitizer + UBSan, -O1 -g, asserts on;
                the whole suite; build/asan
  tsan          ThreadSanitizer, -O1 -g; the tests of the multithreaded parts (the bus, the VO
                bundle-adjuster thread, the viewer's map mesher thread, the ceopt pool, the
                link, the tracker's worker); build/tsan. Runs ctest on one CPU (taskset):
                see the script for why
  --jobs J      parallel compile and test jobs (default 2)
  --no-build    run the tests already built
  --help        this text

Anything after -- goes to ctest (e.g. -- -R '^Bus\.' or -- -L link).

Options come from the test presets of CMakePresets.json: a UBSan report halts its process,
leaks are reported (suppressions with a reason each: tools/sanitizers/*.supp). The script
fails on a failed test and on any sanitizer report in the output of the tests, passed ones
included (build/<preset>/Testing/Temporary/LastTest.log), which is where the reports of
the nodes a test starts with its own stderr land; under tsan every process also writes its
report to build/tsan/sanitizer.<exe>.<pid>, which the script prints. Reproduce a failing
test by hand with the same options: ctest --preset <preset> -R '<test name>'.
EOF
}

root=$(cd "$(dirname "$0")/.." && pwd)
preset=asan
jobs=2
do_build=1
ctest_args=()
while [ $# -gt 0 ]; do
  case $1 in
    asan|tsan) preset=$1; shift ;;
    --jobs) jobs=${2:?--jobs needs a value}; shift 2 ;;
    --no-build) do_build=0; shift ;;
    -h|--help) usage; exit 0 ;;
    --) shift; ctest_args=("$@"); break ;;
    *) echo "sanitize.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
[[ $jobs =~ ^[0-9]+$ && $jobs -gt 0 ]] || { echo "sanitize.sh: --jobs must be a positive integer" >&2; exit 2; }

cd "$root"
build=build/$preset
start=$(date +%s)
if [ $do_build = 1 ]; then
  [ -f "$build/CMakeCache.txt" ] || cmake --preset "$preset"
  nice -n 10 cmake --build --preset "$preset" -j "$jobs"
fi
[ -f "$build/CMakeCache.txt" ] || { echo "sanitize.sh: $build is not configured (run without --no-build)" >&2; exit 2; }
built=$(date +%s)

rm -f "$build"/sanitizer.*
status=0
# tsan: one CPU. OpenCV's cv::parallel_for_ runs on TBB worker threads, and Debian's libtbb is
# not built with TSan: TSan cannot see the hand-off and the join, and reports every stripe and
# every later reuse of the caller's stack as a race. With one CPU in the affinity mask TBB
# starts no workers and OpenCV runs its loops in the calling thread; Aerie's own threads
# (std::thread) are unaffected, and TSan finds races by happens-before, not by timing.
pin=()
[ "$preset" = tsan ] && pin=(taskset -c "$(taskset -pc $$ | sed 's/.*: *//; s/[-,].*//')")
"${pin[@]}" nice -n 10 ctest --preset "$preset" -j "$jobs" "${ctest_args[@]}" 2>&1 | tee "$build/sanitize-ctest.log" || true
grep -q "100% tests passed" "$build/sanitize-ctest.log" || status=1
done_at=$(date +%s)

# Reports in the output of tests that passed all the same (e.g. from a node whose exit status
# the test does not check). Anchored at the start of a line as the runtimes print them
# ("==PID==ERROR: AddressSanitizer", "file:line:col: runtime error:"): fuzz_script_smoke prints
# fuzz.sh's summary of a fake crash ("...: CRASH: ERROR: AddressSanitizer: ..."), which is no report.
marks='^[^ ]+:[0-9]+:[0-9]+: runtime error:|^==[0-9]+==(ERROR: (AddressSanitizer|LeakSanitizer)|WARNING: ThreadSanitizer)'
in_log=$(grep -cE "$marks" "$build/Testing/Temporary/LastTest.log" 2>/dev/null || true)
if [ "${in_log:-0}" -gt 0 ]; then
  status=1
  echo
  echo "sanitize.sh: $in_log sanitizer report line(s) in $build/Testing/Temporary/LastTest.log:"
  grep -nE "$marks" "$build/Testing/Temporary/LastTest.log" | head -n 40
fi
shopt -s nullglob
reports=("$build"/sanitizer.*)
if [ ${#reports[@]} -gt 0 ]; then
  status=1
  echo
  echo "sanitize.sh: ${#reports[@]} sanitizer report(s):"
  for r in "${reports[@]}"; do
    echo "----- $r"
    head -n 60 "$r"
  done
fi
echo
echo "sanitize.sh $preset: build $((built - start)) s, tests $((done_at - built)) s;" \
     "$(grep -E '^[0-9]+% tests passed' "$build/sanitize-ctest.log" || echo 'no test summary')," \
     "${in_log:-0} report line(s) in the test output, ${#reports[@]} report file(s)"
exit $status

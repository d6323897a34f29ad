#!/usr/bin/env bash
# Stands in for a libFuzzer binary in fuzz_script_smoke.sh: writes its arguments to $FAKE_ARGS,
# prints the libFuzzer log $FAKE_LOG (excerpts of real runs, logs/), saves an input named
# $FAKE_ARTIFACT under -artifact_prefix when set (what libFuzzer does on a crash), and exits
# with $FAKE_RC.
printf '%s\n' "$@" >"$FAKE_ARGS"
for a in "$@"; do
  case $a in -artifact_prefix=*) prefix=${a#-artifact_prefix=} ;; esac
done
[ -n "${FAKE_ARTIFACT:-}" ] && echo crash >"$prefix$FAKE_ARTIFACT"
cat "$FAKE_LOG"
exit "${FAKE_RC:-0}"

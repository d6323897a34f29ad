#!/usr/bin/env bash
# Builds everything and runs the whole test suite through CTest (the README's
# second command; .ci/run calls exactly this).
set -euo pipefail
cd "$(dirname "$0")/.."
start=$(date +%s)
bash scripts/build.sh default
built=$(date +%s)
echo "build: $((built - start)) s"
ctest --preset default --output-on-failure "$@"
echo "tests: $(( $(date +%s) - built )) s"

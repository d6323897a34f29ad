#!/usr/bin/env bash
# Builds the QEMU instruction-count plugin: bench/arm/build.sh [OUT_DIR] (default build/insncount).
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
out=${1:-$root/build/insncount}
mkdir -p "$out"
cc -O2 -fPIC -shared -Wall -Wextra -o "$out/libinsncount.so" "$root/bench/arm/insncount.c"
echo "$out/libinsncount.so"

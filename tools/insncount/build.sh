#!/usr/bin/env bash
# Builds the QEMU instruction-count plugin: tools/insncount/build.sh [OUT_DIR] (default build/insncount).
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
out=${1:-$root/build/insncount}
mkdir -p "$out"
cc -O2 -fPIC -shared -Wall -Wextra -o "$out/libinsncount.so" "$root/tools/insncount/insncount.c"
echo "$out/libinsncount.so"

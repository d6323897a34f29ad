#!/usr/bin/env bash
# Installs what is missing, configures (preset "default": RelWithDebInfo, Ninja) and builds.
# Usage: scripts/build.sh [PRESET] [extra cmake --build args]
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
preset=${1:-default}
shift || true
if [ ! -f "build/$preset/build.ninja" ]; then
  cmake --preset "$preset" >/dev/null
fi
cmake --build --preset "$preset" "$@"

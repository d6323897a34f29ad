#!/usr/bin/env bash
# Which commits changed the code a fuzz target runs since a given time or commit: the files
# build/fuzz/fuzz/fuzz_TARGET is built from (its sources, the headers ninja's dependency log
# records for each object, the .lcm files of the message types it includes) and the configs
# the target loads. A target's executions count for the code at HEAD only when this prints
# nothing for the time its run began (docs/fuzz.md, "Which counts are of the code at HEAD").
set -euo pipefail

usage() {
  cat <<'EOF'
usage: scripts/fuzz-changes.sh TARGET SINCE
       scripts/fuzz-changes.sh --files TARGET

  TARGET   a fuzz target (fuzz/targets/TARGET.cpp), built in build/fuzz (scripts/fuzz.sh)
  SINCE    a commit, or a date git understands ("2026-11-25 06:51", "2026-11-25T06:51Z")
  --files  print the repository files the target is built from (and the configs it loads)

Prints one line per commit after SINCE that touched those files: hash, date (UTC), the files.
Nothing printed: the target's code is the same as at SINCE.
EOF
}

files_only=0
[ "${1:-}" = --files ] && { files_only=1; shift; }
case "${1:-}" in -h|--help) usage; exit 0 ;; esac
[ $# -eq $((2 - files_only)) ] || { usage >&2; exit 2; }
target=$1 since=${2:-}
root=$(cd "$(dirname "$0")/.." && pwd)
build=$root/build/fuzz
[ -f "$root/fuzz/targets/$target.cpp" ] || { echo "fuzz-changes.sh: no target '$target' (fuzz/targets/$target.cpp)" >&2; exit 2; }
[ -f "$build/build.ninja" ] || { echo "fuzz-changes.sh: $build is not configured (run scripts/fuzz.sh first)" >&2; exit 2; }
ninja -C "$build" -t query "fuzz/fuzz_$target" >/dev/null 2>&1 ||
  { echo "fuzz-changes.sh: build/fuzz has no fuzz/fuzz_$target" >&2; exit 2; }

inputs=$(ninja -C "$build" -t inputs "fuzz/fuzz_$target")
closure=$(
  cd "$build"
  {
    grep -E '\.(c|cc|cpp|h|hpp)$' <<<"$inputs" || true
    for o in $(grep '\.o$' <<<"$inputs"); do ninja -t deps "$o" | sed -n 's/^    //p'; done
  } | xargs -r realpath -m | sort -u
)
mapfile -t files < <(
  {
    # repository files, and each generated message header as its .lcm
    sed -n "s#^$root/##p" <<<"$closure" | grep -v '^build/' || true
    sed -nE "s#^$build/lcmtypes/include/aerie/(.*)\.hpp\$#lcmtypes/aerie_\1.lcm#p" <<<"$closure"
    # configs the target loads at run time
    grep -oE '"config/[A-Za-z0-9_./-]+\.yaml"' "$root/fuzz/targets/$target.cpp" | tr -d '"' || true
  } | sort -u
)

if [ $files_only = 1 ]; then printf '%s\n' "${files[@]}"; exit 0; fi
cd "$root"
if git rev-parse -q --verify "$since^{commit}" >/dev/null; then range=("$since..HEAD"); else range=(--since="$since" HEAD); fi
TZ=UTC git log --reverse --format='%h %ad' --date=format-local:'%Y-%m-%d %H:%M' "${range[@]}" -- "${files[@]}" |
  while read -r hash day hour; do
    echo "$hash $day $hour UTC: $(git show --name-only --format= "$hash" -- "${files[@]}" | tr '\n' ' ')"
  done

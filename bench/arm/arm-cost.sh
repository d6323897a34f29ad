#!/usr/bin/env bash
# What the air side costs on a board (issue 16 §3): instructions retired per frame of each
# air-side node's work, counted with a QEMU instruction-count plugin (bench/arm) under
# qemu-user for arm64 and armhf and under qemu-x86_64 for x86, the heap the node takes, and
# (x86, natively) the peak RSS and CPU time per frame. Method: docs/arm.md ("What it costs on a
# board"); figures: docs/results/arm.md.
set -euo pipefail

root=$(cd "$(dirname "$0")/../.." && pwd)
usage() {
  cat <<'EOF'
usage: bench/arm/arm-cost.sh [options]

Counts the instructions each air-side node retires per frame. Every case runs twice, with N1
and N2 frames (the same frames prepared in both runs), under qemu-user with the plugin of
bench/arm (insncount.c); per frame = (count(N2) - count(N1)) / (N2 - N1), so start-up, library
loading and reading the data cancel. Also: the node's heap (glibc mallinfo2 inside the
program, so the target's own), qemu's max RSS, and on x86 native runs (max RSS, CPU s/frame).

options:
  --arch LIST     comma-separated: arm64, armhf, x86 (default arm64,x86)
  --cases LIST    comma-separated case names or prefixes (default: all; --list shows them)
  --list          list the cases and exit
  --quick         small frame counts (a smoke test, a few minutes)
  --out DIR       results (default build/insncount/results); raw.tsv is appended to,
                  per_frame.tsv and table.md are rewritten from it
  --build         first build the four node binaries in the build directories
                  (ninja -j1 under nice); otherwise they must exist
  --native-runs K x86 native timing runs per case, the fastest is kept (default 3)
  -h, --help      this text

needs: qemu-user (the dynamic qemu-aarch64/qemu-arm/qemu-x86_64: Debian's qemu-user-static
cannot load plugins), a C compiler, python3, /usr/bin/time, the build directories
build/arm64, build/armhf (scripts/arm.sh) and build/air (cmake --preset air) with
aerie-track, aerie-vo, aerie-capture and aerie-control built, the sysroots
/opt/aerie-sysroot-<arch>, and the shared data (../shared/data or $AERIE_DATA).
EOF
}

die() { echo "arm-cost.sh: $*" >&2; exit 1; }

archs=arm64,x86
cases_sel=""
quick=0
out="$root/build/insncount/results"
do_build=0
native_runs=3
list=0
while [[ $# -gt 0 ]]; do
  case "$1" in
    --arch) archs=${2:?--arch needs a value}; shift 2 ;;
    --cases) cases_sel=${2:?--cases needs a value}; shift 2 ;;
    --list) list=1; shift ;;
    --quick) quick=1; shift ;;
    --out) out=${2:?--out needs a directory}; shift 2 ;;
    --build) do_build=1; shift ;;
    --native-runs) native_runs=${2:?}; shift 2 ;;
    -h|--help) usage; exit 0 ;;
    *) usage >&2; die "unknown option '$1'" ;;
  esac
done

data=${AERIE_DATA:-$(cd "$root/.." && pwd)/shared/data}
T=$data/tracking
EUROC=$data/stereo_seq/EuRoC_V1_01_easy_f000-094
KITTI=$data/stereo_seq/KITTI_odom_06_f000-050

# Cases: name | binary (capture = the aerie-capture node itself, cost = bench/arm's
# driver) | N1 | N2 | quick N1 | quick N2 | arguments ({N}: frames, {P}: frames prepared).
# 376x240 is the thesis' resolution (the EuRoC camera halved); "native" is the data's own size.
cases=(
  "capture-euroc-376|capture|10|60|2|6|--lcm-url memq:// -s euroc -p $EUROC --downscale 2 --rate 0 --stop {N} --log-level warn"
  "capture-kitti-1226|capture|5|45|2|6|--lcm-url memq:// -s kitti -p $KITTI --rate 0 --stop {N} --log-level warn"
  "track-amcmr-david-376|cost|10|110|2|6|track --source folder --path $T/David/img --width 376 --height 240 --frames {N} --prepare {P}"
  "track-amcmr-boat1-376|cost|10|110|2|6|track --source folder --path $T/uav123_10fps_boat1/img --width 376 --height 240 --frames {N} --prepare {P}"
  "track-amcmr-boat1-1280|cost|10|60|2|6|track --source folder --path $T/uav123_10fps_boat1/img --frames {N} --prepare {P}"
  "track-ipslmr-david-376|cost|10|110|2|6|track --tracker ipsl-mr --source folder --path $T/David/img --width 376 --height 240 --frames {N} --prepare {P}"
  "track-dcf-david-376|cost|5|45|2|6|track --tracker dcf --source folder --path $T/David/img --width 376 --height 240 --frames {N} --prepare {P}"
  "vo-sim-376|cost|10|40|2|6|vo --source sim --width 376 --height 240 --frames {N} --prepare {P}"
  "vo-sim-376-noba|cost|10|40|2|6|vo --no-ba --source sim --width 376 --height 240 --frames {N} --prepare {P}"
  "vo-euroc-376|cost|10|60|2|6|vo --source euroc --path $EUROC --downscale 2 --frames {N} --prepare {P}"
  "vo-kitti-1226|cost|5|45|2|6|vo --source kitti --path $KITTI --frames {N} --prepare {P}"
  "control|cost|100|1100|10|60|control --frames {N} --prepare {P}"
)
if [[ $list == 1 ]]; then
  for c in "${cases[@]}"; do IFS='|' read -r name bin n1 n2 _ _ args <<<"$c"; printf '%-24s N=%s,%s  %s %s\n' "$name" "$n1" "$n2" "$bin" "$args"; done
  exit 0
fi

selected() {
  [[ -z $cases_sel ]] && return 0
  local s
  IFS=',' read -ra sel <<<"$cases_sel"
  for s in "${sel[@]}"; do [[ $1 == "$s"* ]] && return 0; done
  return 1
}

builddir() { case $1 in arm64) echo "$root/build/arm64" ;; armhf) echo "$root/build/armhf" ;; x86) echo "$root/build/air" ;; *) die "unknown arch '$1' (arm64, armhf, x86)" ;; esac; }
qemu_of() { case $1 in arm64) echo qemu-aarch64 ;; armhf) echo qemu-arm ;; x86) echo qemu-x86_64 ;; esac; }
# Emulated CPU: the Pi 4's (NEON; the Pi 5's Cortex-A76 takes the same code path), the
# ODROID U3's Cortex-A9, and qemu's "max" x86 CPU (AVX2: qemu 7.2 has no AVX-512).
cpu_of() { case $1 in arm64) echo cortex-a72 ;; armhf) echo cortex-a9 ;; x86) echo max ;; esac; }
sysroot_of() { case $1 in arm64) echo /opt/aerie-sysroot-arm64 ;; armhf) echo /opt/aerie-sysroot-armhf ;; x86) echo "" ;; esac; }

# ---- checks ----
for t in cc python3 ninja /usr/bin/time; do command -v "$t" >/dev/null || die "'$t' is missing"; done
[[ -d $T && -d $EUROC && -d $KITTI ]] || die "shared data not found under $data (set AERIE_DATA)"
IFS=',' read -ra arch_list <<<"$archs"
for a in "${arch_list[@]}"; do
  b=$(builddir "$a")
  q=$(qemu_of "$a")
  command -v "$q" >/dev/null || die "$q is missing: apt-get install qemu-user (the -static ones cannot load plugins)"
  [[ -f $b/build.ninja ]] || die "$b is not configured (scripts/arm.sh for arm64/armhf, cmake --preset air for x86)"
  s=$(sysroot_of "$a")
  [[ -z $s || -d $s ]] || die "sysroot $s is missing (scripts/arm.sh --arch $a --setup-only)"
done

mkdir -p "$out"
raw=$out/raw.tsv
[[ -f $raw ]] || printf 'date\tarch\tcpu\tcase\tframes\tinsns\tthreads\tqemu_maxrss_kb\twall_s\tprogram_output\n' >"$raw"
log=$out/run.log
echo "== $(date -u +%FT%TZ) arm-cost.sh --arch $archs ${cases_sel:+--cases $cases_sel} $([[ $quick == 1 ]] && echo --quick)" | tee -a "$log"
echo "machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ //'), $(nproc) CPUs; load: $(cut -d' ' -f1-3 /proc/loadavg)" | tee -a "$log"

# ---- build ----
plugin_dir=$root/build/insncount
"$root/bench/arm/build.sh" "$plugin_dir" >/dev/null
plugin=$plugin_dir/libinsncount.so
for a in "${arch_list[@]}"; do
  b=$(builddir "$a")
  if [[ $do_build == 1 ]]; then
    echo "building the nodes in $b (ninja -j1)" | tee -a "$log"
    nice -n 10 ninja -C "$b" -j1 aerie-track aerie-vo aerie-capture aerie-control >>"$log" 2>&1 || die "ninja failed in $b (see $log)"
  fi
  [[ -x $b/bin/aerie-capture ]] || die "$b/bin/aerie-capture is not built (run with --build)"
  drv=$plugin_dir/$a/aerie-cost
  if [[ ! -x $drv || $root/bench/arm/aerie_cost.cpp -nt $drv || $b/air/track/node/libaerie_track_node.a -nt $drv ]]; then
    echo "building $drv" | tee -a "$log"
    nice -n 10 python3 "$root/bench/arm/build_driver.py" "$b" "$drv" >>"$log" 2>&1 || die "building the driver failed (see $log)"
  fi
done

# ---- runs ----
# run ARCH CASE N P BIN ARGS...: one counted run; appends a row to raw.tsv.
counted_run() {
  local a=$1 name=$2 n=$3 bin=$4; shift 4
  local q cpu s f tf o
  q=$(qemu_of "$a"); cpu=$(cpu_of "$a"); s=$(sysroot_of "$a")
  f=$(mktemp); tf=$(mktemp); o=$(mktemp)
  local -a cmd=(env QEMU_CPU="$cpu")
  [[ -n $s ]] && cmd+=(QEMU_LD_PREFIX="$s" "$q" -L "$s") || cmd+=("$q")
  cmd+=(-plugin "$plugin,out=$f" "$bin" "$@")
  if ! nice -n 10 /usr/bin/time -f '%M %e' -o "$tf" "${cmd[@]}" >"$o" 2>>"$log"; then
    echo "FAILED: ${cmd[*]}" | tee -a "$log"; cat "$o" >>"$log"; rm -f "$f" "$tf" "$o"; return 1
  fi
  local insns threads rss wall
  insns=$(sed -n 's/.*insns=\([0-9]*\).*/\1/p' "$f" | tail -1)
  threads=$(sed -n 's/.*threads=\([0-9]*\).*/\1/p' "$f" | tail -1)
  read -r rss wall <"$tf"
  printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$(date -u +%FT%TZ)" "$a" "$cpu" "$name" "$n" "$insns" "$threads" "$rss" "$wall" \
    "$(grep -m1 '^mode=' "$o" || true)" >>"$raw"
  echo "  $a $name frames=$n insns=$insns threads=$threads qemu_maxrss=${rss}KB wall=${wall}s" | tee -a "$log"
  rm -f "$f" "$tf" "$o"
}

# native_run CASE N BIN ARGS...: x86 native, fastest of $native_runs; row with arch x86-native.
native_run() {
  local name=$1 n=$2 bin=$3; shift 3
  local best_rss="" best_cpu="" best_line="" tf o k
  tf=$(mktemp); o=$(mktemp)
  for ((k = 0; k < native_runs; ++k)); do
    nice -n 10 /usr/bin/time -f '%M %U %S' -o "$tf" "$bin" "$@" >"$o" 2>>"$log" || { echo "FAILED natively: $bin $*" | tee -a "$log"; break; }
    local rss u sy cpu
    read -r rss u sy <"$tf"
    cpu=$(python3 -c "print($u+$sy)")
    if [[ -z $best_cpu ]] || python3 -c "import sys; sys.exit(0 if $cpu < $best_cpu else 1)"; then
      best_cpu=$cpu; best_rss=$rss; best_line=$(grep -m1 '^mode=' "$o" || true)
    fi
  done
  printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$(date -u +%FT%TZ)" x86-native host "$name" "$n" "" "" "$best_rss" "$best_cpu" \
    "$best_line" >>"$raw"
  echo "  x86-native $name frames=$n maxrss=${best_rss}KB cpu=${best_cpu}s" | tee -a "$log"
  rm -f "$tf" "$o"
}

for a in "${arch_list[@]}"; do
  b=$(builddir "$a")
  for c in "${cases[@]}"; do
    IFS='|' read -r name kind n1 n2 qn1 qn2 args <<<"$c"
    selected "$name" || continue
    [[ $quick == 1 ]] && n1=$qn1 n2=$qn2
    p=$((n2 + 1))
    if [[ $kind == capture ]]; then bin=$b/bin/aerie-capture; else bin=$plugin_dir/$a/aerie-cost; fi
    for n in "$n1" "$n2"; do
      a_n=${args//\{N\}/$n}; a_n=${a_n//\{P\}/$p}
      # shellcheck disable=SC2086
      counted_run "$a" "$name" "$n" "$bin" $a_n || true
    done
    if [[ $a == x86 ]]; then
      for n in "$n1" "$n2"; do
        a_n=${args//\{N\}/$n}; a_n=${a_n//\{P\}/$p}
        # shellcheck disable=SC2086
        native_run "$name" "$n" "$bin" $a_n || true
      done
    fi
  done
done

python3 "$root/bench/arm/summarise.py" "$raw" "$out" | tee -a "$log"
echo "tables: $out/per_frame.tsv, $out/table.md (raw: $raw)"

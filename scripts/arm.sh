#!/usr/bin/env bash
# The air side for ARM (docs/arm.md): installs what is missing (cross compiler, qemu-user, a
# Debian sysroot of the target's -dev packages), configures and builds the preset arm64 or armhf
# (air-only: common/, air/, the deputy, the link), and runs the air side's tests under qemu-user
# through CTest. Idempotent: a second run only rebuilds what changed and runs the tests again.
set -euo pipefail
cd "$(dirname "$0")/.."

usage() {
  cat <<'EOF'
Usage: scripts/arm.sh [--arch arm64|armhf] [--sysroot DIR] [--jobs N] [--no-test] [--cpu CPU]
                      [--setup-only] [--all] [-h|--help] [-- CTEST_ARGS...]

Builds the air side (preset arm64 or armhf, into build/<arch>) with Debian 12's cross compiler and
runs its unit tests under qemu-user (CMAKE_CROSSCOMPILING_EMULATOR). On a fresh Debian 12 machine,
as root, it first installs the missing host packages and makes the target's sysroot with
mmdebstrap from the Debian archive this machine's apt already uses.

  --arch A       arm64 (aarch64-linux-gnu, default) or armhf (arm-linux-gnueabihf)
  --sysroot DIR  the target sysroot (default /opt/aerie-sysroot-<arch>; made when missing)
  --jobs N       parallel compile jobs (default 2), run under nice
  --no-test      configure and build only
  --cpu CPU      the CPU qemu emulates for the tests (QEMU_CPU; default: qemu's "max", which
                 has SVE2 on arm64). E.g. cortex-a72 (Raspberry Pi 4), cortex-a76 (Pi 5),
                 cortex-a9 (armhf: ODROID U3)
  --setup-only   install the host packages and make the sysroot, nothing else
  --all          also run the 3 procman tests that fail under qemu-user only (no
                 PR_SET_CHILD_SUBREAPER in qemu 7.2; docs/arm.md), left out by default
  --no-landing   leave out the lock-step landing flown after the tests
  -- ARGS        passed to ctest (e.g. -- -R simd -V)

After the tests it runs test_simd_dispatch again on a NEON-only CPU (arm64: cortex-a72) so the
log shows both the SVE and the NEON path of every Highway-dispatched kernel, then (arm64) flies one
seeded lock-step landing with the target's aerie-flightsim, aerie-track and aerie-pilot under
qemu (in a network namespace of its own; about 2 minutes): it fails the run unless it lands.
EOF
}

arch=arm64 sysroot="" jobs=2 run_tests=1 cpu="" setup_only=0 run_all=0 run_landing=1 ctest_args=()
while [ $# -gt 0 ]; do
  case "$1" in
    --arch) arch=$2; shift 2 ;;
    --sysroot) sysroot=$2; shift 2 ;;
    --jobs) jobs=$2; shift 2 ;;
    --no-test) run_tests=0; shift ;;
    --cpu) cpu=$2; shift 2 ;;
    --setup-only) setup_only=1; shift ;;
    --all) run_all=1; shift ;;
    --no-landing) run_landing=0; shift ;;
    -h|--help) usage; exit 0 ;;
    --) shift; ctest_args=("$@"); break ;;
    *) echo "arm.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done

case "$arch" in
  arm64) triplet=aarch64-linux-gnu; qemu=qemu-aarch64-static; binfmt=qemu-aarch64; neon_cpu=cortex-a72 ;;
  armhf) triplet=arm-linux-gnueabihf; qemu=qemu-arm-static; binfmt=qemu-arm; neon_cpu=cortex-a15 ;;
  *) echo "arm.sh: --arch must be arm64 or armhf, not '$arch'" >&2; exit 2 ;;
esac
sysroot=${sysroot:-/opt/aerie-sysroot-$arch}
start=$(date +%s)
log() { echo "arm.sh [$(( $(date +%s) - start )) s]: $*"; }

# --- host packages -------------------------------------------------------------------------------
# Only what the cross build needs on the host: the build tools, lcm-gen and python3 (code
# generation runs on the host), the cross compiler, qemu-user and mmdebstrap. The target's
# libraries come from the sysroot, not from the host.
HOST_PACKAGES=(cmake ninja-build pkg-config liblcm-bin python3 "g++-$triplet" qemu-user-static
               binfmt-support mmdebstrap iproute2)

# The sysroot: the air side's -dev packages for the target (scripts/setup.sh has the full list;
# no VTK, OctoMap, NLopt, benchmark here). libopencv-dev brings every OpenCV module, as its CMake
# package checks that they all exist; the air binaries link only the modules they use.
SYSROOT_PACKAGES=(libc6-dev libstdc++-12-dev libopencv-dev libopencv-contrib-dev libeigen3-dev
                  libceres-dev libblas-dev liblapack-dev liblcm-dev libglib2.0-dev libhwy-dev
                  libyaml-cpp-dev libcli11-dev libspdlog-dev libfmt-dev libgtest-dev libgmock-dev
                  libfuzzylite-dev libsodium-dev libapriltag-dev)

need_root() {
  if [ "$(id -u)" -ne 0 ]; then
    echo "arm.sh: $1 needs root (run as root or with sudo)" >&2
    exit 1
  fi
}

install_host_packages() {
  local missing=() p
  for p in "${HOST_PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  need_root "installing ${missing[*]}"
  log "installing host packages: ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

# The Debian archive entries of this machine's apt configuration (deb822 .sources files and
# one-line sources.list entries for the installed release), written to one file for mmdebstrap.
# The mirror is read here, at run time; it is written nowhere in the repository.
# With "nosecurity" as second argument, the -security suite is left out (see make_sysroot).
apt_sources_for_sysroot() {
  local out=$1 drop=${2:-} codename f
  codename=$(. /etc/os-release && echo "${VERSION_CODENAME:-bookworm}")
  : >"$out"
  for f in /etc/apt/sources.list.d/*.sources; do
    [ -f "$f" ] || continue
    # Only Debian's own archive (signed by the Debian archive keyring or naming the release),
    # paragraph by paragraph.
    awk -v RS= -v ORS='\n\n' -v codename="$codename" -v drop="$drop" '
      /Enabled: *[Nn]o/ { next }
      drop == "nosecurity" && /Suites:[^\n]*-security/ { next }
      /debian-archive-keyring/ || $0 ~ ("Suites:[^\n]*" codename) { print }' "$f" >>"$out"
  done
  for f in /etc/apt/sources.list /etc/apt/sources.list.d/*.list; do
    [ -f "$f" ] || continue
    grep -E "^deb[[:space:]].*[[:space:]]$codename(-updates|-security|/updates)?[[:space:]]" "$f" \
      | grep -v "arch=" | { if [ "$drop" = nosecurity ]; then grep -v -- "-security"; else cat; fi; } >>"$out" || true
  done
  if ! grep -qE "^(deb |URIs:)" "$out"; then
    echo "arm.sh: found no Debian $codename entry in /etc/apt/sources.list* for the sysroot" >&2
    exit 1
  fi
}

make_sysroot() {
  local stamp=$sysroot/.aerie-sysroot want
  want="fixups-3 $arch ${SYSROOT_PACKAGES[*]}"
  if [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$want" ]; then
    return 0
  fi
  need_root "making the sysroot $sysroot"
  local sources tmp
  sources=$(mktemp --suffix=.sources)
  apt_sources_for_sysroot "$sources"
  tmp="$sysroot.new"
  rm -rf "$tmp"
  log "making the $arch sysroot $sysroot with mmdebstrap (${#SYSROOT_PACKAGES[@]} -dev packages and their dependencies)"
  local codename
  codename=$(. /etc/os-release && echo "${VERSION_CODENAME:-bookworm}")
  # extract: unpack the packages and their dependencies, run no maintainer script (nothing of the
  # target architecture has to run to make a sysroot).
  local try
  for try in 1 2 3; do
    # A mirror (or caching proxy) caught mid-sync fails apt-get update ("File has unexpected size"):
    # try again, and the third time without the -security suite, which is the usual culprit for
    # a foreign architecture (the sysroot then has the point release's packages; said below).
    [ "$try" -eq 3 ] && apt_sources_for_sysroot "$sources" nosecurity
    rm -rf "$tmp"
    if mmdebstrap --quiet --variant=extract --architectures="$arch" \
         --include="$(IFS=,; echo "${SYSROOT_PACKAGES[*]}")" "$codename" "$tmp" "$sources"; then
      [ "$try" -eq 3 ] && log "WARNING: the $arch sysroot was made without the -security suite (its index did not download)"
      break
    fi
    [ "$try" -eq 3 ] && { echo "arm.sh: mmdebstrap failed three times" >&2; exit 1; }
    log "mmdebstrap failed (try $try); trying again in 20 s"
    sleep 20
  done
  rm -f "$sources"
  # Absolute symlinks (libz.so -> /lib/...) would point into the host: make them relative.
  find "$tmp" -type l -lname '/*' | while read -r l; do
    ln -sfnr "$tmp$(readlink "$l")" "$l"
  done
  # Device nodes and /tmp of the target's root: qemu's -L looks there first, and a ptmx outside
  # a devpts mount fails forkpty() with ENODEV (the deputy's commands). A sysroot needs neither.
  rm -rf "${tmp:?}/dev" "${tmp:?}/tmp"
  # What update-alternatives would have made: the reference BLAS/LAPACK under their usual names.
  local libdir=$tmp/usr/lib/$triplet name d
  for name in libblas.so libblas.so.3 liblapack.so liblapack.so.3; do
    [ -e "$libdir/$name" ] && continue
    for d in blas lapack atlas openblas-pthread; do
      if [ -e "$libdir/$d/$name" ]; then ln -sfnr "$libdir/$d/$name" "$libdir/$name"; break; fi
    done
  done
  # CMake packages that name libraries by absolute path (Ceres: /usr/lib/<triplet>/liblapack.so):
  # make those paths relative to the sysroot the toolchain file sets.
  grep -rlE 'INTERFACE_LINK_LIBRARIES.*["; ]/usr/lib/' "$libdir/cmake" "$tmp/usr/share" --include='*.cmake' 2>/dev/null \
    | while read -r f; do
        sed -i -E '/INTERFACE_LINK_LIBRARIES/ s#([";])/usr/lib/#\1${CMAKE_SYSROOT}/usr/lib/#g' "$f"
      done
  echo "$want" >"$tmp/.aerie-sysroot"
  rm -rf "$sysroot"
  mv "$tmp" "$sysroot"
  log "sysroot ready: $(du -sh "$sysroot" | cut -f1)"
}

# Tests that start target programs themselves (aerie-deputy, aerie-link, aerie-sim) need the kernel
# to run ARM executables through qemu: binfmt_misc. Not fatal when it cannot be had (a container
# without the right): those tests are then left out and named.
enable_binfmt() {
  local dir=/proc/sys/fs/binfmt_misc
  if [ ! -e "$dir/register" ]; then
    mount -t binfmt_misc binfmt_misc "$dir" 2>/dev/null || true
  fi
  if [ -e "$dir/$binfmt" ] && grep -q enabled "$dir/$binfmt"; then
    return 0
  fi
  if [ -e "$dir/register" ] && [ "$(id -u)" -eq 0 ]; then
    update-binfmts --enable "$binfmt" >/dev/null 2>&1 || update-binfmts --import "$binfmt" >/dev/null 2>&1 || true
  fi
  [ -e "$dir/$binfmt" ] && grep -q enabled "$dir/$binfmt"
}

install_host_packages
make_sysroot
[ "$setup_only" -eq 1 ] && { log "setup done"; exit 0; }

preset=$arch
cfg_args=()
[ "$sysroot" != "/opt/aerie-sysroot-$arch" ] && cfg_args+=("-DAERIE_SYSROOT=$sysroot")
if [ ! -f "build/$preset/build.ninja" ] || [ ${#cfg_args[@]} -gt 0 ]; then
  log "configuring preset $preset"
  cmake --preset "$preset" "${cfg_args[@]}" >/dev/null
fi
log "building preset $preset (-j$jobs)"
nice -n 15 cmake --build --preset "$preset" -j "$jobs"
built=$(date +%s)
log "build done"
[ "$run_tests" -eq 0 ] && exit 0

# Tests that cannot pass under qemu-user 7.2 (Debian 12) and would on the board (docs/arm.md):
# qemu-user refuses prctl(PR_SET_CHILD_SUBREAPER) with EINVAL, so a command's orphans are
# re-parented to init instead of the deputy, which then cannot find and kill them; and its termios
# translation reads a pty's line speed back as 0 (the serial endpoint's settings test; the bytes
# still flow both ways, tested). --all runs them.
QEMU_LIMITED="Deputy.NoOrphansSurviveAStop|Deputy.OrphansOfACrashedCommandAreKilled|ProcmanLcm.ObserverWatchesAndDeputyExitLeavesNothingRunning|SerialEndpoint.ConfiguresTheLineRawAtItsBaudRate"
exclude_re=""
[ "$run_all" -eq 0 ] && exclude_re=$QEMU_LIMITED
if ! enable_binfmt; then
  log "binfmt_misc for $binfmt not available: leaving out the tests that start $arch programs themselves"
  exclude_re="${exclude_re:+$exclude_re|}ProcmanLcm|LinkNode|AerieSim"
fi
exclude=()
if [ -n "$exclude_re" ]; then
  log "left out (qemu-user limits, see docs/arm.md): ${exclude_re//|/, }"
  exclude=(-E "$exclude_re")
fi
[ -n "$cpu" ] && export QEMU_CPU=$cpu
log "running the tests under ${qemu}${cpu:+ (QEMU_CPU=$cpu)}"
status=0
ctest --preset "$preset" "${exclude[@]}" "${ctest_args[@]}" || status=$?
log "tests done in $(( $(date +%s) - built )) s (exit $status)"

# The SIMD target of every Highway-dispatched kernel on a NEON-only core as well.
if [ -z "$cpu" ] && [ -x "build/$preset/tests/test_simd_dispatch" ]; then
  log "Highway dispatch on a NEON-only CPU (QEMU_CPU=$neon_cpu):"
  QEMU_CPU=$neon_cpu QEMU_LD_PREFIX=$sysroot "$qemu" -L "$sysroot" "build/$preset/tests/test_simd_dispatch" \
    --gtest_brief=1 || status=$?
fi
# One closed-loop landing on the air side's architecture (issue 50, section 5): the target's
# binaries under qemu over LCM in a network namespace of their own (multicast on its loopback
# only), in lock-step: the simulator's next frame waits for the tracker's TRACK and the pilot's
# CTRL_CMD. Seed 2 of config/sim/landing_room.yaml; the flightsim's one-line result decides.
landing_check() {
  local ns=aerie-arm-landing-$$ dir=build/$preset/landing url="udpm://239.255.76.67:7667?ttl=0" t p rc=0
  if [ "$(id -u)" -ne 0 ] || ! ip netns add "$ns" 2>/dev/null; then
    log "landing under qemu left out: it needs root for its network namespace"
    return 0
  fi
  mkdir -p "$dir"
  rm -f "$dir/result.txt"
  ip netns exec "$ns" ip link set lo up
  ip netns exec "$ns" ip route add 224.0.0.0/4 dev lo
  local run=(ip netns exec "$ns" env LCM_DEFAULT_URL="$url" QEMU_LD_PREFIX="$sysroot" "$qemu" -L "$sysroot")
  log "lock-step landing under ${qemu} (seed 2, config/sim/landing_room.yaml)"
  "${run[@]}" "build/$preset/bin/aerie-track" --config config/track_landing.yaml --log-level warn >"$dir/track.log" 2>&1 &
  t=$!
  "${run[@]}" "build/$preset/bin/aerie-pilot" --config config/pilot.yaml --log-level warn >"$dir/pilot.log" 2>&1 &
  p=$!
  sleep 5  # both subscribed before the first frame
  timeout 600 "${run[@]}" "build/$preset/bin/aerie-flightsim" --config config/sim/landing_room.yaml --mode lockstep \
    --answer TRACK CTRL_CMD --seed 2 --result "$dir/result.txt" --log-level warn >"$dir/flightsim.log" 2>&1 || rc=$?
  kill "$t" "$p" 2>/dev/null || true
  wait "$t" "$p" 2>/dev/null || true
  ip netns del "$ns"
  log "landing: $(cat "$dir/result.txt" 2>/dev/null || echo "no result (flightsim exit $rc; logs in $dir)")"
  grep -q "^LANDED (success)" "$dir/result.txt" 2>/dev/null
}
if [ "$run_landing" -eq 1 ] && [ "$arch" = arm64 ]; then
  landing_check || status=1
fi
log "total $(( $(date +%s) - start )) s"
exit $status

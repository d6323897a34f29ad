#!/usr/bin/env bash
# Aerie split over two hosts, on one machine: two network namespaces stand for the
# drone's computer ("air") and the ground station ("ground"), joined by a veth pair.
# A deputy runs in each; the sheriff on the ground starts the air and ground commands
# of config/split.pmd; the ground records the flight; aerie-latency summarises it.
#
#   sudo scripts/split-demo.sh                # one LCM network: multicast, ttl=1, across the veth
#   sudo scripts/split-demo.sh --link         # two LCM networks joined by aerie-link (config/link.yaml)
#   sudo scripts/split-demo.sh --duration 30 --log logs/my-split.lcm
#
# Run from the repository root after building (bash scripts/build.sh). Needs root
# (network namespaces). Everything it creates is removed at the end, also on failure
# or Ctrl-C. No traffic leaves the two namespaces.
set -euo pipefail

usage() {
  sed -n '2,13p' "$0" | sed 's/^# \{0,1\}//'
  cat <<EOF
Options:
  --link              relay through aerie-link between an air and a ground network
  --link-config FILE  aerie-link configuration (default: config/link.yaml; the demo adds PMD_* to its channels)
  --config FILE       procman config (default: config/split.pmd)
  --duration S        seconds to fly between start_all and stop_all (default: 20)
  --log FILE          flight log written on the ground (default: logs/split.lcm)
  --bin DIR           Aerie executables (default: build/default/bin)
EOF
}

LINK=0
LINK_CONFIG=config/link.yaml
CONFIG=config/split.pmd
DURATION=20
LOG=logs/split.lcm
BIN=${AERIE_BIN:-build/default/bin}
while [[ $# -gt 0 ]]; do
  case "$1" in
    --link) LINK=1 ;;
    --link-config) LINK_CONFIG=$2; shift ;;
    --config) CONFIG=$2; shift ;;
    --duration) DURATION=$2; shift ;;
    --log) LOG=$2; shift ;;
    --bin) BIN=$2; shift ;;
    -h|--help) usage; exit 0 ;;
    *) echo "split-demo: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
  shift
done

die() { echo "split-demo: $*" >&2; exit 1; }
[[ $(id -u) -eq 0 ]] || die "needs root for network namespaces (sudo $0 ...)"
command -v ip >/dev/null || die "iproute2 'ip' is missing (apt-get install iproute2)"
[[ -f $CONFIG ]] || die "no procman config '$CONFIG' (run from the repository root)"
needed=(aerie-deputy aerie-sheriff aerie-latency aerie-capture aerie-log)
[[ $LINK -eq 1 ]] && needed+=(aerie-link)
for exe in "${needed[@]}"; do
  [[ -x $BIN/$exe ]] || die "$BIN/$exe not found: build first (bash scripts/build.sh) or give --bin"
done

BIN=$(cd "$BIN" && pwd)
AIR=aerie-split-$$-air
GROUND=aerie-split-$$-ground
VA=vsa$$; VG=vsg$$                  # veth ends (at most 15 characters)
RUN_DIR=$(mktemp -d /tmp/aerie-split.XXXXXX)
PIDS=()

cleanup() {
  local rc=$?
  trap - EXIT INT TERM
  for (( i=${#PIDS[@]}-1; i>=0; i-- )); do kill -TERM "${PIDS[$i]}" 2>/dev/null || true; done
  for pid in "${PIDS[@]}"; do
    for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -KILL "$pid" 2>/dev/null || true
  done
  for ns in "$AIR" "$GROUND"; do
    if ip netns list | grep -q "^$ns\b"; then
      for pid in $(ip netns pids "$ns" 2>/dev/null); do kill -KILL "$pid" 2>/dev/null || true; done
      ip netns del "$ns" || true
    fi
  done
  echo "split-demo: namespaces removed; process logs in $RUN_DIR"
  exit $rc
}
trap cleanup EXIT
trap 'exit 130' INT TERM

echo "split-demo: creating namespaces $AIR and $GROUND"
ip netns add "$AIR"
ip netns add "$GROUND"
for ns in "$AIR" "$GROUND"; do ip -n "$ns" link set lo up; done
ip -n "$AIR" link add "$VA" type veth peer name "$VG" netns "$GROUND"
ip -n "$AIR" addr add 10.214.0.1/24 dev "$VA"
ip -n "$GROUND" addr add 10.214.0.2/24 dev "$VG"
ip -n "$AIR" link set "$VA" up
ip -n "$GROUND" link set "$VG" up
ip -n "$AIR" route add 224.0.0.0/4 dev "$VA"
ip -n "$GROUND" route add 224.0.0.0/4 dev "$VG"

if [[ $LINK -eq 1 ]]; then
  # The air network stays on the air host's loopback; the ground network uses the veth.
  AIR_URL="udpm://239.255.76.67:7667?ttl=0"
  GROUND_URL="udpm://239.255.76.68:7668?ttl=1"
  ip -n "$AIR" route add 239.255.76.67/32 dev lo
  # The link's config lets no procman channel cross by default; this demo runs the air deputy
  # from the ground sheriff, so a copy names them explicitly (docs/link.md "Channels").
  awk '/^air_to_ground:/ { dir = "down" } /^ground_to_air:/ { dir = "up" }
       /^  channels: "/ { sub(/"$/, dir == "down" ? "|PMD_INFO2|PMD_PRINTF|PMD_DISCOVER\"" : "|PMD_ORDERS2_SEALED|PMD_DISCOVER\"") }
       { print }' "$LINK_CONFIG" >"$RUN_DIR/link.yaml"
  grep -q 'PMD_ORDERS2' "$RUN_DIR/link.yaml" || die "$LINK_CONFIG: no ground_to_air.channels line to add PMD_* to"
  echo "split-demo: aerie-link ($LINK_CONFIG, with PMD_* named) on the air host between $AIR_URL and $GROUND_URL"
  ip netns exec "$AIR" "$BIN/aerie-link" --config "$RUN_DIR/link.yaml" --air-url "$AIR_URL" --ground-url "$GROUND_URL" \
    >"$RUN_DIR/link.log" 2>&1 &
  LINK_PID=$!
  PIDS+=($LINK_PID)
  sleep 0.5
else
  AIR_URL="udpm://239.255.76.67:7667?ttl=1"
  GROUND_URL=$AIR_URL
  echo "split-demo: one LCM network, $AIR_URL, across the veth"
fi

# The ground logger asks for a 4 MiB socket buffer (config/split.pmd); the kernel caps it at
# net.core.rmem_max (not per namespace), 208 KiB by default.
rmem_max=$(cat /proc/sys/net/core/rmem_max 2>/dev/null || echo 0)
if [[ $rmem_max -lt 4194304 ]]; then
  if echo 4194304 2>/dev/null >/proc/sys/net/core/rmem_max; then
    echo "split-demo: raised net.core.rmem_max from $rmem_max to 4194304 (the logger's receive buffer)"
  else
    echo "split-demo: could not raise net.core.rmem_max from $rmem_max: the logger may lose image bursts" >&2
  fi
fi

mkdir -p "$(dirname "$LOG")"
# The commands inherit the deputy's environment: their LCM URL and the log name.
# Keyed procman (docs/procman.md "Keyed mode"): one mission key for this run, in the run's temp folder.
MISSION_KEY="${AERIE_MISSION_KEY:-$RUN_DIR/mission.key}"
[ -f "$MISSION_KEY" ] || "$BIN/aerie-keys" generate --out "$MISSION_KEY" >/dev/null
ip netns exec "$AIR" env LCM_DEFAULT_URL="$AIR_URL" "$BIN/aerie-deputy" --name air --key "$MISSION_KEY" \
  --state "$RUN_DIR/deputy-air.counters" >"$RUN_DIR/deputy-air.log" 2>&1 &
PIDS+=($!)
ip netns exec "$GROUND" env LCM_DEFAULT_URL="$GROUND_URL" AERIE_LOG="$LOG" "$BIN/aerie-deputy" --name ground \
  --key "$MISSION_KEY" --state "$RUN_DIR/deputy-ground.counters" >"$RUN_DIR/deputy-ground.log" 2>&1 &
PIDS+=($!)

sheriff() {
  ip netns exec "$GROUND" env LCM_DEFAULT_URL="$GROUND_URL" "$BIN/aerie-sheriff" "$CONFIG" --key "$MISSION_KEY" --no-table \
    --wait-timeout 60 --on-script-complete exit --script "$@"
}
t0=$(date +%s%N)
echo "split-demo: sheriff (ground) runs script start_all"
sheriff start_all
echo "split-demo: flying for $DURATION s"
sleep "$DURATION"
echo "split-demo: sheriff (ground) runs script stop_all"
sheriff stop_all
t1=$(date +%s%N)
echo "split-demo: flight done in $(( (t1 - t0) / 1000000 )) ms; log $LOG"
if [[ $LINK -eq 1 ]]; then
  kill -INT "$LINK_PID"; wait "$LINK_PID" || true
  echo "split-demo: aerie-link totals:"; tail -n 2 "$RUN_DIR/link.log"
fi
echo
"$BIN/aerie-latency" "$LOG"
# What the recorder missed (sequence gaps that are not a producer's skipped frames, aerie-log info).
lost=$("$BIN/aerie-log" info "$LOG" 2>/dev/null | grep '^logger lost:' || true)
echo "split-demo: ground ${lost:-logger lost: unknown (aerie-log info $LOG failed)}"

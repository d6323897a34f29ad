#!/usr/bin/env bash
# One door per host (issue 46 section 1; docs/security.md "Deployment: one door"): the nodes run
# in a network namespace that has only loopback, the radio (or LAN) interface lives in another
# namespace where only the door's half runs, and the half holds one socket in each -- its sealed
# UDP socket on the radio, its LCM sockets among the nodes (aerie-link --lcm-netns). Nothing but
# the door's port is reachable from the radio, by multicast or unicast: the nodes' namespace has
# no interface but loopback. The air host runs it with the air half (the default); the ground
# station with --half ground, so that no one on the radio or the ground LAN can put a command on
# the ground's LCM for the ground half to sign with the operator's key.
#
#   sudo scripts/air-netns.sh up --radio wlan0        # namespaces; wlan0 moves into the radio one
#   sudo scripts/air-netns.sh door -- --key /etc/aerie/mission.key --operator-pub /etc/aerie/operator.key.pub \
#                                     --listen 10.0.0.1:17200 --peer 10.0.0.2:17200
#   sudo scripts/air-netns.sh nodes -- aerie-deputy --name air      # any air node (procman's deputy, ...)
#   sudo scripts/air-netns.sh check                   # refuses a topology that is not one door
#   sudo scripts/air-netns.sh down                    # the radio back to the host, namespaces removed
#   sudo scripts/air-netns.sh up --half ground --radio eth0 ...   # the same on the ground station
#
# Needs root and iproute2. `door` runs aerie-link --half air|ground --config config/link.yaml
# (give more options after --); `nodes` runs its command in the nodes' namespace.
set -euo pipefail

usage() {
  sed -n '2,20p' "$0" | sed 's/^# \{0,1\}//'
  cat <<EOF
Options (after the command, before -- and the command's own arguments):
  --half H          air (default) or ground: which half the door runs, and the default names
  --nodes-ns NAME   the nodes' namespace (default: aerie-air; aerie-ground with --half ground)
  --radio-ns NAME   the radio's namespace (default: aerie-radio; aerie-lan with --half ground)
  --radio IFACE     (up) the radio interface to move into the radio namespace
  --address CIDR    (up) an address for the radio interface there (e.g. 10.0.0.1/24)
  --bin DIR         Aerie executables (default: build/default/bin)
  --config FILE     (door) link configuration (default: config/link.yaml)
EOF
}

die() { echo "air-netns: $*" >&2; exit 1; }

[[ $# -ge 1 ]] || { usage; exit 2; }
CMD=$1
shift
case "$CMD" in -h|--help) usage; exit 0 ;; esac
HALF=air
NODES=
RADIO=
IFACE=
ADDRESS=
BIN=${AERIE_BIN:-build/default/bin}
CONFIG=config/link.yaml
while [[ $# -gt 0 ]]; do
  case "$1" in
    --half) HALF=$2; shift ;;
    --nodes-ns) NODES=$2; shift ;;
    --radio-ns) RADIO=$2; shift ;;
    --radio) IFACE=$2; shift ;;
    --address) ADDRESS=$2; shift ;;
    --bin) BIN=$2; shift ;;
    --config) CONFIG=$2; shift ;;
    --) shift; break ;;
    -h|--help) usage; exit 0 ;;
    *) echo "air-netns: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
  shift
done

case "$HALF" in
  air) NODES=${NODES:-aerie-air}; RADIO=${RADIO:-aerie-radio} ;;
  ground) NODES=${NODES:-aerie-ground}; RADIO=${RADIO:-aerie-lan} ;;
  *) echo "air-netns: --half must be air or ground, not '$HALF'" >&2; exit 2 ;;
esac

[[ $(id -u) -eq 0 ]] || die "needs root for network namespaces (sudo $0 ...)"
command -v ip >/dev/null || die "iproute2 'ip' is missing (apt-get install iproute2)"
exists() { ip netns list | awk '{print $1}' | grep -qx "$1"; }

# The nodes' namespace must hold loopback only; the radio's must not be the host's.
check() {
  exists "$NODES" || die "no namespace '$NODES' (air-netns.sh up first)"
  exists "$RADIO" || die "no namespace '$RADIO' (air-netns.sh up first)"
  local links
  links=$(ip -n "$NODES" -o link show | awk -F': ' '{print $2}' | sed 's/@.*//')
  [[ $links == lo ]] || die "namespace '$NODES' must hold loopback only, it holds: $(echo $links)"
  ip -n "$NODES" -o link show lo | grep -q 'UP' || die "loopback of '$NODES' is down"
  # Nothing but aerie-link may listen on UDP in the radio's namespace.
  local others
  others=$(ip netns exec "$RADIO" ss -Hulpn 2>/dev/null | grep -v '"aerie-link"' || true)
  [[ -z $others ]] || die "something other than aerie-link listens on UDP in '$RADIO':
$others"
  echo "air-netns: one door: '$NODES' has loopback only; in '$RADIO' only aerie-link listens"
}

case "$CMD" in
  up)
    exists "$NODES" || ip netns add "$NODES"
    exists "$RADIO" || ip netns add "$RADIO"
    ip -n "$NODES" link set lo up
    ip -n "$NODES" route replace 224.0.0.0/4 dev lo  # LCM multicast (ttl=0) among the nodes
    ip -n "$RADIO" link set lo up
    if [[ -n $IFACE ]]; then
      ip link set "$IFACE" netns "$RADIO"
      [[ -n $ADDRESS ]] && ip -n "$RADIO" addr add "$ADDRESS" dev "$IFACE"
      ip -n "$RADIO" link set "$IFACE" up
    fi
    check
    ;;
  down)
    if [[ -n $IFACE ]] && exists "$RADIO"; then
      ip -n "$RADIO" link set "$IFACE" netns 1 || true  # back to the host's namespace
    fi
    pids=$( { ip netns pids "$NODES" 2>/dev/null; ip netns pids "$RADIO" 2>/dev/null; } || true)
    [[ -n $pids ]] && kill $pids 2>/dev/null || true
    exists "$NODES" && ip netns del "$NODES"
    exists "$RADIO" && ip netns del "$RADIO"
    echo "air-netns: removed '$NODES' and '$RADIO'"
    ;;
  check)
    check
    ;;
  door)
    exists "$NODES" && exists "$RADIO" || die "namespaces missing (air-netns.sh up first)"
    [[ -x $BIN/aerie-link ]] || die "$BIN/aerie-link not found: build first or give --bin"
    exec ip netns exec "$RADIO" "$BIN/aerie-link" --half "$HALF" --config "$CONFIG" \
      --lcm-netns "/run/netns/$NODES" "$@"
    ;;
  nodes)
    exists "$NODES" || die "no namespace '$NODES' (air-netns.sh up first)"
    [[ $# -ge 1 ]] || die "nodes: give the command after --"
    # A secure deployment: a node that takes commands refuses a network-facing LCM URL (ttl > 0).
    AERIE_DEPLOYMENT=secure exec ip netns exec "$NODES" "$@"
    ;;
  *)
    die "unknown command '$CMD' (up, door, nodes, check, down; see --help)"
    ;;
esac

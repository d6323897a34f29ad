# Shared by the capture benchmarks: paths, a network namespace with loopback multicast
# (created here, deleted on exit), and the LCM URLs.
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
BIN=${AERIE_BIN:-$ROOT/build/default/bin}
DATA=${AERIE_DATA_DIR:-$ROOT/../shared/data}
EUROC=$DATA/stereo_seq/EuRoC_V1_01_easy_f000-094
KITTI=$DATA/stereo_seq/KITTI_odom_06_f000-050
URL='udpm://239.255.76.67:7667?ttl=0'
RECV_URL="$URL&recv_buf_size=4194304"   # receivers: 4 MB socket buffer (docs/logs.md)
PY=/usr/bin/python3

NS=""
make_namespace() {  # make_namespace NAME
  [ "$(id -u)" -eq 0 ] || { echo "needs root (ip netns add)" >&2; exit 1; }
  NS="$1-$$"
  ip netns add "$NS"
  trap 'ip netns del "$NS" 2>/dev/null || true' EXIT
  ip netns exec "$NS" ip link set lo up
  ip netns exec "$NS" ip route add 224.0.0.0/4 dev lo
}
# Runs a command in the namespace. `ip netns exec` execs the command, so `in_ns ... &`
# would give the pid of a subshell: background processes use `ip netns exec "$NS"` directly.
in_ns() { ip netns exec "$NS" "$@"; }

machine_note() {  # one line: the load when the figure was taken
  echo "$(date -u +%Y-%m-%dT%H:%M:%SZ) $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg)"
}

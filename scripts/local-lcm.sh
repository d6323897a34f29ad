# Shared set-up of the scripts that fly the demo chain on this host (scripts/demo.sh,
# scripts/soak.sh). Sourced, not run:   source scripts/local-lcm.sh
#
#   aerie_local_lcm TAG   LCM on this host: UDP multicast that never leaves it (ttl=0) in
#                         LCM_DEFAULT_URL, the multicast route on lo when it is missing
#                         (root), net.core.rmem_max raised to 4 MiB (root). Messages start
#                         with "TAG:".
#   aerie_start_xvfb      a private Xvfb when DISPLAY is unset (the viewer renders off-screen
#                         but needs an X server); sets DISPLAY and xvfb_pid ("" when none).

aerie_local_lcm() {
  local tag="$1"
  # recv_buf_size: every node's socket receives every channel; the 208 KiB default dropped
  # 14,000-37,000 datagrams per node in the 30 min soak under load (docs/results/soak.md).
  export LCM_DEFAULT_URL='udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304'
  # A node that takes commands then refuses a URL with ttl > 0 (common/bus/deployment.hpp).
  export AERIE_DEPLOYMENT=secure
  if ! ip route show 224.0.0.0/4 2>/dev/null | grep -q .; then
    if [ "$(id -u)" -eq 0 ]; then
      ip route add 224.0.0.0/4 dev lo
      echo "$tag: added the multicast route 224.0.0.0/4 on lo (ip route add 224.0.0.0/4 dev lo)"
    else
      echo "$tag: no multicast route; as root run: ip route add 224.0.0.0/4 dev lo" >&2
    fi
  fi
  # lcm-logger and the nodes need large socket buffers: stereo frames arrive as bursts of
  # fragments that overflow the kernel default (docs/logs.md).
  local rmem_max
  rmem_max=$(cat /proc/sys/net/core/rmem_max 2>/dev/null || echo 0)  # no sysctl: procps may be absent
  if [ "$rmem_max" -lt 4194304 ] && [ "$(id -u)" -eq 0 ]; then
    if echo 4194304 2>/dev/null >/proc/sys/net/core/rmem_max; then
      echo "$tag: raised net.core.rmem_max from $rmem_max to 4194304 (UDP receive buffers for images)"
    else
      echo "$tag: could not raise net.core.rmem_max from $rmem_max (read-only /proc/sys?): large images may be dropped" >&2
    fi
  fi
}

aerie_start_xvfb() {
  xvfb_pid=""
  if [ -z "${DISPLAY:-}" ]; then
    local n=$((90 + RANDOM % 100))
    while [ -e "/tmp/.X$n-lock" ]; do n=$((n + 1)); done  # a display no X server holds
    export DISPLAY=:$n
    Xvfb "$DISPLAY" -screen 0 1280x1024x24 -nolisten tcp -noreset >/dev/null 2>&1 &  # no reset when the last client leaves
    xvfb_pid=$!
  fi
}

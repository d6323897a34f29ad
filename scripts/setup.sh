#!/usr/bin/env bash
# Installs the Debian 12 packages Aerie builds and runs with. Idempotent: when
# everything is present it only checks (dpkg-query) and returns in well under a second.
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build pkg-config
  liblcm-dev liblcm-bin liblcm-java default-jdk-headless libjchart2d-java libglib2.0-dev
  libopencv-dev libopencv-contrib-dev libeigen3-dev libceres-dev libapriltag-dev
  liboctomap-dev libdynamicedt3d-dev octomap-tools
  libvtk9-dev mpi-default-dev xvfb xauth
  libyaml-cpp-dev libcli11-dev libspdlog-dev libfuzzylite-dev libnlopt-cxx-dev libhwy-dev libsodium-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  iproute2 python3-numpy python3-matplotlib librsvg2-bin
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
[ ${#missing[@]} -eq 0 ] && exit 0

echo "setup: installing ${#missing[@]} Debian packages: ${missing[*]}"
if [ "$(id -u)" -ne 0 ]; then
  echo "setup: run as root (or with sudo) to install packages" >&2
  exit 1
fi
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "setup: done"

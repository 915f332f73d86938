#!/usr/bin/env bash
# Installs every build/test dependency of posefilter from Debian packages.
# Idempotent: packages already installed are not touched, and apt-get runs only when
# something is missing. Needs root (or sudo) on a Debian 12 machine.
#
# usage: scripts/setup.sh [peers|hw]
#   peers: also the peer methods the benchmarks compare with (python3-open3d and
#          python3-opencv for scripts/peers.py); not needed to build or test.
#   hw:    also Yosys, for the RTL raster core's synthesis (scripts/rtl/synth_raster_core.sh);
#          not needed to build or test (Verilator, for the RTL co-simulation test, is always
#          installed).
set -euo pipefail

PACKAGES=(
  build-essential cmake pkg-config
  libeigen3-dev libassimp-dev libpng-dev nlohmann-json3-dev libcli11-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  python3 python3-dev python3-numpy python3-pytest pybind11-dev python3-matplotlib
  python3-pip python3-venv python3-setuptools python3-wheel python3-distributed
  libsystemc-dev libmeshoptimizer-dev libqhull-dev clang-tools clang libclang-rt-dev libomp-dev
  clang-tidy clang-format  # scripts/tidy.sh, .clang-format
  libvulkan-dev glslang-tools mesa-vulkan-drivers vulkan-validationlayers
  verilator
  libjs-three chromium  # three.js of the viewer page (inlined at build time); its browser tests
)

case "${1:-}" in
  "") ;;
  peers) PACKAGES+=(python3-open3d python3-opencv python3-scipy) ;;
  hw) PACKAGES+=(yosys) ;;
  *) echo "setup: unknown argument '$1' (usage: scripts/setup.sh [peers|hw])" >&2; exit 2 ;;
esac

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#PACKAGES[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "setup: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"

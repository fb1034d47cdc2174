#!/usr/bin/env bash
# Installs kanegen's build and run dependencies from Debian's packages, only
# those missing (idempotent; needs root or sudo).
set -euo pipefail
packages=(
  build-essential cmake pkg-config
  libeigen3-dev libfmt-dev libyaml-cpp-dev nlohmann-json3-dev libcli11-dev
  libsundials-dev libginac-dev catch2 libbenchmark-dev libspectra-dev libboost-dev zlib1g-dev
  python3 python3-numpy python3-scipy python3-matplotlib python3-dev pybind11-dev python3-pybind11
  libopenmpi-dev openmpi-bin
  libmujoco-dev libsimbody-dev
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "installing: ${missing[*]}"
  SUDO=""
  [[ $(id -u) -ne 0 ]] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
else
  echo "all dependencies present"
fi

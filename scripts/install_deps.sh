#!/usr/bin/env bash
# Installs kanegen's build and run dependencies from Debian's packages, only
# those missing (idempotent; needs root or sudo).
#   install_deps.sh demo   what the CLI and the demo's plots need
#   install_deps.sh        all of it: also the tests, benchmarks, peers (MuJoCo,
#                          Simbody), the Python module and Open MPI
set -euo pipefail
packages=(
  build-essential cmake pkg-config ccache
  libeigen3-dev libfmt-dev libyaml-cpp-dev nlohmann-json3-dev libcli11-dev
  libsundials-dev libginac-dev libspectra-dev libboost-dev zlib1g-dev
  python3 python3-numpy python3-matplotlib
)
if [[ "${1:-all}" != demo ]]; then
  packages+=(
    catch2 libbenchmark-dev
    python3-scipy python3-dev pybind11-dev python3-pybind11
    libopenmpi-dev openmpi-bin
    libmujoco-dev libsimbody-dev
  )
fi
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

#!/usr/bin/env bash
# Installs kanegen's build and run dependencies from Debian's packages, only
# those missing (idempotent; needs root or sudo).
#   install_deps.sh demo-build   what the CLI needs to build and run (compiler,
#                                cmake, ninja, ccache, the libraries)
#   install_deps.sh demo-plot    what the demo's plots and 3D view need (numpy, matplotlib,
#                                three.js: libjs-three)
#   install_deps.sh demo         both
#   install_deps.sh              all of it: also the tests, benchmarks, peers
#                                (MuJoCo, Simbody), the Python module, Open MPI, clang (the
#                                JIT's second compiler for u-dot, engine/jit.cpp) and the
#                                browser the 3D view's test opens (chromium)
set -euo pipefail
build_packages=(
  build-essential cmake ninja-build pkg-config ccache
  libeigen3-dev libfmt-dev libyaml-cpp-dev nlohmann-json3-dev libcli11-dev
  libsundials-dev libginac-dev libspectra-dev libboost-dev zlib1g-dev
)
plot_packages=(python3 python3-numpy python3-matplotlib libjs-three)
case "${1:-all}" in
  demo-build) packages=("${build_packages[@]}") ;;
  demo-plot) packages=("${plot_packages[@]}") ;;
  demo) packages=("${build_packages[@]}" "${plot_packages[@]}") ;;
  all)
    packages=("${build_packages[@]}" "${plot_packages[@]}"
      catch2 libbenchmark-dev
      python3-scipy python3-dev pybind11-dev python3-pybind11
      libopenmpi-dev openmpi-bin
      libmujoco-dev libsimbody-dev
      clang
      chromium)
    ;;
  *) echo "install_deps.sh: unknown set '$1' (expected demo-build, demo-plot, demo or nothing)" >&2; exit 2 ;;
esac
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

#!/usr/bin/env bash
# Configures and builds kanegen (Release) into ./build, through ccache when it
# is installed (cmake/BuildSpeed.cmake: a second clone on the same machine hits
# its cache), with Ninja when it is installed and with precompiled headers.
#   build.sh                     everything: the CLI, the Python module, the
#                                examples, the benchmarks and peers, the tests
#   build.sh --demo              the kanegen CLI only (what scripts/demo.sh runs);
#                                configured without the tests, benchmarks, examples
#                                and Python module, whose packages it does not need
set -euo pipefail
cd "$(dirname "$0")/.."
args=(-DCMAKE_BUILD_TYPE=Release)
targets=()
if [[ "${1:-}" == --demo ]]; then
  # options not given keep their cached value: a tree configured for the tests
  # stays so, and a fresh one leaves out what needs packages the demo skips
  if [[ ! -f build/CMakeCache.txt ]]; then
    args+=(-DKANEGEN_BUILD_TESTS=OFF -DKANEGEN_BUILD_BENCH=OFF -DKANEGEN_BUILD_EXAMPLES=OFF -DKANEGEN_BUILD_PYTHON=OFF)
  fi
  targets=(--target kanegen)
else
  # the example simulators at -O1: the suite runs them for a few seconds (CMakeLists.txt)
  args+=(-DKANEGEN_BUILD_TESTS=ON -DKANEGEN_BUILD_BENCH=ON -DKANEGEN_BUILD_EXAMPLES=ON -DKANEGEN_BUILD_PYTHON=ON
         -DKANEGEN_EXAMPLES_OPTIONS=-O1)
fi
# Ninja when installed (install_deps.sh installs it): it schedules the two
# cores better than make; a tree configured before keeps its generator
if [[ ! -f build/CMakeCache.txt ]] && command -v ninja >/dev/null; then
  args+=(-G Ninja)
fi
cmake -S . -B build "${args[@]}" >/dev/null
cmake --build build -j"$(nproc)" "${targets[@]}"

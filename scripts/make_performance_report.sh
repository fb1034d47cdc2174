#!/usr/bin/env bash
# One command for docs/performance.md: builds kanegen if needed, runs
# `kanegen bench` (work-precision: error against wall time, both engines, all
# integrators) on
#   - models/explorer1.yaml        flexible spinner (modal antennas), t_end 200 s
#   - models/explorer1_rigid.yaml  the same with hinged rigid antennas, t_end 200 s
#   - a stiff model: models/extreme/stiff_appendage.yaml (kHz mast modes; t_end 5 s
#     instead of its 20 s: the explicit methods sit at their stability limit, ~27000
#     steps per simulated second, whatever the tolerance), else models/spacecraft_arrays.yaml (100 s)
# and writes docs/performance.md with the plots as docs/img/perf_<model>.png.
# About 5-10 minutes on 2 cores. Timings are wall-clock: run it on a quiet machine.
#
#   scripts/make_performance_report.sh
# Environment: BUILD_DIR (build), BENCH_OUT (BUILD_DIR/perf), REPEATS (3),
#   T_END (200, the explorer models), STIFF_T_END (5), KANEGEN_PYTHON (/usr/bin/python3).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${BUILD_DIR:-build}
OUT=${BENCH_OUT:-$BUILD/perf}
REPEATS=${REPEATS:-3}
T_END=${T_END:-200}
STIFF_T_END=${STIFF_T_END:-5}
PY=${KANEGEN_PYTHON:-/usr/bin/python3}
export KANEGEN_PYTHON=$PY

if [ ! -f "$BUILD/CMakeCache.txt" ]; then
  cmake -S . -B "$BUILD" -DCMAKE_BUILD_TYPE=Release
fi
cmake --build "$BUILD" -j2 --target kanegen
KANEGEN=$BUILD/bin/kanegen

if [ -f models/extreme/stiff_appendage.yaml ]; then
  STIFF=(models/extreme/stiff_appendage.yaml --t-end "$STIFF_T_END")
else
  STIFF=(models/spacecraft_arrays.yaml --t-end 100)
fi

load_before=$(cut -d' ' -f1-3 /proc/loadavg)
rm -rf "$OUT"
"$KANEGEN" bench models/explorer1.yaml --t-end "$T_END" --repeats "$REPEATS" --out "$OUT/explorer1"
"$KANEGEN" bench models/explorer1_rigid.yaml --t-end "$T_END" --repeats "$REPEATS" --out "$OUT/explorer1_rigid"
"$KANEGEN" bench "${STIFF[@]}" --repeats "$REPEATS" --out "$OUT/stiff"
load_after=$(cut -d' ' -f1-3 /proc/loadavg)

"$PY" scripts/plot_work_precision.py report --out docs/performance.md --img-dir docs/img \
  --machine "$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//'), $(nproc) cores; load average $load_before before, $load_after after" \
  --command "scripts/make_performance_report.sh (REPEATS=$REPEATS, T_END=$T_END, STIFF_T_END=$STIFF_T_END)" \
  "$OUT/explorer1" "$OUT/explorer1_rigid" "$OUT/stiff"
echo "wrote docs/performance.md and docs/img/perf_*.png"

#!/usr/bin/env bash
# Installs what is missing (scripts/install_deps.sh demo), builds the CLI
# only (scripts/build.sh --demo), simulates explorer1_rigid (minor-axis spin
# turning into major-axis spin through damping in the antenna hinges) and
# writes its plots to out/explorer1_rigid/. The default engine (auto) runs
# the model's generated code when it is cached; on a first run it starts on
# the generic engine while the generated code is built in the background.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh demo
bash scripts/build.sh --demo
mkdir -p out/explorer1_rigid
./build/bin/kanegen check models/explorer1_rigid.yaml
./build/bin/kanegen simulate models/explorer1_rigid.yaml --t-end 3000 --dt-out 0.1 \
  -o out/explorer1_rigid/explorer1_rigid.csv
/usr/bin/python3 scripts/plot_simulation.py out/explorer1_rigid/explorer1_rigid.csv \
  --model models/explorer1_rigid.yaml -o out/explorer1_rigid

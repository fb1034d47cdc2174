#!/usr/bin/env bash
# Installs what is missing (scripts/install_deps.sh), builds the CLI only
# (scripts/build.sh --demo), simulates explorer1_rigid (minor-axis spin
# turning into major-axis spin through damping in the antenna hinges) and
# writes its plots and its 3D view (plot_simulation.py runs kanegen view:
# explorer1_rigid_view.html, open it in a browser) to out/explorer1_rigid/. The default engine (auto) runs
# the model's generated code when it is cached; on a first run it starts on
# the generic engine while the generated code is built in the background.
# The plots' packages (numpy, matplotlib) install while the CLI compiles.
set -euo pipefail
cd "$(dirname "$0")/.."
mkdir -p out/explorer1_rigid
bash scripts/install_deps.sh demo-build
plot_install=""
if [[ $(id -u) -eq 0 ]] || sudo -n true 2>/dev/null; then
  bash scripts/install_deps.sh demo-plot >out/install_plot_packages.log 2>&1 &
  plot_install=$!
else
  bash scripts/install_deps.sh demo-plot  # sudo may ask for a password: not in the background
fi
bash scripts/build.sh --demo
./build/bin/kanegen check models/explorer1_rigid.yaml
./build/bin/kanegen simulate models/explorer1_rigid.yaml --t-end 3000 --dt-out 0.1 \
  -o out/explorer1_rigid/explorer1_rigid.csv
if [[ -n $plot_install ]] && ! wait "$plot_install"; then
  cat out/install_plot_packages.log >&2
  echo "demo.sh: installing the plots' packages failed (out/install_plot_packages.log)" >&2
  exit 1
fi
/usr/bin/python3 scripts/plot_simulation.py out/explorer1_rigid/explorer1_rigid.csv \
  --model models/explorer1_rigid.yaml -o out/explorer1_rigid

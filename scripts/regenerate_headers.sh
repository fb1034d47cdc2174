#!/usr/bin/env bash
# Regenerates generated/<model>.hpp for every model in models/ (the headers
# are committed; tests/test_generated_headers.cpp checks they are current).
set -euo pipefail
cd "$(dirname "$0")/.."
KANEGEN=${KANEGEN:-./build/bin/kanegen}
mkdir -p generated
find models -name '*.yaml' ! -name '*.modal.yaml' ! -path 'models/spinup/*' | sort | while read -r m; do
  name=$(basename "$m" .yaml)
  "$KANEGEN" generate "$m" -o "generated/$name.hpp"
done

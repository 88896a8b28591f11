#!/usr/bin/env bash
# Sets up (idempotent), builds and runs the main job: the default foam bar's statics.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
./build/shapectl statics scenes/foam_bar_clamped.json --out build/foam_bar_result.json --vtu build/foam_bar.vtu
echo "wrote build/foam_bar_result.json and build/foam_bar.vtu"

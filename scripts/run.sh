#!/usr/bin/env bash
# Sets up (idempotent), builds and runs the main job: the browser GUI with the default YuMi +
# foam bar scene and a simulated robot. Open the printed address; Ctrl-C stops it.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh shapectl_cli  # the CLI and its libraries only: no tests, no benchmarks
exec ./build/shapectl serve scenes/yumi_bar.json --robot sim --port "${SHAPECTL_PORT:-8080}"

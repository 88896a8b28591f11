#!/usr/bin/env bash
# Sets up (idempotent), builds and runs every test: GoogleTest through CTest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cd build
ctest --output-on-failure -j "$(nproc)" --timeout 900

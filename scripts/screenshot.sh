#!/usr/bin/env bash
# Sets up (idempotent), builds and regenerates docs/gui.png, the README's screenshot.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
SHAPECTL_CLI="$PWD/build/shapectl" SHAPECTL_SOURCE_DIR="$PWD" node scripts/screenshot.mjs

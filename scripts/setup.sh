#!/usr/bin/env bash
# Installs what shapectl needs from Debian 12 and builds it in ./build (Release).
# Idempotent: packages already present are not touched, the build is incremental.
# Arguments name the targets to build (scripts/run.sh: shapectl_cli); none builds everything.
# The configuration is the same either way (tests and benchmarks on), so a later full build in
# ./build picks up where a partial one stopped.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  build-essential cmake pkg-config
  libeigen3-dev libsuitesparse-dev libopenblas-dev libtbb-dev
  liburdfdom-dev libtinyxml-dev liborocos-kdl-dev libtet1.5-dev
  nlohmann-json3-dev libcli11-dev liblbfgspp-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libboost-dev chromium
  libprotobuf-dev protobuf-compiler
  libpng-dev  # calib/'s depth images (16-bit PNG)
  clang-format
  qemu-user  # portable_install runs the installed tree on an emulated CPU without AVX
  pybind11-dev python3-dev python3-numpy python3-pytest
  python3-matplotlib python3-dask python3-distributed python3-tqdm
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  sudo_cmd=""
  [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
  echo "setup: installing ${missing[*]}"
  $sudo_cmd apt-get update -q
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

# Node.js and npm by command, not by Debian package: a machine may carry another build of
# Node.js (NodeSource's bundles npm and conflicts with Debian's npm package).
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  sudo_cmd=""
  [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
  echo "setup: installing nodejs npm"
  $sudo_cmd apt-get update -q
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -q --no-install-recommends nodejs npm
fi

# ---- web: the browser GUI's packages (three.js, playwright-core) from web/package-lock.json ----
# Before CMake configures: it registers the browser tests only when node and these are present.
# npm ci only when the lock file changed since the last install (stamp inside node_modules).
lock_sum="$(sha256sum web/package-lock.json | cut -d' ' -f1)"
if [ "$(cat web/node_modules/.shapectl-lock-sha256 2>/dev/null)" != "$lock_sum" ]; then
  echo "setup: npm ci in web/"
  (cd web && npm ci --no-audit --no-fund)
  echo "$lock_sum" > web/node_modules/.shapectl-lock-sha256
fi

# CMake's progress lines are dropped; its warnings and errors are shown.
if ! configure_log=$(cmake -S . -B build -DCMAKE_BUILD_TYPE=Release \
                     -DSHAPECTL_BUILD_TESTS=ON -DSHAPECTL_BUILD_BENCHMARKS=ON 2>&1); then
  echo "$configure_log" >&2
  exit 1
fi
grep -v -e '^-- ' -e '^$' <<<"$configure_log" >&2 || true
targets=()
if [ $# -gt 0 ]; then targets=(--target "$@"); fi
cmake --build build -j "$(nproc)" "${targets[@]}"

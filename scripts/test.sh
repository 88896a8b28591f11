#!/usr/bin/env bash
# Sets up (idempotent), builds and runs every test: GoogleTest through CTest. First the
# ThreadSanitizer tree of the concurrency tests (build-tsan, cmake/tsan.cmake; stops here on a
# report), then the whole suite in ./build, whose CTest summary is the last thing printed.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh

# CMake's progress lines are dropped; its warnings and errors are shown.
if ! configure_log=$(cmake -S . -B build-tsan -DSHAPECTL_TSAN=ON -DSHAPECTL_BUILD_TESTS=ON \
                     -DSHAPECTL_BUILD_BENCHMARKS=OFF -DSHAPECTL_BUILD_PYTHON=OFF \
                     -DSHAPECTL_WEB_TESTS=OFF 2>&1); then
  echo "$configure_log" >&2
  exit 1
fi
grep -v -e '^-- ' -e '^$' <<<"$configure_log" >&2 || true
cmake --build build-tsan -j "$(nproc)" --target tsan_tests
(cd build-tsan && ctest -L tsan --output-on-failure -j "$(nproc)" --timeout 900)

cd build
ctest --output-on-failure -j "$(nproc)" --timeout 900

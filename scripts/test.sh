#!/usr/bin/env bash
# Set-up, build, and all tests: the Release build's CTest suite (unit, accuracy, integration
# against the real server, deployment checks), then the unit tests and the server's integration
# tests again under AddressSanitizer + UndefinedBehaviorSanitizer (Debug). Non-zero exit on any
# failure.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs="$(nproc)"

scripts/setup.sh --tests
scripts/build.sh -DNIDEVO_BUILD_TESTS=ON

echo "== tests (Release)"
ctest --test-dir build --output-on-failure -j "$jobs"

if [ "${NIDEVO_SKIP_SANITIZERS:-0}" != "1" ]; then
  echo "== unit tests under ASan + UBSan (Debug)"
  cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=Debug -DNIDEVO_SANITIZE=ON \
    -DNIDEVO_BUILD_BENCHMARKS=OFF >/dev/null
  cmake --build build-asan -j "$jobs" --target nidevo_unit_tests nidevo_service_unit_tests \
    nidevo_integration_tests nidevo-server
  # The server's own tests (sessions, limits, drain) under the sanitizers; the client-tool tests
  # render full-size sequences, too slow at -O0, and run in the Release pass only.
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
    ctest --test-dir build-asan --output-on-failure -j "$jobs" -L unit
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
    ctest --test-dir build-asan --output-on-failure -j 1 -L integration -R "Service|Metrics"
fi

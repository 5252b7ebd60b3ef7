#!/usr/bin/env bash
# Set-up, build, and all tests: the Release build's CTest suite, then the unit tests again under
# AddressSanitizer + UndefinedBehaviorSanitizer (Debug). Non-zero exit on any failure.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs="$(nproc)"

scripts/setup.sh
scripts/build.sh -DNIDEVO_BUILD_TESTS=ON

echo "== tests (Release)"
ctest --test-dir build --output-on-failure -j "$jobs"

if [ "${NIDEVO_SKIP_SANITIZERS:-0}" != "1" ]; then
  echo "== unit tests under ASan + UBSan (Debug)"
  cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=Debug -DNIDEVO_SANITIZE=ON \
    -DNIDEVO_BUILD_BENCHMARKS=OFF >/dev/null
  cmake --build build-asan -j "$jobs" --target nidevo_unit_tests
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
    ctest --test-dir build-asan --output-on-failure -j "$jobs" -L unit
fi

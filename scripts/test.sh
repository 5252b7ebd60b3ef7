#!/usr/bin/env bash
# Set-up, build, and all tests: the Release build's CTest suite (unit, accuracy, integration
# against the real server, deployment checks), then the unit tests under AddressSanitizer +
# UndefinedBehaviorSanitizer (Debug) and the server's integration tests against a sanitizer build
# of nidevo-server; the threaded tests (worker pool, frame pipeline, offline three-thread
# pipeline) under ThreadSanitizer; and each libFuzzer target for a few seconds on its corpus
# (scripts/fuzz.sh; NIDEVO_FUZZ_SECONDS, default 5). Non-zero exit on any failure.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs="$(nproc)"

scripts/setup.sh --tests --bench
scripts/build.sh -DNIDEVO_BUILD_TESTS=ON

echo "== tests (Release)"
ctest --test-dir build --output-on-failure -j "$jobs"

if [ "${NIDEVO_SKIP_SANITIZERS:-0}" != "1" ]; then
  echo "== unit tests under ASan + UBSan (Debug)"
  cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=Debug -DNIDEVO_SANITIZE=ON \
    -DNIDEVO_BUILD_BENCHMARKS=OFF >/dev/null
  cmake --build build-asan -j "$jobs" --target nidevo_unit_tests nidevo_service_unit_tests \
    nidevo-server
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1
  ctest --test-dir build-asan --output-on-failure -j "$jobs" -L unit
  echo "== the server's integration tests against the ASan + UBSan server"
  # The Release test client drives the sanitizer server: sessions, limits, drain, metrics.
  NIDEVO_TEST_SERVER_BINARY="$PWD/build-asan/bin/nidevo-server" \
    ctest --test-dir build --output-on-failure -j 1 -L integration -R "Service|Metrics"

  echo "== the threaded tests under ThreadSanitizer"
  cmake -S . -B build-tsan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DNIDEVO_SANITIZE_THREAD=ON \
    -DNIDEVO_BUILD_BENCHMARKS=OFF >/dev/null
  cmake --build build-tsan -j "$jobs" --target nidevo_thread_tests
  TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1" \
    ctest --test-dir build-tsan --output-on-failure -j "$jobs" -L thread

  echo "== every fuzz target briefly on its corpus"
  scripts/fuzz.sh "${NIDEVO_FUZZ_SECONDS:-5}"
fi

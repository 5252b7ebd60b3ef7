#!/usr/bin/env bash
# Set-up, build, and all tests: the Release build's CTest suite (unit, accuracy, integration
# against the real server, deployment checks); then one clang build with AddressSanitizer +
# UndefinedBehaviorSanitizer and libFuzzer's coverage (Debug, build-asan/) that runs the unit
# tests, drives the server's integration tests against its nidevo-server, and runs each libFuzzer
# target for a few seconds on its corpus (scripts/fuzz.sh; NIDEVO_FUZZ_SECONDS, default 5); and
# the threaded tests (worker pool, frame pipeline, offline three-thread pipeline) under
# ThreadSanitizer. One sanitizer build instead of two keeps CI near half an hour on two cores.
# NIDEVO_SKIP_SANITIZERS=1 runs the Release suite only. Non-zero exit on any failure.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs="$(nproc)"

if [ "${NIDEVO_SKIP_SANITIZERS:-0}" != "1" ]; then
  scripts/setup.sh --tests --bench --fuzz
else
  scripts/setup.sh --tests --bench
fi
scripts/build.sh -DNIDEVO_BUILD_TESTS=ON

echo "== tests (Release)"
ctest --test-dir build --output-on-failure -j "$jobs"

if [ "${NIDEVO_SKIP_SANITIZERS:-0}" != "1" ]; then
  echo "== unit tests under ASan + UBSan (clang, Debug, with the fuzz targets)"
  cmake -S . -B build-asan -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=Debug \
    -DCMAKE_CXX_FLAGS_DEBUG="-g -O1" -DNIDEVO_SANITIZE=ON -DNIDEVO_BUILD_FUZZERS=ON \
    -DNIDEVO_BUILD_BENCHMARKS=OFF >/dev/null
  cmake --build build-asan -j "$jobs" --target nidevo_unit_tests nidevo_service_unit_tests \
    nidevo-server
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1
  ctest --test-dir build-asan --output-on-failure -j "$jobs" -L unit
  echo "== the server's integration tests against the ASan + UBSan server"
  # The Release test client drives the sanitizer server: sessions, limits, drain, metrics.
  NIDEVO_TEST_SERVER_BINARY="$PWD/build-asan/bin/nidevo-server" \
    ctest --test-dir build --output-on-failure -j 1 -L integration -R "Service|Metrics"

  echo "== every fuzz target briefly on its corpus (in the same sanitizer build)"
  NIDEVO_FUZZ_BUILD_DIR=build-asan scripts/fuzz.sh "${NIDEVO_FUZZ_SECONDS:-5}"

  echo "== the threaded tests under ThreadSanitizer"
  cmake -S . -B build-tsan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DNIDEVO_SANITIZE_THREAD=ON \
    -DNIDEVO_BUILD_BENCHMARKS=OFF >/dev/null
  cmake --build build-tsan -j "$jobs" --target nidevo_thread_tests
  TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1" \
    ctest --test-dir build-tsan --output-on-failure -j "$jobs" -L thread
fi

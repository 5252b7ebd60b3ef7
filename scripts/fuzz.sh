#!/usr/bin/env bash
# Builds the libFuzzer targets (clang, ASan + UBSan, in build-fuzz/) and runs each for the given
# seconds on its corpus: the committed seeds in tests/fuzz/corpus/<target> (found crashes among
# them, as regressions) plus what earlier runs added in build-fuzz/corpus/<target>. Prints the
# executions per target; exits non-zero on any crash, leak, sanitizer report or failed check,
# with the input saved as build-fuzz/artifacts/<target>-crash-*.
# Usage: scripts/fuzz.sh [SECONDS_PER_TARGET (default 60)] [TARGET...]
#   targets: camera_file file_list trajectory session_config frame_decode frame_pipeline
# Environment: NIDEVO_FUZZ_RUNS=N stops each target after N executions instead (the seconds
# then only bound the time); NIDEVO_FUZZ_MAX_LEN=N caps the input size (libFuzzer's -max_len).
# Each target's line is also appended to build-fuzz/history.txt with the date.
# NIDEVO_FUZZ_BUILD_DIR=DIR uses an already configured build with -DNIDEVO_BUILD_FUZZERS=ON
# (the test command's Debug sanitizer build) instead of configuring build-fuzz/ (RelWithDebInfo,
# for long runs); corpora, logs and artifacts then go under DIR.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
shift || true
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  targets=(camera_file file_list trajectory session_config frame_decode frame_pipeline)
fi
case "$seconds" in '' | *[!0-9]*) echo "fuzz.sh: SECONDS must be a whole number, got '$seconds'" >&2; exit 2 ;; esac

scripts/setup.sh --fuzz
out="${NIDEVO_FUZZ_BUILD_DIR:-build-fuzz}"
if [ -n "${NIDEVO_FUZZ_BUILD_DIR:-}" ]; then
  grep -q '^NIDEVO_BUILD_FUZZERS:BOOL=ON' "$out/CMakeCache.txt" 2>/dev/null || {
    echo "fuzz.sh: NIDEVO_FUZZ_BUILD_DIR=$out is not a build configured with -DNIDEVO_BUILD_FUZZERS=ON" >&2
    exit 2
  }
else
  cmake -S . -B "$out" -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DNIDEVO_BUILD_FUZZERS=ON -DNIDEVO_BUILD_TESTS=OFF -DNIDEVO_BUILD_BENCHMARKS=OFF >/dev/null
fi
cmake --build "$out" -j "$(nproc)" --target "${targets[@]/#/nidevo_fuzz_}"

mkdir -p "$out/artifacts"
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1
status=0
summary="$(mktemp)"
printf '%-16s %8s %12s %10s\n' target seconds executions exec/s > "$summary"
for t in "${targets[@]}"; do
  seeds="tests/fuzz/corpus/$t"
  work="$out/corpus/$t"
  [ -d "$seeds" ] || { echo "fuzz.sh: unknown target '$t' (no $seeds)" >&2; exit 2; }
  mkdir -p "$work"
  log="$out/$t.log"
  echo "== fuzzing $t for ${seconds}s"
  start=$SECONDS
  if ! "$out/bin/nidevo_fuzz_$t" -max_total_time="$seconds" -runs="${NIDEVO_FUZZ_RUNS:--1}" \
      -print_final_stats=1 ${NIDEVO_FUZZ_MAX_LEN:+-max_len=$NIDEVO_FUZZ_MAX_LEN} \
      -timeout=30 -rss_limit_mb=4096 -artifact_prefix="$out/artifacts/$t-" \
      "$work" "$seeds" >"$log" 2>&1; then
    echo "fuzz.sh: $t FAILED; the input is in $out/artifacts/, the log in $log:" >&2
    grep -E "ERROR|SUMMARY|fuzz check|runtime error|Test unit written" "$log" | head -20 >&2
    status=1
  fi
  execs="$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)"
  execs="${execs:-0}"
  took=$((SECONDS - start))
  line="$(printf '%-16s %8s %12s %10s' "$t" "$took" "$execs" "$((execs / (took > 0 ? took : 1)))")"
  echo "$line" >> "$summary"
  echo "$(date -u +%FT%TZ) $line max_len=${NIDEVO_FUZZ_MAX_LEN:-default}" >> "$out/history.txt"
done
cat "$summary"
rm -f "$summary"
exit $status

#!/usr/bin/env bash
# The randomized stress suite: renders sequences 0..COUNT-1 (nidevo-synth --stress K) into
# build/stress/ once (two at a time; kept and reused), then runs nidevo-bench on all of them and,
# with --with-real, on the real clip too, and on the clip two and three times as fast (every 2nd
# and 3rd frame). Results: build/stress/results.{csv,json}, real_x2.csv, real_x3.csv, log.txt.
# Usage: scripts/stress_suite.sh [COUNT=20] [--methods LIST] [--with-real]
# (Build first: scripts/build.sh; with the peers: scripts/setup.sh --bench.)
set -euo pipefail
cd "$(dirname "$0")/.."
count=20
methods=()
datasets=()
while [ $# -gt 0 ]; do
  case "$1" in
    --methods) methods=(--methods "$2"); shift ;;
    --with-real) datasets+=(../shared/data/tum_fr1_rpy_first250) ;;
    [0-9]*) count="$1" ;;
    *) echo "stress_suite.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
  shift
done
out=build/stress
mkdir -p "$out"
start=$(date +%s)
render() {
  local k dir
  k=$1
  dir=$(printf '%s/stress_%02d' "$out" "$k")
  [ -f "$dir/groundtruth.txt" ] && return 0
  rm -rf "$dir.tmp"
  build/bin/nidevo-synth --stress "$k" --out "$dir.tmp" >"$dir.log" && mv "$dir.tmp" "$dir"
}
export -f render
export out
seq 0 $((count - 1)) | xargs -P 2 -I{} bash -c 'render {}'
rendered=$(date +%s)
echo "stress_suite: $count sequences ready in $((rendered - start)) s"
for k in $(seq 0 $((count - 1))); do datasets+=("$(printf '%s/stress_%02d' "$out" "$k")"); done
list=$(IFS=,; echo "${datasets[*]}")
build/bin/nidevo-bench --scenes "" --datasets "$list" "${methods[@]}" \
  --csv "$out/results.csv" --json "$out/results.json" | tee "$out/log.txt"
if [ ${#datasets[@]} -gt $count ]; then
  # The real clip two and three times as fast (every 2nd and 3rd frame), with the same methods.
  for step in 2 3; do
    build/bin/nidevo-bench --scenes "" --datasets "${datasets[0]}" --frame_step "$step" \
      "${methods[@]}" --csv "$out/real_x$step.csv" | tee -a "$out/log.txt"
  done
fi
echo "stress_suite: benchmark took $(($(date +%s) - rendered)) s"

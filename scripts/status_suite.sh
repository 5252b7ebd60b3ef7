#!/usr/bin/env bash
# Runs nidevo-run on the stress suite's sequences (build/stress/stress_*, rendered by
# scripts/stress_suite.sh) and on the real clip, one per-frame CSV each, then prints per sequence
# the ATE, the OK share and the silent failures, and the per-status error table over the suite
# and over the real clip (as recorded, and every 2nd and 3rd frame: two and three times as
# fast; and all three played backwards, scripts/reverse_tum.py), and the pose check's reported
# spread against the error (scripts/sigma_table.py). Extra arguments go to nidevo-run (e.g.
# --align_photometric_weight 0).
# Usage: scripts/status_suite.sh [nidevo-run flags...]   (NIDEVO_STATUS_OUT: CSV folder,
# default build/status; NIDEVO_STATUS_SUITE: the sequences' folder, default build/stress;
# NIDEVO_STATUS_BIN: the folder of the nidevo-run to measure, default build/bin, e.g. an older
# build's for an A/B of the same suite)
set -euo pipefail
cd "$(dirname "$0")/.."
out=${NIDEVO_STATUS_OUT:-build/status}
suite_dir=${NIDEVO_STATUS_SUITE:-build/stress}
mkdir -p "$out"
real=../shared/data/tum_fr1_rpy_first250
printf '%-12s %8s %8s %7s\n' sequence "ATE m" "OK" silent
run() {  # name, nidevo-run arguments...
  local name=$1
  shift
  "${NIDEVO_STATUS_BIN:-build/bin}/nidevo-run" "$@" --frames_csv "$out/$name.csv" >"$out/$name.txt"
  local ate ok frames silent
  ate=$(grep -m1 rmse "$out/$name.txt" | awk '{print $2}')
  ok=$(awk -F, 'NR>1 && $3=="OK"' "$out/$name.csv" | wc -l)
  frames=$(($(wc -l <"$out/$name.csv") - 1))
  silent=$(grep '^silent failures' "$out/$name.txt" | sed 's/.*: \([0-9]*\) of.*/\1/')
  printf '%-12s %8.4f %7.1f%% %7s\n' "$name" "$ate" "$(echo "100 * $ok / $frames" | bc -l)" "$silent"
}
suite=()
for dir in "$suite_dir"/stress_*/; do
  name=$(basename "$dir")
  run "$name" --dataset "$dir" "$@"
  suite+=("$out/$name.csv")
done
if [ -d "$real" ]; then
  run tum_fr1_rpy --dataset "$real" --camera tum_fr1 "$@"
  # The same recording two and three times as fast: every 2nd and 3rd frame.
  run tum_fr1_rpy_x2 --dataset "$real" --camera tum_fr1 --frame_step 2 "$@"
  run tum_fr1_rpy_x3 --dataset "$real" --camera tum_fr1 --frame_step 3 "$@"
  # The same recording played backwards (scripts/reverse_tum.py), at the three speeds.
  reversed=build/tum_fr1_rpy_reversed
  python3 scripts/reverse_tum.py "$real" "$reversed"
  for step in 1 2 3; do
    run "tum_fr1_rpy_reversed_x$step" --dataset "$reversed" --camera tum_fr1 --frame_step "$step" "$@"
  done
fi
if [ ${#suite[@]} -gt 0 ]; then
  echo; echo "stress suite (${#suite[@]} sequences):"; python3 scripts/status_table.py "${suite[@]}"
  echo; echo "stress suite, spread against error:"; python3 scripts/sigma_table.py "${suite[@]}"
fi
if [ -d "$real" ]; then
  echo; echo "real clip:"; python3 scripts/status_table.py "$out/tum_fr1_rpy.csv"
  echo; echo "real clip, spread against error:"; python3 scripts/sigma_table.py "$out/tum_fr1_rpy.csv"
  echo; echo "real clip, two and three times as fast:"
  python3 scripts/status_table.py "$out/tum_fr1_rpy_x2.csv" "$out/tum_fr1_rpy_x3.csv"
  echo; echo "real clip backwards, as recorded and two and three times as fast:"
  python3 scripts/status_table.py "$out"/tum_fr1_rpy_reversed_x{1,2,3}.csv
fi

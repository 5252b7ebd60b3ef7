#!/usr/bin/env bash
# How far the FFT's rounding moves one sequence's figures: runs nidevo-run once with this host's
# FFTW_ESTIMATE plan and RUNS times with --fft_measure (each process times the candidate
# algorithms and may pick another), then prints per sequence the range of the ATE, the OK count
# and the silent failures. A change measured on one sequence is only a change when it leaves
# this range (docs/accuracy.md, "How far the FFT's rounding moves the figures").
# Usage: scripts/fft_spread.sh [RUNS=6] [nidevo-run flags...]
# NIDEVO_SPREAD_DATASETS: comma-separated DIR or DIR:STEP (default: the real clip as recorded,
# two and three times as fast, and the same played backwards); NIDEVO_SPREAD_BIN: the folder of
# the nidevo-run to measure (default build/bin).
set -euo pipefail
cd "$(dirname "$0")/.."
runs=6
if [ $# -gt 0 ] && [[ "$1" =~ ^[0-9]+$ ]]; then
  runs=$1
  shift
fi
bin=${NIDEVO_SPREAD_BIN:-build/bin}/nidevo-run
[ -x "$bin" ] || { echo "fft_spread.sh: $bin not found (build first: scripts/build.sh)" >&2; exit 2; }
real=../shared/data/tum_fr1_rpy_first250
datasets=${NIDEVO_SPREAD_DATASETS:-}
if [ -z "$datasets" ]; then
  [ -d "$real" ] || { echo "fft_spread.sh: $real not found; set NIDEVO_SPREAD_DATASETS" >&2; exit 2; }
  reversed=build/tum_fr1_rpy_reversed
  python3 scripts/reverse_tum.py "$real" "$reversed" >/dev/null
  datasets="$real:1,$real:2,$real:3,$reversed:1,$reversed:2,$reversed:3"
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# One run's figures as "ATE OK SILENT" (NA for the ATE and SILENT without ground truth).
figures() {
  awk '/^tracking:/ {ok=$2}
       /^APE/ {ape=1} ape && $1=="rmse" {ate=$2; ape=0}
       /^silent failures/ {split($0, a, ": "); split(a[2], b, " "); silent=b[1]}
       END {printf "%s %s %s\n", ate == "" ? "NA" : ate, ok, silent == "" ? "NA" : silent}' "$1"
}
printf '%-32s %5s %-27s %-9s %-9s %s\n' sequence runs "ATE m: min median max" "OK" silent \
  "ESTIMATE: ATE OK silent"
rows="$work/rows.txt"
IFS=, read -ra entries <<<"$datasets"
for entry in "${entries[@]}"; do
  dir=${entry%:*}
  step=1
  [ "$dir" != "$entry" ] && step=${entry##*:}
  [ -d "$dir" ] || { echo "fft_spread.sh: $dir not found" >&2; exit 2; }
  : >"$rows"
  for i in $(seq 0 "$runs"); do
    plan=()
    [ "$i" -gt 0 ] && plan=(--fft_measure)
    "$bin" --dataset "$dir" --frame_step "$step" "${plan[@]}" "$@" >"$work/run.txt" 2>&1 || {
      echo "fft_spread.sh: nidevo-run failed on $dir:" >&2
      tail -n 5 "$work/run.txt" >&2
      exit 1
    }
    figures "$work/run.txt" >>"$rows"
  done
  python3 - "$rows" "$(basename "$dir") x$step" <<'EOF'
import statistics, sys
rows = [line.split() for line in open(sys.argv[1]) if line.strip()]
ate = [float(r[0]) for r in rows if r[0] != "NA"]
ok = [int(r[1]) for r in rows]
silent = [int(r[2]) for r in rows if r[2] != "NA"]
first = rows[0]
span = (f"{min(ate):.4f} {statistics.median(ate):.4f} {max(ate):.4f}" if ate else "no ground truth")
print(f"{sys.argv[2]:<32} {len(rows):5d} {span:<27} {f'{min(ok)}-{max(ok)}':<9} "
      f"{(f'{min(silent)}-{max(silent)}' if silent else 'NA'):<9} {' '.join(first)}")
EOF
done

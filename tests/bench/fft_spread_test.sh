#!/usr/bin/env bash
# scripts/fft_spread.sh on a short rendered sequence: one ESTIMATE run and one --fft_measure run
# give one row whose ATE range, OK range and ESTIMATE figures agree with nidevo-run's own output;
# a missing folder is an error that names it.
# Usage: fft_spread_test.sh <bin dir> <work dir>
set -euo pipefail
bin="$1"
work="$2"
rm -rf "$work"
mkdir -p "$work"
"$bin/nidevo-synth" --scene office --frames 12 --out "$work/office" >/dev/null
NIDEVO_SPREAD_BIN="$bin" NIDEVO_SPREAD_DATASETS="$work/office" \
  bash "$(dirname "$0")/../../scripts/fft_spread.sh" 1 | tee "$work/spread.txt"
"$bin/nidevo-run" --dataset "$work/office" >"$work/estimate.txt" 2>&1
python3 - "$work/spread.txt" "$work/estimate.txt" <<'PY'
import re, sys
rows = [l.split() for l in open(sys.argv[1]) if l.startswith("office")]
assert len(rows) == 1, f"expected one row, got {rows}"
row = rows[0]
assert row[1] == "x1" and row[2] == "2", f"expected 2 runs of office x1: {row}"
lo, med, hi = map(float, row[3:6])
assert lo <= med <= hi, row
out = open(sys.argv[2]).read()
ok = int(re.search(r"^tracking: (\d+) OK", out, re.M).group(1))
ate = float(re.search(r"^\s+rmse\s+([0-9.]+)", out, re.M).group(1))  # the first: the ATE's
assert abs(float(row[-3]) - ate) < 1e-6, f"ESTIMATE ATE {row[-3]} against nidevo-run's {ate}"
assert int(row[-2]) == ok, f"ESTIMATE OK {row[-2]} against nidevo-run's {ok}"
assert lo - 5e-5 <= ate <= hi + 5e-5, f"nidevo-run's ATE {ate} outside the range {lo}-{hi}"
okmin, okmax = map(int, row[6].split("-"))
assert okmin <= ok <= okmax, row
print("fft_spread_test: ok")
PY
if NIDEVO_SPREAD_BIN="$bin" NIDEVO_SPREAD_DATASETS="$work/missing" \
  bash "$(dirname "$0")/../../scripts/fft_spread.sh" 1 2>"$work/err.txt"; then
  echo "fft_spread_test: a missing folder was accepted" >&2
  exit 1
fi
grep -q "$work/missing not found" "$work/err.txt"

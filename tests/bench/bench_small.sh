#!/usr/bin/env bash
# A small run of nidevo-bench (two short synthetic sequences and the start of the real clip, if
# present), so that it keeps working; then each method's ATE as the benchmark printed it must
# equal nidevo-eval's on the trajectory the benchmark wrote, for NIDEVO and for each peer the
# build has (so that a peer silently missing from the run fails the test).
# Usage: bench_small.sh <bin dir> <work dir> [real clip folder] [expected methods, ; or , separated]
set -euo pipefail
bin="$1"
work="$2"
clip="${3:-}"
expected="nidevo;${4:-}"
rm -rf "$work"
mkdir -p "$work"
datasets=()
[ -n "$clip" ] && [ -d "$clip" ] && datasets=(--datasets "$clip" --max_frames 15)
"$bin/nidevo-bench" --scenes office/rich/none,corridor/low/icl --frames 15 "${datasets[@]}" \
  --csv "$work/results.csv" --trajectories "$work/trajectories" | tee "$work/log.txt"

# Each CSV row against nidevo-eval on the written trajectory (the tag is the benchmark's).
python3 - "$bin/nidevo-eval" "$work" "$expected" <<'PY'
import csv, re, subprocess, sys
evaluator, work = sys.argv[1], sys.argv[2]
rows = list(csv.DictReader(open(f"{work}/results.csv")))
if not rows:
    sys.exit(f"no results in {work}/results.csv")
missing = {m for m in re.split(r"[;,]", sys.argv[3]) if m} - {r["method"] for r in rows}
if missing:
    sys.exit(f"bench_small: no result of {sorted(missing)}, which this build should have")
bad = 0
for row in rows:
    folder = f"{work}/trajectories/" + re.sub(r"[^A-Za-z0-9]", "_", row["sequence"])
    out = subprocess.run([evaluator, f"{folder}/groundtruth.txt", f"{folder}/{row['method']}.txt",
                          "--max_time_difference", "0.005"], capture_output=True, text=True,
                         check=True).stdout
    ape = out[out.index("APE w.r.t. translation"):]
    rmse = float(re.search(r"rmse\t([0-9.eE+-]+)", ape).group(1))
    if abs(rmse - float(row["ate_rmse_m"])) > 2e-6:
        print(f"{row['sequence']} / {row['method']}: benchmark ATE {row['ate_rmse_m']}, "
              f"nidevo-eval {rmse}", file=sys.stderr)
        bad += 1
print(f"bench_small: {len(rows) - bad} of {len(rows)} ATEs equal nidevo-eval's")
sys.exit(1 if bad else 0)
PY

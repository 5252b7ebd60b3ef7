#!/usr/bin/env bash
# A/B of two nidevo-server binaries under the same load, run alternately round after round (this
# host's speed drifts by tens of percent between hours, so only alternated runs compare): per
# round and binary, the server pinned to CPU 1 with one worker and the load tester on CPU 0
# (PINNED sessions), then the server with 2 workers sharing both CPUs with the tester (SHARED
# sessions); 30 Hz raw frames, 2 s warm-up, 8 s windows. Prints one line per binary, mode and
# session count: p99 and p50 send to answer, the server's CPU ms per tracked frame and its median
# stage time (the odometry's speed in that hour, to read the other figures against).
# Usage: scripts/server_ab.sh OLD_SERVER NEW_SERVER [ROUNDS (3)] [PINNED (4,5)] [SHARED (6,8)]
set -euo pipefail
cd "$(dirname "$0")/.."
[ $# -ge 2 ] || { sed -n 2,9p "$0" >&2; exit 2; }
old=$1 new=$2 rounds=${3:-3} pinned=${4:-4,5} shared=${5:-6,8}
for b in "$old" "$new" build/bin/nidevo-client; do
  [ -x "$b" ] || { echo "server_ab.sh: $b is not an executable" >&2; exit 2; }
done
case "$rounds" in '' | *[!0-9]*) echo "server_ab.sh: ROUNDS must be a whole number" >&2; exit 2 ;; esac
[ "$(nproc)" -ge 2 ] || { echo "server_ab.sh: needs 2 CPUs" >&2; exit 2; }
out=$(mktemp -d)
port=$((50900 + RANDOM % 100))
target="127.0.0.1:$port"
metrics="http://127.0.0.1:$((port + 1000))/metrics"
server=""
stop_server() { [ -n "$server" ] && { kill "$server" 2>/dev/null; wait "$server" 2>/dev/null || true; }; server=""; }
trap stop_server EXIT

measure() {  # measure LABEL MODE SERVER
  local label=$1 mode=$2 bin=$3 sessions cpus=()
  if [ "$mode" = pinned ]; then
    taskset -c 1 "$bin" --workers 1 --address "$target" --metrics_address "127.0.0.1:$((port + 1000))" \
      >>"$out/server.log" 2>&1 &
    sessions=$pinned cpus=(--cpus 0)
  else
    "$bin" --workers 2 --address "$target" --metrics_address "127.0.0.1:$((port + 1000))" \
      >>"$out/server.log" 2>&1 &
    sessions=$shared
  fi
  server=$!
  for _ in $(seq 50); do
    build/bin/nidevo-client health --target "$target" >/dev/null 2>&1 && break
    sleep 0.2
  done
  build/bin/nidevo-client load --target "$target" --metrics_url "$metrics" --encoding raw "${cpus[@]}" \
    --sessions "$sessions" --session_rate 30 --warmup_s 2 --duration_s 8 --csv "$out/step.csv" \
    >"$out/load.txt" 2>&1
  stop_server
  python3 - "$out/step.csv" "$label" "$mode" <<'EOF'
import csv, sys
for r in csv.DictReader(open(sys.argv[1])):
    print(f'{sys.argv[2]:4s} {sys.argv[3]:7s} {int(r["sessions"]):3d}  p99 {1e3*float(r["p99_s"]):7.1f}'
          f'  p50 {1e3*float(r["p50_s"]):6.1f}  cpu/frame {1e3*float(r["server_cpu_s_per_tracked_frame"]):5.2f}'
          f'  stages {1e3*float(r["median_stages_s"]):5.2f}')
EOF
}

echo "binary  mode   sessions, then ms (one line per round)"
for _ in $(seq "$rounds"); do
  for label in old new; do
    bin=$old
    [ "$label" = new ] && bin=$new
    measure "$label" pinned "$bin"
    measure "$label" shared "$bin"
  done
done | sort -s -k2,2 -k3,3n -k1,1

#!/usr/bin/env bash
# Capacity of a local nidevo-server, as issue 14 measures it, in one run on a 2-core machine:
#   1. core: the odometry alone on the load tester's frames (office scene, 640x480), one thread
#      pinned to CPU 1 (nidevo-run), ms per frame;
#   2. pinned: the server on CPU 1 with one worker, the load tester on CPU 0, 30 Hz sessions
#      1..PINNED_MAX: p99 and the server's CPU ms per tracked frame (process_cpu_seconds_total),
#      against the core's ms per frame, and against the server's own stage time (the odometry as
#      it runs in the server, between other sessions' frames: "minus stages" is the path around it);
#   3. unpinned: the server (2 workers) and the load tester sharing both cores, 1..UNPINNED_MAX;
#   4. memory: resident size and heap in use with MEMORY_SESSIONS sessions open (at 5 Hz, so
#      that none waits; NIDEVO_CAPACITY_MEMORY_RATE sets another rate, e.g. 30 for a loaded
#      server whose queues fill), against the idle server: MB per active session.
# Raw frames, 2 s warm-up, SECONDS-long windows. Prints tables; the CSVs go to NIDEVO_CAPACITY_OUT.
# Timing on a shared machine is reported, never judged; the exit code only says the runs worked.
# NIDEVO_CAPACITY_PHASE: the sessions' send phases, random (default: independent cameras) or
# aligned (every session's frame at the same instant, the worst case; the tables before
# 2026-12-03 evening were aligned). NIDEVO_CAPACITY_SERVER: the nidevo-server to measure
# (default build/bin/nidevo-server), e.g. an older build's for an A/B with the same tester.
# Usage: scripts/capacity.sh [SECONDS (8)] [PINNED_MAX (4)] [UNPINNED_MAX (6)] [MEMORY_SESSIONS (8)]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-8}" pinned_max="${2:-4}" unpinned_max="${3:-6}" memory_sessions="${4:-8}"
phase="${NIDEVO_CAPACITY_PHASE:-random}"
memory_rate="${NIDEVO_CAPACITY_MEMORY_RATE:-5}"
server_bin="${NIDEVO_CAPACITY_SERVER:-build/bin/nidevo-server}"
case "$seconds$pinned_max$unpinned_max$memory_sessions$memory_rate" in
  '' | *[!0-9]*)
    echo "capacity.sh: arguments and NIDEVO_CAPACITY_MEMORY_RATE must be whole numbers" >&2
    exit 2
    ;;
esac
for b in nidevo-server nidevo-client nidevo-run; do
  [ -x "build/bin/$b" ] || { echo "capacity.sh: build/bin/$b missing (run scripts/build.sh)" >&2; exit 2; }
done
[ -x "$server_bin" ] || { echo "capacity.sh: $server_bin is not an executable" >&2; exit 2; }
[ "$(nproc)" -ge 2 ] || { echo "capacity.sh: needs 2 CPUs (server on one, tester on the other)" >&2; exit 2; }
out="${NIDEVO_CAPACITY_OUT:-$(mktemp -d)}"
mkdir -p "$out"
port=$((50700 + RANDOM % 200))
metrics_port=$((port + 1000))
target="127.0.0.1:$port"
metrics="http://127.0.0.1:$metrics_port/metrics"
server=""
stop_server() { [ -n "$server" ] && { kill "$server" 2>/dev/null; wait "$server" 2>/dev/null || true; }; server=""; }
trap stop_server EXIT

start_server() {  # start_server PREFIX... (e.g. taskset -c 1), then server flags after --
  "$@" --address "$target" --metrics_address "127.0.0.1:$metrics_port" --max_sessions 512 \
    >>"$out/server.log" 2>&1 &
  server=$!
  for _ in $(seq 50); do
    build/bin/nidevo-client health --target "$target" >/dev/null 2>&1 && return 0
    sleep 0.2
  done
  echo "capacity.sh: the server did not come up (see $out/server.log)" >&2
  exit 1
}

table() {  # table CSV CORE_MS
  python3 - "$1" "$2" <<'EOF'
import csv, sys
core = float(sys.argv[2])
print("sessions  poses/s   p50 ms   p99 ms  dropped  server CPU ms/frame  minus core ms  tester cores"
      "  outside server ms  server ms  stages ms  minus stages ms")
for r in csv.DictReader(open(sys.argv[1])):
    cpu = 1e3 * float(r["server_cpu_s_per_tracked_frame"])
    cores = float(r["tester_cpu_s"]) / float(r["step_s"]) if float(r["step_s"]) else 0
    stages = 1e3 * float(r["median_stages_s"])
    print(f'{int(r["sessions"]):8d} {float(r["poses_per_s"]):8.1f} {1e3*float(r["p50_s"]):8.2f} '
          f'{1e3*float(r["p99_s"]):8.2f} {int(r["dropped"]):8d} {cpu:20.2f} {cpu-core:14.2f} '
          f'{cores:13.2f} {1e3*float(r["median_outside_server_s"]):18.2f} '
          f'{1e3*float(r["median_server_total_s"]):10.2f} {stages:10.2f} {cpu-stages:16.2f}')
EOF
}

echo "== core: nidevo-run on the load tester's frames, pinned to CPU 1"
core_ms="$(taskset -c 1 build/bin/nidevo-run --frames 60 --threads 1 |
  sed -n 's/^odometry: \([0-9]*\) frames in \([0-9.]*\) s.*/\1 \2/p' |
  awk '{printf "%.2f", 1000 * $2 / $1}')"
echo "core: $core_ms ms per frame"

echo "== pinned: server on CPU 1 (1 worker), load tester on CPU 0, 30 Hz sessions"
start_server taskset -c 1 "$server_bin" --workers 1
build/bin/nidevo-client load --target "$target" --metrics_url "$metrics" --encoding raw --cpus 0 \
  --session_phase "$phase" \
  --sessions "$(seq -s, 1 "$pinned_max")" --session_rate 30 --warmup_s 2 --duration_s "$seconds" \
  --csv "$out/pinned.csv" >"$out/pinned.txt"
stop_server
table "$out/pinned.csv" "$core_ms"

echo "== unpinned: server (2 workers) and load tester on both CPUs, 30 Hz sessions"
start_server "$server_bin" --workers 2
build/bin/nidevo-client load --target "$target" --metrics_url "$metrics" --encoding raw \
  --session_phase "$phase" --sessions "$(seq -s, 1 "$unpinned_max")" --session_rate 30 --warmup_s 2 \
  --duration_s "$seconds" --csv "$out/unpinned.csv" >"$out/unpinned.txt"
stop_server
table "$out/unpinned.csv" "$core_ms"

echo "== memory: $memory_sessions sessions open at $memory_rate Hz against the idle server"
scrape() {  # resident and heap bytes
  curl -s "$metrics" | awk '/^process_resident_memory_bytes /{r=$2} /^nidevo_heap_allocated_bytes /{h=$2}
    END {printf "%.0f %.0f\n", r, h}'
}
start_server "$server_bin" --workers 2
sleep 1
read -r idle_rss idle_heap <<<"$(scrape)"
build/bin/nidevo-client load --target "$target" --encoding raw --sessions "$memory_sessions" \
  --session_rate "$memory_rate" --warmup_s 2 --duration_s "$seconds" >"$out/memory.txt" &
tester=$!
sleep $((2 + seconds / 2))
read -r busy_rss busy_heap <<<"$(scrape)"
wait "$tester"
stop_server
python3 - "$memory_sessions" "$idle_rss" "$idle_heap" "$busy_rss" "$busy_heap" <<'EOF'
import sys
n, ir, ih, br, bh = int(sys.argv[1]), *map(float, sys.argv[2:])
mb = 1 / (1 << 20)
print(f"idle: resident {ir*mb:.1f} MB, heap {ih*mb:.1f} MB; {n} sessions: resident {br*mb:.1f} MB, "
      f"heap {bh*mb:.1f} MB")
print(f"per active session: resident {(br-ir)/n*mb:.1f} MB, heap {(bh-ih)/n*mb:.1f} MB")
EOF
echo "CSVs and the load tester's output: $out"

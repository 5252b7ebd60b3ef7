#!/usr/bin/env bash
# Overload run of the load tester against a local nidevo-server: first the server's capacity
# (a sweep of 30 Hz sessions up to far past saturation: the most poses/s of any step), then
# FACTOR times that as 30 Hz sessions for SECONDS, once with LATEST and once with BLOCK. Prints each
# step's table and a verdict: LATEST must answer every frame (tracked or DROPPED), BLOCK must drop
# none, and the accounting must close in both; the latencies are reported, not judged (a shared
# machine's timing is no test). Exit 1 when a verdict fails.
# Usage: scripts/overload.sh [SECONDS (default 60)] [FACTOR (default 3)]
# Environment: NIDEVO_OVERLOAD_ENCODING (default raw), NIDEVO_OVERLOAD_OUT (a folder for the JSON).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
factor="${2:-3}"
case "$seconds$factor" in '' | *[!0-9]*) echo "overload.sh: SECONDS and FACTOR must be whole numbers" >&2; exit 2 ;; esac
for b in nidevo-server nidevo-client; do
  [ -x "build/bin/$b" ] || { echo "overload.sh: build/bin/$b missing (run scripts/build.sh)" >&2; exit 2; }
done
encoding="${NIDEVO_OVERLOAD_ENCODING:-raw}"
out="${NIDEVO_OVERLOAD_OUT:-$(mktemp -d)}"
mkdir -p "$out"
port=$((50200 + RANDOM % 500))
metrics_port=$((port + 1000))
target="127.0.0.1:$port"
metrics="http://127.0.0.1:$metrics_port/metrics"

build/bin/nidevo-server --address "$target" --metrics_address "127.0.0.1:$metrics_port" \
  --max_sessions 512 >"$out/server.log" 2>&1 &
server=$!
trap 'kill "$server" 2>/dev/null; wait "$server" 2>/dev/null || true' EXIT
for _ in $(seq 50); do
  build/bin/nidevo-client health --target "$target" >/dev/null 2>&1 && break
  sleep 0.2
done
workers="$(build/bin/nidevo-client info --target "$target" | sed -n 's/^worker threads *\([0-9][0-9]*\).*/\1/p')"
workers="${workers:-$(nproc)}"

load() {  # load NAME SESSIONS RATE POLICY SECONDS
  local rate="$3 Hz"
  [ "$3" = 0 ] && rate="as fast as the server takes"
  echo "== $1: $2 sessions, $rate per session, $4, $5 s"
  build/bin/nidevo-client load --target "$target" --metrics_url "$metrics" --encoding "$encoding" \
    --sessions "$2" --session_rate "$3" --policy "$4" --warmup_s 2 --duration_s "$5" \
    --json "$out/$1.json" | tail -n +2
}

# Sessions sending as fast as they can are no capacity measure: on a shared machine the sending
# itself takes the CPU the server would track with.
sweep="$(seq -s, "$workers" "$workers" $((8 * workers)))"
load capacity "$sweep" 30 block 4
read -r capacity sessions <<<"$(python3 -c "
import json, math
steps = json.load(open('$out/capacity.json'))
c = max(s['poses_per_s'] for s in steps)
print(c, max(1, math.ceil($factor * c / 30)))")"
echo "capacity: $capacity poses/s (the most of any step); ${factor}x is $sessions sessions at 30 Hz"
load latest "$sessions" 30 latest "$seconds"
load block "$sessions" 30 block "$seconds"

python3 - "$out" <<'EOF'
import json, sys
out = sys.argv[1]
ok = True
for name in ("latest", "block"):
    s = json.load(open(f"{out}/{name}.json"))[0]
    answered = s["ok"] + s["degraded"] + s["lost"] + s["dropped"] + s["error"]
    print(f"{name}: sent {s['sent']}, answered {answered} (dropped {s['dropped']}), "
          f"unanswered {s['unanswered']}, errors {s['error']}, poses/s {s['poses_per_s']:.1f}, "
          f"p50 {1e3 * s['latency_s']['p50']:.1f} ms, p99 {1e3 * s['latency_s']['p99']:.1f} ms, "
          f"sessions ended {s['sessions_ended']}")
    checks = {"accounting closes": s["accounting_closed"], "no errors": s["error"] == 0,
              "every frame answered": s["unanswered"] == 0,
              "every session ended OK": list(s["sessions_ended"]) == ["OK"]}
    if name == "block":
        checks["nothing dropped"] = s["dropped"] == 0
    for what, passed in checks.items():
        if not passed:
            print(f"  FAILED: {name}: {what}")
            ok = False
print("overload verdict:", "passed" if ok else "FAILED", f"(JSON in {out})")
sys.exit(0 if ok else 1)
EOF

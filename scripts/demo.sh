#!/usr/bin/env bash
# The main job on the built-in synthetic sequence, through the service: render the sequence as a
# TUM folder, start nidevo-server on free loopback ports, stream the sequence through it with
# nidevo-client replay (trajectory, frames per second, ATE table and plot), stop the server.
# Environment: NIDEVO_DEMO_SCENE (office), NIDEVO_DEMO_TEXTURE (low), NIDEVO_DEMO_NOISE (icl).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh -DNIDEVO_BUILD_TESTS=OFF -DNIDEVO_BUILD_BENCHMARKS=OFF

out="build/demo"
scene="${NIDEVO_DEMO_SCENE:-office}"
texture="${NIDEVO_DEMO_TEXTURE:-low}"
noise="${NIDEVO_DEMO_NOISE:-icl}"
rm -rf "$out"
mkdir -p "$out"
echo "== 1/3 rendering the synthetic '$scene' sequence ($texture texture, $noise noise, 300 frames)"
build/bin/nidevo-synth --scene "$scene" --texture "$texture" --noise "$noise" --out "$out/sequence"

echo
echo "== 2/3 starting nidevo-server on free loopback ports"
build/bin/nidevo-server --address 127.0.0.1:0 --metrics_address 127.0.0.1:0 \
  --port_file "$out/ports" 2>"$out/server.log" &
server_pid=$!
trap 'kill "$server_pid" 2>/dev/null || true' EXIT
for _ in $(seq 1 300); do
  [ -s "$out/ports" ] && break
  kill -0 "$server_pid" 2>/dev/null || { cat "$out/server.log"; exit 1; }
  sleep 0.1
done
grpc_port="$(awk '$1 == "grpc_port" {print $2}' "$out/ports")"
metrics_port="$(awk '$1 == "metrics_port" {print $2}' "$out/ports")"
cat "$out/server.log"
build/bin/nidevo-client health --target "127.0.0.1:$grpc_port"

echo
echo "== 3/3 streaming the sequence through the server (PNG frames, as fast as the server takes them)"
build/bin/nidevo-client replay --target "127.0.0.1:$grpc_port" --dataset "$out/sequence" \
  --encoding png --out "$out/trajectory.txt" --plot "$out/trajectory.png"
echo
echo "server metrics (http://127.0.0.1:$metrics_port/metrics):"
curl -s "http://127.0.0.1:$metrics_port/metrics" | grep -E '^nidevo_(frames_total|sessions_total\{code="OK"\})'

kill -TERM "$server_pid"
wait "$server_pid"
trap - EXIT
tail -n 2 "$out/server.log"
echo "plot: $out/trajectory.png"

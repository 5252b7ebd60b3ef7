#!/usr/bin/env bash
# The main job on the built-in synthetic sequence: render it, run the odometry, evaluate.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh -DNIDEVO_BUILD_TESTS=OFF -DNIDEVO_BUILD_BENCHMARKS=OFF

out="${NIDEVO_DEMO_DIR:-build/demo}"
scene="${NIDEVO_DEMO_SCENE:-office}"
rm -rf "$out"
mkdir -p "$out"
echo "== rendering the synthetic '$scene' sequence (300 frames, 640x480)"
build/bin/nidevo-synth --scene "$scene" --out "$out/sequence"
echo "== evaluating the ground truth against itself moved rigidly (sanity check of the metrics)"
build/bin/nidevo-eval "$out/sequence/groundtruth.txt" "$out/sequence/groundtruth.txt" \
  --plot "$out/trajectory.png"

#!/usr/bin/env bash
# The main job on the built-in synthetic sequence: render it as a TUM folder, run the odometry
# on it, evaluate the trajectory against the ground truth (table and plot).
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
echo "== 2/3 odometry on the TUM folder"
build/bin/nidevo-run --dataset "$out/sequence" --out "$out/trajectory.txt"
echo
echo "== 3/3 evaluation against the ground truth"
build/bin/nidevo-eval "$out/sequence/groundtruth.txt" "$out/trajectory.txt" --plot "$out/trajectory.png"

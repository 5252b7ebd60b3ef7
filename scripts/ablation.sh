#!/usr/bin/env bash
# Ablation of the odometry's design choices (the paper's Table 3 and ours): ATE RMSE in metres on
# synthetic sequences, one row per variant, as a Markdown table. Builds first if needed.
# Usage: scripts/ablation.sh [frames]   (default 300)
set -euo pipefail
cd "$(dirname "$0")/.."
frames="${1:-300}"
[ -x build/bin/nidevo-run ] || scripts/build.sh >/dev/null
dir=build/ablation
mkdir -p "$dir"

sequences=("office rich none" "office low icl" "corridor low icl")
for s in "${sequences[@]}"; do
  read -r scene texture noise <<<"$s"
  out="$dir/${scene}_${texture}_${noise}_$frames"
  [ -f "$out/groundtruth.txt" ] || build/bin/nidevo-synth --scene "$scene" --texture "$texture" \
    --noise "$noise" --frames "$frames" --out "$out" >/dev/null
done

variants=(
  "defaults|"
  "cell size 1|--cell_size 1"
  "cell size 5|--cell_size 5"
  "normal map at full resolution|--normal_stride 1"
  "rotation: best pair (paper)|--rotation_method best_pair"
  "plane normal: median (paper)|--plane_normal median"
  "rotation: best pair + median (paper)|--rotation_method best_pair --plane_normal median"
  "KCC grey + depth channels|--kcc_depth"
  "KCC Gaussian label of 2 px|--kcc_label_sigma 2"
  "KCC Gaussian label of 2 px, PSR bound 20|--kcc_label_sigma 2 --psr_bound 20"
  "PSR bound 50 (paper)|--psr_bound 50"
  "no outline flattening (empty = 0.5)|--noflatten_outline"
  "no projection gap fill|--fill_gap 0"
  "projection 480x360 from every pixel|--projection_width 480 --projection_height 360 --projection_stride 1"
)

header="| variant |"
rule="|---|"
for s in "${sequences[@]}"; do header="$header ${s// /, } |"; rule="$rule---|"; done
echo "$header"
echo "$rule"
for v in "${variants[@]}"; do
  name="${v%%|*}"
  flags="${v#*|}"
  row="| $name |"
  for s in "${sequences[@]}"; do
    read -r scene texture noise <<<"$s"
    # shellcheck disable=SC2086
    result=$(build/bin/nidevo-run --dataset "$dir/${scene}_${texture}_${noise}_$frames" $flags 2>&1 || true)
    ate=$(echo "$result" | awk '/^APE/{f=1} f && $1=="rmse"{print $2; exit}')
    lost=$(echo "$result" | sed -n 's/^tracking: .* \([0-9]*\) LOST.*/\1/p')
    row="$row ${ate:-failed} (${lost:-?} lost) |"
  done
  echo "$row"
done

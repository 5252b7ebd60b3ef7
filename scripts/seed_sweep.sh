#!/usr/bin/env bash
# ATE RMSE of odometry variants over several seeds (handheld shake and sensor noise) of the
# synthetic sequences: how a choice does on sequences it was not tuned on, not on one of them.
# Renders each sequence once into build/ablation/, then one nidevo-run per variant and sequence.
# Usage: scripts/seed_sweep.sh [seeds] ['name|flags' ...]
#   seeds: how many seeds per sequence (default 8); variants default to the PSR bound sweep below.
set -euo pipefail
cd "$(dirname "$0")/.."
seeds="${1:-8}"
shift || true
[ -x build/bin/nidevo-run ] || scripts/build.sh >/dev/null
dir=build/ablation
mkdir -p "$dir"

sequences=("office low icl" "corridor low icl" "office rich none")
variants=("$@")
if [ ${#variants[@]} -eq 0 ]; then
  variants=("defaults (PSR bound 30)|" "PSR bound 50 (paper)|--psr_bound 50"
            "PSR bound 40|--psr_bound 40" "PSR bound 20|--psr_bound 20")
fi

folder() { echo "$dir/${1}_${2}_${3}_seed${4}_300"; }
render_jobs=()
for s in "${sequences[@]}"; do
  read -r scene texture noise <<<"$s"
  for seed in $(seq 1 "$seeds"); do
    out=$(folder "$scene" "$texture" "$noise" "$seed")
    [ -f "$out/groundtruth.txt" ] || render_jobs+=("$scene $texture $noise $seed $out")
  done
done
# Two renders at a time: each is single-threaded.
if [ ${#render_jobs[@]} -gt 0 ]; then
  printf '%s\n' "${render_jobs[@]}" | xargs -P 2 -L 1 bash -c \
    'build/bin/nidevo-synth --scene $0 --texture $1 --noise $2 --seed $3 --out $4 >/dev/null'
fi

ate_of() {
  # shellcheck disable=SC2086
  build/bin/nidevo-run --dataset "$1" $2 2>&1 | awk '/^APE/{f=1} f && $1=="rmse"{print $2; exit}'
}
echo "| variant | sequence | $(seq -s ' | ' 1 "$seeds" | sed -E 's/[0-9]+/seed &/g') | mean | max |"
echo "|---|---|$(printf -- '---|%.0s' $(seq 1 "$seeds"))---|---|"
for v in "${variants[@]}"; do
  name="${v%%|*}"
  flags="${v#*|}"
  for s in "${sequences[@]}"; do
    read -r scene texture noise <<<"$s"
    values=()
    for seed in $(seq 1 "$seeds"); do
      ate=$(ate_of "$(folder "$scene" "$texture" "$noise" "$seed")" "$flags")
      values+=("${ate:-nan}")
    done
    summary=$(printf '%s\n' "${values[@]}" |
      awk '{s+=$1; if($1>m)m=$1} END{printf "%.4f | %.4f", s/NR, m}')
    echo "| $name | ${s// /, } | $(printf '%.4f | ' "${values[@]}")$summary |"
  done
done

#!/usr/bin/env bash
# Specialized kernel vs the all-features ("uber") kernel for each demo scene:
# samples/s (median of RUNS renders), SPIR-V size, glslang time, and time to
# the first finished frame cold (empty vkrt cache, MESA_SHADER_CACHE_DISABLE)
# and warm. Usage: tools/bench_variants.sh [SCENE...]   env: RUNS (3), SPP (32), SIZE (320x240)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
vkrt=${VKRT:-$root/build/vkrt}
runs=${RUNS:-3}
spp=${SPP:-32}
size=${SIZE:-320x240}
width=${size%x*}
height=${size#*x}
scenes=("$@")
((${#scenes[@]})) || scenes=("$root"/scenes/seed/*.toml)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

field() { awk -v key="$1" -F': *' '$1 == key {print $2}'; }
median() { sort -g | awk '{a[NR] = $1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}'; }
rate() { # samples/s of one render
  "$vkrt" render "$1" -o "$work/out.exr" --spp "$spp" --width "$width" --height "$height" ${2:-} 2>&1 |
    awk '/ spp /{for (i = 1; i <= NF; i++) if ($i ~ /samples\/s$/) { u = $i; sub(/samples\/s/, "", u);
         m = (u == "k") ? 1e3 : (u == "M") ? 1e6 : (u == "G") ? 1e9 : 1; printf "%.0f\n", $(i-1) * m } }'
}
first_frame() { # seconds from set-up start to the first finished frame
  "$vkrt" info "$1" ${2:-} | field "first frame" | awk '{print $1}'
}

printf '%-22s %6s %12s %12s %7s %10s %10s %9s %9s %9s %9s\n' scene kernel "samples/s" "" "ratio" "spirv B" "glslang s" "cold s" "warm s" "" ""
for scene in "${scenes[@]}"; do
  name=$(basename "$scene" .toml)
  for kind in specialized uber; do
    flag=""; [[ $kind == uber ]] && flag="--uber"
    cold_cache="$work/cold-$name-$kind"
    info=$(VKRT_CACHE_DIR="$cold_cache" MESA_SHADER_CACHE_DISABLE=true "$vkrt" info "$scene" $flag)
    spirv=$(field "spirv bytes" <<<"$info")
    glslang=$(field "glslang" <<<"$info" | awk '{print $1}')
    cold=$(field "first frame" <<<"$info" | awk '{print $1}')
    "$vkrt" info "$scene" $flag >/dev/null # fill the caches
    warm=$(for ((i = 0; i < runs; i++)); do first_frame "$scene" "$flag"; done | median)
    rate_median=$(for ((i = 0; i < runs; i++)); do rate "$scene" "$flag"; done | median)
    if [[ $kind == specialized ]]; then base=$rate_median; ratio=1; else ratio=$(awk -v a="$base" -v b="$rate_median" 'BEGIN{printf "%.2f", a / b}'); fi
    printf '%-22s %6s %12s %12s %7s %10s %10s %9s %9s\n' "$name" "${kind:0:6}" "$rate_median" "" "$ratio" "$spirv" "$glslang" "$cold" "$warm"
  done
done
echo "(ratio: specialized samples/s over uber samples/s; $runs runs, $spp spp at $size; cold = empty vkrt cache and MESA_SHADER_CACHE_DISABLE=true)"

#!/usr/bin/env bash
# Prints samples/s of `vkrt render` for a scene at 640x480 (default: the
# default scene): RUNS runs (default 5), each value, then the median.
# Usage: tools/bench.sh [SCENE] [SPP]      env: RUNS, VKRT (path of the binary)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
scene=${1:-$root/scenes/default.toml}
spp=${2:-64}
runs=${RUNS:-5}
vkrt=${VKRT:-$root/build/vkrt}
[[ -x $vkrt ]] || { echo "bench: no vkrt binary at $vkrt (build first: tools/setup.sh render)" >&2; exit 2; }
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

"$vkrt" render "$scene" -o "$out/warm.exr" --spp 1 --width 640 --height 480 >/dev/null 2>&1 # warm the caches
rates=()
for ((i = 1; i <= runs; i++)); do
  start=$(date +%s.%N)
  line=$("$vkrt" render "$scene" -o "$out/b.exr" --spp "$spp" --width 640 --height 480 2>&1 | grep ' spp ')
  end=$(date +%s.%N)
  # "64 spp  3.21 s  6.1 Msamples/s ..." -> samples/s as a plain number
  rate=$(awk '{for (i = 1; i <= NF; i++) if ($i ~ /samples\/s$/) { v = $(i-1); u = $i; sub(/samples\/s/, "", u);
               m = (u == "k") ? 1e3 : (u == "M") ? 1e6 : (u == "G") ? 1e9 : 1; printf "%.0f", v * m } }' <<<"$line")
  rates+=("$rate")
  printf 'run %d: %s samples/s, whole process %.2f s\n' "$i" "$rate" "$(awk -v a="$start" -v b="$end" 'BEGIN{print b - a}')"
done
median=$(printf '%s\n' "${rates[@]}" | sort -n | awk '{a[NR] = $1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}')
echo "scene $(basename "$scene") 640x480 ${spp} spp on $("$vkrt" devices | awk '/^\*/{sub(/^\* [0-9]+: /, ""); print; exit}')"
echo "median: $median samples/s over $runs runs"

#!/usr/bin/env bash
# The render farm's figures (docs/farm.md, "Figures"), printed as Markdown:
#   1. a shard's start-up with a cold and a warm kernel cache (whole process);
#   2. kernel cache hits of 4 array tasks sharing one fresh $VKRT_CACHE_DIR;
#   3. wall time of one process against 1, 2 and 4 shards through a real
#      single-node Slurm (tools/slurm/local-cluster.sh), submit to merged frame;
#   4. `vkrt merge` of 4 shards at 3840x2160 (time, file sizes, peak memory).
# Medians of --repeats runs (default 3), interleaved so that drift on a shared
# machine hits every configuration alike. Needs root (the Slurm cluster) and
# the build in build/ (or $VKRT).
#   tools/bench_farm.sh [--repeats R] [--spp S] [--scene SCENE] [--skip-4k]
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
repeats=3 spp=512 scene=$root/scenes/validation/diffuse-box.toml skip_4k=false
while (($#)); do
  case $1 in
    --repeats) repeats=$2; shift 2 ;;
    --spp) spp=$2; shift 2 ;;
    --scene) scene=$(realpath -e "$2"); shift 2 ;;
    --skip-4k) skip_4k=true; shift ;;
    *) echo "usage: tools/bench_farm.sh [--repeats R] [--spp S] [--scene SCENE] [--skip-4k]" >&2; exit 2 ;;
  esac
done
export VKRT=${VKRT:-$root/build/vkrt}
[[ -x $VKRT ]] || { echo "bench_farm.sh: no vkrt at $VKRT (build first)" >&2; exit 1; }
size=(--width 320 --height 240)

work=$(mktemp -d "${TMPDIR:-/tmp}/vkrt-bench-farm.XXXXXX")
trap '"$root/tools/slurm/local-cluster.sh" stop "$work/cluster" || true; rm -rf "$work"' EXIT

now() { date +%s.%N; }
elapsed() { awk "BEGIN { printf \"%.3f\", $(now) - $1 }"; }
median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
startup_of() { sed -n 's/.*(start-up \([0-9.]*\) s.*/\1/p' "$1"; }

echo "# vkrt farm figures, $(date -u +%Y-%m-%d), $(nproc) cores, $("$VKRT" devices 2>/dev/null | sed -n 's/^[* ]*0: *//p' | head -n 1)"
echo
echo "scene $(realpath --relative-to="$root" "$scene"), ${size[1]}x${size[3]}, medians of $repeats"
echo

# ---- 1. start-up of one shard, cold and warm caches
declare -a cold_wall cold_start warm_wall warm_start
mkdir -p "$work/warm-cache" "$work/warm-mesa"
VKRT_CACHE_DIR=$work/warm-cache MESA_SHADER_CACHE_DIR=$work/warm-mesa \
  "$VKRT" render "$scene" --spp 2 "${size[@]}" -o "$work/prime.exr" 2>/dev/null
for ((r = 0; r < repeats; ++r)); do
  rm -rf "$work/cold-cache" "$work/cold-mesa"
  t=$(now)
  VKRT_CACHE_DIR=$work/cold-cache MESA_SHADER_CACHE_DIR=$work/cold-mesa \
    "$VKRT" render "$scene" --spp 2 --shard 0/1 --variance "${size[@]}" -o "$work/s.exr" 2>"$work/cold.log"
  cold_wall+=("$(elapsed "$t")") cold_start+=("$(startup_of "$work/cold.log")")
  t=$(now)
  VKRT_CACHE_DIR=$work/warm-cache MESA_SHADER_CACHE_DIR=$work/warm-mesa \
    "$VKRT" render "$scene" --spp 2 --shard 0/1 --variance "${size[@]}" -o "$work/s.exr" 2>"$work/warm.log"
  warm_wall+=("$(elapsed "$t")") warm_start+=("$(startup_of "$work/warm.log")")
done
echo "| shard of 2 spp, whole process | wall s | vkrt start-up s |"
echo "|---|---:|---:|"
echo "| cold caches (vkrt SPIR-V and Mesa's) | $(printf '%s\n' "${cold_wall[@]}" | median) | $(printf '%s\n' "${cold_start[@]}" | median) |"
echo "| warm caches | $(printf '%s\n' "${warm_wall[@]}" | median) | $(printf '%s\n' "${warm_start[@]}" | median) |"
echo

# ---- 2. and 3. through Slurm
chmod 0755 "$work" # munged runs as user munge and must reach its socket
exports=$("$root/tools/slurm/local-cluster.sh" start "$work/cluster")
eval "$exports"
submit() { # SHARDS OUT [extra submit.sh options]; prints the wall time
  local shards=$1 out=$2 t
  shift 2
  t=$(now)
  "$root/tools/slurm/submit.sh" "$scene" --shards "$shards" --spp "$spp" --seed 1 --out "$out" --no-check --wait "$@" \
    -- "${size[@]}" >/dev/null 2>&1 || { echo "bench_farm.sh: Slurm run failed, logs in $out/logs" >&2; exit 1; }
  elapsed "$t"
}

rm -rf "$work/shared-cache"
VKRT_CACHE_DIR=$work/shared-cache submit 4 "$work/hits" >/dev/null
compiled=$(grep -l "kernel compiled" "$work"/hits/logs/shard-*.log | wc -l)
cached=$(grep -l "kernel cached" "$work"/hits/logs/shard-*.log | wc -l)
echo "Kernel cache shared by 4 array tasks (fresh \$VKRT_CACHE_DIR, $(nproc) tasks at once): $compiled compiled, $cached cache hits."
echo

declare -A wall
for ((r = 0; r < repeats; ++r)); do
  t=$(now)
  VKRT_CACHE_DIR=$work/warm-cache "$VKRT" render "$scene" --spp "$spp" --seed 1 --variance "${size[@]}" \
    -o "$work/one.exr" 2>/dev/null
  wall[one]+="$(elapsed "$t") "
  for shards in 1 2 4; do
    rm -rf "$work/run-$shards"
    wall[$shards]+="$(VKRT_CACHE_DIR=$work/warm-cache submit "$shards" "$work/run-$shards") "
  done
done
one=$(tr ' ' '\n' <<<"${wall[one]}" | grep . | median)
echo "| $spp spp | wall s (submit to merged frame) | vs one process |"
echo "|---|---:|---:|"
echo "| one process, no Slurm | $one | 1.00x |"
for shards in 1 2 4; do
  m=$(tr ' ' '\n' <<<"${wall[$shards]}" | grep . | median)
  echo "| Slurm, $shards shard(s) + merge | $m | $(awk "BEGIN { printf \"%.2fx\", $m / $one }") |"
done
echo
"$VKRT" compare "$work/run-4/frame.exr" "$work/one.exr" | grep -E 'relMSE|max' | sed 's/^/    4 shards vs one process: /'
echo
"$root/tools/slurm/local-cluster.sh" stop "$work/cluster"

$skip_4k && exit 0
# ---- 4. merging 4K shards
for i in 0 1 2 3; do
  VKRT_CACHE_DIR=$work/warm-cache "$root/tools/farm/shard.sh" "$scene" --index "$i" --shards 4 --spp 8 --out "$work/4k" \
    -- --width 3840 --height 2160 --sampler independent 2>/dev/null
done
declare -a merge_s merge_rss
for ((r = 0; r < repeats; ++r)); do
  /usr/bin/time -f '%e %M' -o "$work/time.txt" "$VKRT" merge "$work"/4k/shard-*-of-4.exr -o "$work/4k/frame.exr" 2>/dev/null
  read -r s kib <"$work/time.txt"
  merge_s+=("$s") merge_rss+=("$kib")
done
shard_mb=$(du -m "$work/4k/shard-0-of-4.exr" | cut -f1)
frame_mb=$(du -m "$work/4k/frame.exr" | cut -f1)
echo "| merge of 4 shards, 3840x2160, independent sampler | |"
echo "|---|---:|"
echo "| wall s | $(printf '%s\n' "${merge_s[@]}" | median) |"
echo "| peak memory MiB | $(($(printf '%s\n' "${merge_rss[@]}" | median | cut -d. -f1) / 1024)) |"
echo "| one shard's EXR MiB (mean, variance, tally layers) | $shard_mb |"
echo "| merged EXR MiB | $frame_mb |"

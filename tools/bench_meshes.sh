#!/usr/bin/env bash
# Mesh benchmark: load time, BVH build time, GPU memory, samples/s and
# Mrays/s against triangle count, on the default driver.
#   tools/bench_meshes.sh [COUNTS...]     (default: 100 1000 10000 100000 1000000)
# env: RUNS (renders per size, default 3: the median is printed), SPP (default 16),
#      VKRT, MAKE_MESH (paths of the binaries), ASSETS (default assets/).
# For each size: a UV sphere of that many triangles (binary PLY) on a box
# floor, lit by a point light, seen at 320x240. "primary" renders use
# max_depth = 1 (one camera ray and at most one shadow ray per sample: Mrays/s
# counts both, as measured by the hit fraction below); "path" renders use the
# path integrator at max_depth 5. Then the same for the real assets.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
vkrt=${VKRT:-$root/build/vkrt}
make_mesh=${MAKE_MESH:-$root/build/vkrt-make-mesh}
assets=${ASSETS:-$root/assets}
runs=${RUNS:-3}
spp=${SPP:-16}
counts=("$@")
((${#counts[@]})) || counts=(100 1000 10000 100000 1000000)
for binary in "$vkrt" "$make_mesh"; do
  [[ -x $binary ]] || { echo "bench_meshes: no binary at $binary (build first)" >&2; exit 2; }
done
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

scene() { # FILE INTEGRATOR DEPTH SCALE -> scene text
  cat <<TOML
[render]
integrator = "$2"
max_depth = $3
[camera]
eye = [0, 0.6, 3.2]
target = [0, 0, 0]
fov = 40
width = 320
height = 240
[materials.clay]
type = "lambert"
albedo = [0.7, 0.6, 0.5]
[[objects]]
shape = "mesh"
file = "$1"
material = "clay"
scale = $4
[[objects]]
shape = "box"
min = [-3, -1.2, -3]
max = [3, -1, 3]
material = "clay"
[[lights]]
type = "point"
position = [2, 3, 2]
intensity = 30
TOML
}

median() { sort -g | awk '{a[NR] = $1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}'; }

# samples/s of one render ("16 spp  0.52 s  2.4 Msamples/s ...").
rate_of() {
  awk '{for (i = 1; i <= NF; i++) if ($i ~ /samples\/s$/) { v = $(i-1); u = $i; sub(/samples\/s/, "", u);
        m = (u == "k") ? 1e3 : (u == "M") ? 1e6 : (u == "G") ? 1e9 : 1; printf "%.0f", v * m } }'
}

measure() { # NAME MESHFILE SCALE
  local name=$1 file=$2 scale=$3
  scene "$file" whitted 1 "$scale" >"$work/primary.toml"
  scene "$file" path 5 "$scale" >"$work/path.toml"
  local info load build nodes memory triangles
  info=$("$vkrt" info "$work/primary.toml")
  triangles=$(awk '/^meshes:/ {print $7}' <<<"$info")
  load=$(awk '/^mesh times:/ {print $4}' <<<"$info")
  build=$(awk '/^mesh times:/ {print $8}' <<<"$info")
  nodes=$(awk '/^bvh:/ {print $2}' <<<"$info")
  memory=$(awk '/^mesh memory:/ {print $3}' <<<"$info")
  local primary=() path=()
  "$vkrt" render "$work/primary.toml" -o "$work/warm.exr" --spp 1 >/dev/null 2>&1
  for ((i = 0; i < runs; i++)); do
    primary+=("$("$vkrt" render "$work/primary.toml" -o "$work/p.exr" --spp "$spp" 2>&1 | grep ' spp ' | rate_of)")
    path+=("$("$vkrt" render "$work/path.toml" -o "$work/q.exr" --spp "$spp" 2>&1 | grep ' spp ' | rate_of)")
  done
  local p q
  p=$(printf '%s\n' "${primary[@]}" | median)
  q=$(printf '%s\n' "${path[@]}" | median)
  # Rays per primary sample: 1 camera ray, plus a shadow ray where it hit (the
  # whole view is mesh or floor: every camera ray hits something).
  printf '| %s | %s | %s | %s | %s | %s | %.2f | %.2f | %.3f |\n' "$name" "$triangles" "$load" "$build" "$nodes" \
    "$memory" "$(awk -v r="$p" 'BEGIN{print 2 * r / 1e6}')" "$(awk -v r="$p" 'BEGIN{print r / 1e6}')" \
    "$(awk -v r="$q" 'BEGIN{print r / 1e6}')"
}

echo "vkrt mesh benchmark on $("$vkrt" devices | awk '/^\*/{sub(/^\* [0-9]+: /, ""); print; exit}'), $(nproc) cores, $spp spp x $runs runs (medians)"
echo
echo "| mesh | triangles | load s | build s | BVH nodes | GPU MiB | Mrays/s (primary+shadow) | Msamples/s (depth 1) | Msamples/s (path, depth 5) |"
echo "|---|---|---|---|---|---|---|---|---|"
for n in "${counts[@]}"; do
  "$make_mesh" sphere "$n" "$work/sphere-$n.ply" >/dev/null
  measure "sphere" "$work/sphere-$n.ply" 1
done
[[ -f $assets/bunny.ply ]] && measure "bunny.ply" "$assets/bunny.ply" 10
[[ -f $assets/teapot.obj ]] && measure "teapot.obj" "$assets/teapot.obj" 0.4
[[ -f $assets/spot.obj ]] && measure "spot.obj" "$assets/spot.obj" 1
true

#!/usr/bin/env bash
# Lat-long environment maps: what a map costs at load (read, sampling CDF,
# upload) and per sample, against the same scene under a constant background.
#   tools/bench_environment.sh [BUILD_DIR] [ROUNDS]
# For each width W in 1024 2048 4096 8192 (maps of W x (W/2 + 1) texels made by
# vkrt-make-sky --latlong), renders a small path-traced scene (320 x 240) at
# 1 spp (whole process: start-up is where the map is loaded and its CDF built)
# and at 64 spp (steady samples/s from vkrt's --json), ROUNDS times each, and
# prints medians: start-up seconds, peak resident memory (GNU time), samples/s.
set -euo pipefail
build=${1:-build}
rounds=${2:-3}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

scene() { # $1: background table
  cat <<TOML
[render]
integrator = "path"
max_depth = 5
[camera]
eye = [0, 1.2, 5]
target = [0, 0.6, 0]
fov = 40
width = 320
height = 240
[materials.white]
type = "lambert"
albedo = 0.7
[materials.gold]
type = "conductor"
metal = "Au"
roughness = 0.2
[[objects]]
shape = "box"
material = "white"
min = [-4, -0.2, -4]
max = [4, 0, 4]
[[objects]]
shape = "sphere"
material = "gold"
center = [0, 0.7, 0]
radius = 0.7
$1
TOML
}

median() { sort -g | awk '{v[NR] = $1} END {print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}'; }

# One configuration: prints "startup_s peak_MiB samples_per_s" (medians).
measure() { # $1: scene file
  local startups=() peaks=() rates=()
  for ((r = 0; r < rounds; ++r)); do
    /usr/bin/time -f '%M' -o "$work/rss" "$build/vkrt" render "$1" -o "$work/out.exr" --spp 1 --json "$work/one.json" >/dev/null 2>&1
    startups+=("$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["startupSeconds"])' "$work/one.json")")
    peaks+=("$(($(cat "$work/rss") / 1024))")
    "$build/vkrt" render "$1" -o "$work/out.exr" --spp 64 --json "$work/many.json" >/dev/null 2>&1
    rates+=("$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["samplesPerSecond"])' "$work/many.json")")
  done
  printf '%s %s %s\n' "$(printf '%s\n' "${startups[@]}" | median)" "$(printf '%s\n' "${peaks[@]}" | median)" \
    "$(printf '%s\n' "${rates[@]}" | median)"
}

echo "# $(date -u +%Y-%m-%d) $(git -C "$(dirname "$0")/.." rev-parse --short HEAD 2>/dev/null || echo '?'); $("$build/vkrt" devices 2>/dev/null | grep '\*' | head -1)"
echo "background | startup s | peak MiB | samples/s"
scene $'[background]\ncolor = 0.8' >"$work/constant.toml"
read -r s m r < <(measure "$work/constant.toml")
echo "constant | $s | $m | $r"
for width in 1024 2048 4096 8192; do
  "$build/vkrt-make-sky" "$work/sky$width" --latlong "$width" --sun-radius 0.75 --sun-radiance 5000 >/dev/null
  scene "[background.environment]"$'\n'"file = \"sky$width/sky.exr\"" >"$work/env$width.toml"
  read -r s m r < <(measure "$work/env$width.toml")
  echo "lat-long ${width}x$((width / 2 + 1)) | $s | $m | $r"
done

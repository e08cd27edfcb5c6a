#!/usr/bin/env bash
# Error against spp for both samplers on the validation scenes: MSE against
# the committed Mitsuba references at 16, 64, 256 and 1024 spp, and the
# least-squares slope of log MSE against log spp per scene and sampler
# (-1 for independent samples; steeper where Sobol' points help).
#   tools/sampler_slopes.sh [VKRT] [SCENE ...]
set -euo pipefail
cd "$(dirname "$0")/.."
vkrt=${1:-build/vkrt}
shift || true
scenes=("$@")
[ ${#scenes[@]} -gt 0 ] || scenes=(diffuse-box lights glass environment-sky)
[ -x "$vkrt" ] || { echo "sampler_slopes: $vkrt is not an executable (build first or pass its path)" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "| scene | sampler | MSE 16 | MSE 64 | MSE 256 | MSE 1024 | slope |"
echo "| --- | --- | --- | --- | --- | --- | --- |"
for scene in "${scenes[@]}"; do
    ref=tests/references/validation/$scene/mean.exr
    [ -f "$ref" ] || { echo "sampler_slopes: no reference $ref" >&2; exit 2; }
    for sampler in independent sobol; do
        row="| $scene | $sampler |"
        points=""
        for spp in 16 64 256 1024; do
            "$vkrt" render "scenes/validation/$scene.toml" --spp "$spp" --sampler "$sampler" --seed 11 \
                -o "$work/r.exr" >/dev/null 2>&1
            rmse=$("$vkrt" compare "$work/r.exr" "$ref" | awk '$1 == "RMSE" {print $2}')
            mse=$(awk -v r="$rmse" 'BEGIN {printf "%.3g", r * r}')
            row="$row $mse |"
            points="$points $spp $mse"
        done
        slope=$(echo "$points" | awk '{n = 0; for (i = 1; i <= NF; i += 2) {x = log($i); y = log($(i + 1));
            sx += x; sy += y; sxx += x * x; sxy += x * y; n++}
            printf "%.2f", (n * sxy - sx * sy) / (n * sxx - sx * sx)}')
        echo "$row $slope |"
    done
done

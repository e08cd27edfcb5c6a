#!/usr/bin/env bash
# Runs the regression suite on lavapipe at each SIMD width it can be built
# for at run time (LP_NATIVE_VECTOR_WIDTH 128, 256 and 512 bits: subgroups of
# 4, 8 and 16 invocations). A GPU has subgroups of 32 or 64, which no machine
# here can run: the widths lavapipe offers are how vkrt checks that nothing in
# it assumes a subgroup size (docs/platform.md). Each width gets a Mesa shader
# cache of its own, since Mesa's cache would hand one width the code another
# compiled (docs/performance.md); the SPIR-V cache is shared (SPIR-V does not
# depend on the width). Checks that the device really runs at each width (its
# name says "N bits") and exits non-zero if any width fails a case.
#   tools/check-subgroup-widths.sh [--vkrt build/vkrt] [--widths "128 256 512"] [--quick]
#                                  [--jobs 2] [VKRT REGRESS OPTIONS...]
# --quick runs a subset with each kernel feature family once (ctest's
# subgroup_widths, tests/CMakeLists.txt); without it, the whole suite.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
vkrt=$root/build/vkrt
widths="128 256 512"
jobs=2
filters=()
while (($# > 0)); do
  case $1 in
    --vkrt) vkrt=$2; shift 2 ;;
    --widths) widths=$2; shift 2 ;;
    --jobs) jobs=$2; shift 2 ;;
    --quick)
      # Analytic shapes (two cases), a mesh through the BVH, textures, an
      # HDRI and a dielectric's long loops.
      filters=(--filter validation/diffuse-box --filter validation/mesh-cornell --filter validation/textured
        --filter validation/environment-hdri --filter extreme/tir)
      shift ;;
    -h|--help) sed -n '2,14{s/^# \{0,1\}//;p}' "$0"; exit 0 ;;
    *) break ;;
  esac
done
work=$(mktemp -d "${TMPDIR:-/tmp}/vkrt-widths.XXXXXX")
trap 'rm -rf "$work"' EXIT
export VKRT_CACHE_DIR=${VKRT_CACHE_DIR:-$work/spirv}
failed=0
for width in $widths; do
  device=$(LP_NATIVE_VECTOR_WIDTH=$width MESA_SHADER_CACHE_DIR=$work/mesa-$width "$vkrt" --version | tail -n 1)
  if [[ $device != *"$width bits"* ]]; then
    echo "check-subgroup-widths: LP_NATIVE_VECTOR_WIDTH=$width did not take: $device" >&2
    exit 2
  fi
  start=$(date +%s)
  status=0
  LP_NATIVE_VECTOR_WIDTH=$width MESA_SHADER_CACHE_DIR=$work/mesa-$width \
    "$vkrt" regress --jobs "$jobs" --report-dir "$work/report-$width" "${filters[@]}" "$@" \
    >"$work/$width.log" 2>&1 || status=$?
  echo "check-subgroup-widths: $width bits ($((width / 32))-wide subgroups): exit $status in" \
    "$(($(date +%s) - start)) s; $(tail -n 1 "$work/$width.log")"
  if ((status != 0)); then
    tail -n 30 "$work/$width.log" >&2
    failed=1
  fi
done
exit "$failed"

#!/usr/bin/env bash
# The checks and figures for a machine with an NVIDIA GPU, in one run of
# under 10 minutes (docs/performance.md, "When a GPU is lent"):
#   1. builds vkrt (Release, no tests) into build-gpu/, installing what is
#      missing first when it runs as root on Debian (tools/install-deps.sh);
#   2. `vkrt devices`, and picks the first NVIDIA device (else the first
#      discrete GPU; none: it stops, exit 3);
#   3. the regression suite on the GPU with both traversal backends
#      (`vkrt regress --compare-accel`), its JSON report kept;
#   4. the benchmark tables on the GPU: tools/bench_backends.py (samples/s of
#      both backends on the suite's scenes), the default scene's samples/s at
#      640x480, and the same figure on lavapipe for the ratio;
#   5. both kernel designs on the GPU: the megakernel and the staged kernels
#      (`render --staged`, trace and shade taking turns), samples/s of each on
#      three validation scenes and `vkrt compare` of their images.
# Every step has its own time limit and writes its output under OUT (default
# gpu-check-out/, or $OUT when set, as on the device machine); a step that
# fails is reported and the next one still runs. Exit status: 0 when every
# step passed, 1 when one failed, 3 when there is no GPU.
#
# Usage: tools/gpu-check.sh [OUT]
#   GPU_CHECK_DEVICE=INDEX|NAME  the device to check (default: the first NVIDIA one)
#   GPU_CHECK_VKRT=PATH          a vkrt binary to use instead of building one
set -uo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
out=${1:-${OUT:-$root/gpu-check-out}}
mkdir -p "$out"
cd "$root"
failed=0
log() { echo "gpu-check: $*" | tee -a "$out/summary.txt"; }

# step NAME SECONDS COMMAND...: runs COMMAND with a time limit, its output in OUT/NAME.log.
step() {
  local name=$1 limit=$2
  shift 2
  local start=$SECONDS
  # A function of this script runs in a bash of its own under the time limit.
  if declare -F "$1" >/dev/null; then set -- bash -c "$(declare -f "$1"); \"\$@\"" "$1" "$@"; fi
  if timeout --kill-after=10 "$limit" "$@" >"$out/$name.log" 2>&1; then
    log "$name: passed in $((SECONDS - start)) s"
  else
    local status=$?
    failed=1
    log "$name: FAILED (exit $status$( ((status == 124)) && echo ", past its ${limit} s")) in $((SECONDS - start)) s; see $name.log"
    tail -n 5 "$out/$name.log" | sed 's/^/    /' | tee -a "$out/summary.txt"
  fi
}

log "started $(date -u +%Y-%m-%dT%H:%M:%SZ) on $(nproc) cores"
if command -v nvidia-smi >/dev/null; then
  nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader >"$out/nvidia-smi.txt" 2>&1
  log "nvidia-smi: $(head -n 1 "$out/nvidia-smi.txt")"
fi

if [[ -n ${GPU_CHECK_VKRT:-} ]]; then
  log "using $GPU_CHECK_VKRT (GPU_CHECK_VKRT): no build"
elif [[ $(id -u) == 0 ]] && command -v apt-get >/dev/null &&
  ! { command -v cmake && command -v glslangValidator && pkg-config --exists vulkan; } >/dev/null 2>&1; then
  step install-deps 300 tools/install-deps.sh
fi
[[ -n ${GPU_CHECK_VKRT:-} ]] || step build 300 sh -c 'cmake -S . -B build-gpu -DCMAKE_BUILD_TYPE=Release -DVKRT_BUILD_TESTS=OFF &&
                      cmake --build build-gpu -j "$(nproc)"'
export vkrt=${GPU_CHECK_VKRT:-$root/build-gpu/vkrt} out
if [[ ! -x $vkrt ]]; then
  log "no vkrt binary: stopping"
  exit 1
fi

"$vkrt" devices >"$out/devices.txt" 2>&1
cat "$out/devices.txt" | tee -a "$out/summary.txt"
# The device line: "* 0: NAME (TYPE, Vulkan ..., DRIVER)"; the first NVIDIA one, else the first discrete GPU.
gpu=${GPU_CHECK_DEVICE:-$(sed -n 's/^[* ] *\([0-9][0-9]*\): .*NVIDIA.*/\1/p' "$out/devices.txt" | head -n 1)}
[[ -n $gpu ]] || gpu=$(sed -n 's/^[* ] *\([0-9][0-9]*\): .*(discrete GPU.*/\1/p' "$out/devices.txt" | head -n 1)
if [[ -z $gpu ]]; then
  log "no GPU among the Vulkan devices: nothing to check"
  exit 3
fi
log "GPU: device $gpu"

step regress-both-backends 240 "$vkrt" regress --device "$gpu" --compare-accel --report-dir "$out/regress"
step bench-backends 180 python3 tools/bench_backends.py --vkrt "$vkrt" --device "$gpu" --rounds 3 --spp 64 \
  --size 640x480
# samples/s of the default scene at 640x480 (vkrt's own --json), RUNS runs after a warm-up, on DEVICE.
default_scene_rate() {
  local device=$1 spp=$2 runs=$3
  "$vkrt" render scenes/default.toml --device "$device" --spp 1 --width 640 --height 480 -o "$out/warm.exr" || return 1
  for ((i = 1; i <= runs; i++)); do
    "$vkrt" render scenes/default.toml --device "$device" --spp "$spp" --width 640 --height 480 \
      -o "$out/default-$device.exr" --json - 2>/dev/null |
      python3 -c 'import json, sys; d = json.load(sys.stdin); print(d["device"]["name"], d["samplesPerSecond"])' ||
      return 1
  done
}
step bench-default-gpu 90 default_scene_rate "$gpu" 1024 5
# samples/s of both kernel designs, warm, and how far apart their images are.
both_kernel_designs() {
  local device=$1 scene name design
  for scene in scenes/validation/diffuse-box.toml scenes/validation/mesh-bunny-glass.toml \
    scenes/validation/textured.toml; do
    name=$(basename "$scene" .toml)
    for design in megakernel staged; do
      local flag=()
      [[ $design == staged ]] && flag=(--staged)
      "$vkrt" render "$scene" --device "$device" --spp 1 "${flag[@]}" -o "$out/warm.exr" >/dev/null || return 1
      "$vkrt" render "$scene" --device "$device" --spp 1024 --width 640 "${flag[@]}" -o "$out/$name-$design.exr" \
        --json - 2>/dev/null | python3 -c 'import json, sys; d = json.load(sys.stdin); print(sys.argv[1], sys.argv[2], d["samplesPerSecond"])' "$name" "$design" ||
        return 1
    done
    "$vkrt" compare "$out/$name-megakernel.exr" "$out/$name-staged.exr" | grep -E "^(RMSE|max)" || return 1
  done
}
step kernel-designs 240 both_kernel_designs "$gpu"
# Both ways of reading the scene (--scene-reads): cold first frame (the
# driver's compile, empty caches), samples/s warm, and their images (the same
# bit for bit). What auto picks on this device is measured on lavapipe only.
both_scene_reads() {
  local device=$1 scene name reads
  for scene in scenes/validation/mesh-bunny-glass.toml scenes/validation/textured.toml; do
    name=$(basename "$scene" .toml)
    for reads in descriptor address; do
      local cold
      cold=$(mktemp -d)
      VKRT_CACHE_DIR="$cold/spirv" MESA_SHADER_CACHE_DIR="$cold/mesa" "$vkrt" info "$scene" --device "$device" \
        --scene-reads "$reads" --json - 2>/dev/null |
        python3 -c 'import json, sys; d = json.load(sys.stdin); print(sys.argv[1], sys.argv[2], "first frame", d["startup"]["firstFrameSeconds"])' "$name" "$reads" ||
        return 1
      rm -rf "$cold"
      "$vkrt" render "$scene" --device "$device" --spp 1024 --width 640 --scene-reads "$reads" \
        -o "$out/$name-$reads.exr" --json - 2>/dev/null |
        python3 -c 'import json, sys; d = json.load(sys.stdin); print(sys.argv[1], sys.argv[2], d["samplesPerSecond"])' "$name" "$reads" ||
        return 1
    done
    "$vkrt" compare "$out/$name-descriptor.exr" "$out/$name-address.exr" | grep -E "^(RMSE|max)" || return 1
  done
}
step scene-reads 240 both_scene_reads "$gpu"
step bench-default-lavapipe 150 default_scene_rate llvmpipe 64 3

log "finished $(date -u +%Y-%m-%dT%H:%M:%SZ); outputs in $out"
exit $failed

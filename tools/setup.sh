#!/usr/bin/env bash
# One-command set-up on a fresh Debian 12 or 13 machine:
#   tools/setup.sh render   install what is missing, build, render scenes/default.toml
#                           to default.exr and default.png in the repository root
#   tools/setup.sh test     install what is missing, build, run the whole test suite on lavapipe
set -euo pipefail

mode=${1:-}
if [[ $mode != render && $mode != test ]]; then
  echo "usage: tools/setup.sh render|test" >&2
  exit 2
fi

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
tools/install-deps.sh

build_dir=${VKRT_BUILD_DIR:-build}
jobs=$(nproc)
cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DVKRT_WERROR=ON

if [[ $mode == render ]]; then
  # Rendering needs the vkrt executable alone, not the test executables and tools.
  cmake --build "$build_dir" --parallel "$jobs" --target vkrt
  "$build_dir/vkrt" render scenes/default.toml -o default.exr --png default.png
  echo "wrote $root/default.exr and $root/default.png"
else
  cmake --build "$build_dir" --parallel "$jobs"
  # Tests use lavapipe even where a GPU exists, so results match the references.
  export VKRT_TEST_DEVICE=${VKRT_TEST_DEVICE:-llvmpipe}
  ctest --test-dir "$build_dir" --output-on-failure --parallel "$jobs" --timeout 600
fi

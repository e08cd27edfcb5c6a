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
# Optimized, with line tables only (-g1): a backtrace or a sanitizer report
# still names file and line, and the build takes about a third less time than
# with full debug info (-g, CMake's RelWithDebInfo default; docs/performance.md).
cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DVKRT_WERROR=ON \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG"

# The Python module's virtual environment .venv: the interpreter the build
# made the module for, Debian's NumPy (--system-site-packages), and the
# build's package (build/python) on its path through a .pth file, so that a
# rebuild needs no reinstall (docs/python.md; `pip install .` makes a wheel instead).
python_env() {
  local python site
  python=$(sed -n 's/^_\{0,1\}Python_EXECUTABLE:[A-Z]*=//p' "$build_dir/CMakeCache.txt" | head -n 1)
  [[ -x .venv/bin/python ]] || "${python:-python3}" -m venv --system-site-packages .venv
  site=$(.venv/bin/python -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')
  printf '%s\n' "$(cd "$build_dir" && pwd)/python" >"$site/vkrt-build.pth"
  echo "Python: .venv/bin/python -c 'import vkrt' (docs/python.md)"
}

if [[ $mode == render ]]; then
  # Rendering needs the vkrt executable and the Python module, not the test executables and tools.
  cmake --build "$build_dir" --parallel "$jobs" --target vkrt _vkrt
  "$build_dir/vkrt" render scenes/default.toml -o default.exr --png default.png
  echo "wrote $root/default.exr and $root/default.png"
  python_env
else
  cmake --build "$build_dir" --parallel "$jobs"
  # Tests use lavapipe even where a GPU exists, so results match the references.
  export VKRT_TEST_DEVICE=${VKRT_TEST_DEVICE:-llvmpipe}
  python_env
  ctest --test-dir "$build_dir" --output-on-failure --parallel "$jobs" --timeout 600
fi

#!/usr/bin/env bash
# Creates .venv-cycles/ in the repository root for tools/compare_cycles.py:
# Blender as a Python module (bpy, from PyPI, which brings Cycles), NumPy and
# the OpenEXR bindings (reading both renderers' EXR files).
#
#   tools/setup-cycles-venv.sh            # create or complete .venv-cycles
#   PYTHON=python3.11 tools/setup-cycles-venv.sh
#   tools/setup-cycles-venv.sh --check    # exit 0 if the venv has everything, else 1
#
# bpy 5.0.x wheels exist for CPython 3.11 only (Blender's own Python; newer
# bpy needs 3.13), for x86_64 Linux (manylinux_2_28), macOS and Windows. The
# interpreter is, in order: $PYTHON, python3.11 on PATH, /usr/bin/python3.11
# (Debian 12's python3; its venv module is the package python3.11-venv).
# The bpy wheel is about 400 MB and unpacks to about 1.3 GB; it loads X11 and
# GL libraries even in background mode (Debian 12: libxrender1 libxxf86vm1
# libxfixes3 libxi6 libxkbcommon0 libsm6 libgl1 libegl1; the script installs
# the missing ones with apt-get when it runs as root, else names them).
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
venv=$repo/.venv-cycles
# The versions tools/compare_cycles.py was written and checked against.
packages=(bpy==5.0.1 "numpy>=1.24" "openexr>=3.3")
apt_packages=(libxrender1 libxxf86vm1 libxfixes3 libxi6 libxkbcommon0 libsm6 libgl1 libegl1)

log() { echo "setup-cycles-venv: $*" >&2; }

check() {
  [[ -x $venv/bin/python ]] && "$venv/bin/python" -c 'import numpy, OpenEXR, bpy' >/dev/null 2>&1
}

if [[ ${1:-} == --check ]]; then
  check && exit 0
  exit 1
fi

pick_python() {
  local candidate
  for candidate in ${PYTHON:-} python3.11 /usr/bin/python3.11; do
    command -v "$candidate" >/dev/null 2>&1 || continue
    if "$candidate" -c 'import sys; sys.exit(sys.version_info[:2] != (3, 11))' 2>/dev/null; then
      echo "$candidate"
      return 0
    fi
    log "$candidate is not Python 3.11; skipped"
  done
  return 1
}

missing_libraries() {
  local p
  for p in "${apt_packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'ok installed' || echo "$p"
  done
}

if command -v dpkg-query >/dev/null; then
  mapfile -t missing < <(missing_libraries)
  if ((${#missing[@]})); then
    if [[ $(id -u) -eq 0 ]] && command -v apt-get >/dev/null; then
      log "installing ${missing[*]} (bpy loads them even in background mode)"
      apt-get install -y --no-install-recommends "${missing[@]}" >/dev/null ||
        { apt-get update >/dev/null && apt-get install -y --no-install-recommends "${missing[@]}" >/dev/null; }
    else
      log "warning: bpy may fail to load without: ${missing[*]} (apt-get install them as root)"
    fi
  fi
fi

if [[ ! -x $venv/bin/python ]]; then
  python=$(pick_python) || {
    log "error: no Python 3.11 found (bpy from PyPI needs exactly 3.11); set PYTHON=/path/to/python3.11"
    exit 2
  }
  log "creating $venv with $python ($("$python" --version 2>&1))"
  "$python" -m venv "$venv"
fi
if check; then
  log "$venv is complete: $("$venv/bin/python" -c 'import bpy; print("bpy", bpy.app.version_string)' 2>/dev/null | tail -n 1)"
  exit 0
fi
log "installing ${packages[*]} (bpy is a large download)"
"$venv/bin/python" -m pip install --upgrade --quiet pip
"$venv/bin/python" -m pip install --quiet --only-binary :all: "${packages[@]}"
if ! check; then
  log "error: the packages installed but 'import numpy, OpenEXR, bpy' fails:"
  "$venv/bin/python" -c 'import numpy, OpenEXR, bpy' || true
  exit 1
fi
log "ready: $("$venv/bin/python" -c 'import bpy; print("bpy", bpy.app.version_string)' 2>/dev/null | tail -n 1)"

#!/usr/bin/env bash
# Unpacks Debian 12's stock lavapipe (Mesa 22.3.6, mesa-vulkan-drivers from
# the `bookworm` suite) into DIR without installing it, and writes
# DIR/lvp_icd.json, an ICD manifest that points at the unpacked driver, for
# `vkrt regress --driver DIR/lvp_icd.json` or VK_DRIVER_FILES. The suite runs
# against it as well as against the default Mesa 25 driver: same references,
# two drivers, as a Mesa developer would use it (docs/platform.md).
#
#   tools/fetch-old-lavapipe.sh DIR
#
# Idempotent: an existing DIR/lvp_icd.json whose driver loads is kept. Exit
# status 0 when the manifest is ready, 77 when this system cannot have it
# (not Debian 12: Mesa 22's libraries need bookworm's LLVM 15), 1 on failure.
set -euo pipefail

dir=${1:?usage: tools/fetch-old-lavapipe.sh DIR}
manifest=$dir/lvp_icd.json
mkdir -p "$dir"
dir=$(cd "$dir" && pwd)
manifest=$dir/lvp_icd.json

codename=$( (. /etc/os-release && echo "${VERSION_CODENAME:-}") 2>/dev/null || true)
if [[ $codename != bookworm ]]; then
  echo "fetch-old-lavapipe: Debian 12's Mesa 22 lavapipe is only tested on Debian 12 (this is '${codename:-unknown}')" >&2
  exit 77
fi

# Every shared library the driver needs must resolve on this system.
check_loads() {
  local library=$1 unresolved
  unresolved=$(ldd "$library" 2>&1 | grep 'not found' || true)
  if [[ -n $unresolved ]]; then
    echo "fetch-old-lavapipe: $library needs libraries this system lacks:" >&2
    echo "$unresolved" >&2
    return 1
  fi
}

library=$dir/root/usr/lib/x86_64-linux-gnu/libvulkan_lvp.so
if [[ -f $manifest && -f $library ]] && check_loads "$library"; then
  echo "fetch-old-lavapipe: $manifest already in place"
  exit 0
fi

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# apt-get download fetches into the current folder; as root its sandbox user
# cannot write to a mktemp folder, so allow it explicitly.
chmod 755 "$work"
if ! (cd "$work" && apt-get download -o APT::Sandbox::User=root mesa-vulkan-drivers/bookworm >/dev/null); then
  echo "fetch-old-lavapipe: could not download mesa-vulkan-drivers from the bookworm suite" \
    "(run 'apt-get update' first, or check the apt sources)" >&2
  exit 1
fi
package=$(ls "$work"/mesa-vulkan-drivers_*.deb)
rm -rf "$dir/root"
dpkg-deb -x "$package" "$dir/root"
[[ -f $library ]] || { echo "fetch-old-lavapipe: $package has no libvulkan_lvp.so" >&2; exit 1; }
check_loads "$library"
version=$(dpkg-deb -f "$package" Version)
api=$(sed -n 's/.*"api_version": *"\([^"]*\)".*/\1/p' "$dir"/root/usr/share/vulkan/icd.d/lvp_icd.*.json | head -n 1)
printf '{\n    "ICD": {\n        "api_version": "%s",\n        "library_path": "%s"\n    },\n    "file_format_version": "1.0.0"\n}\n' \
  "${api:-1.3.230}" "$library" >"$manifest.tmp"
mv "$manifest.tmp" "$manifest"
echo "fetch-old-lavapipe: mesa-vulkan-drivers $version unpacked in $dir; driver manifest $manifest"

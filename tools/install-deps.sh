#!/usr/bin/env bash
# Installs the Debian 12 packages vkrt needs. Idempotent: when everything is
# already installed it changes nothing and does not even run `apt-get update`.
set -euo pipefail

packages=(
  # build
  cmake ninja-build g++ pkg-config
  # Vulkan: loader and headers, lavapipe (software Vulkan), validation layers for tests
  libvulkan-dev mesa-vulkan-drivers vulkan-validationlayers
  # run-time GLSL compiler, maths, window, images, scene files, options, tests;
  # glslang-tools because glslang-dev's CMake package refers to glslangValidator
  # and find_package fails without it (it is only a Recommends, not installed here)
  glslang-dev glslang-tools libglm-dev libglfw3-dev libopenexr-dev libtomlplusplus-dev libcli11-dev libstb-dev libboost-dev libgtest-dev
  # a real X display for the viewer's tests
  xvfb xauth
)

missing=()
for package in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$package")
  fi
done

if ((${#missing[@]} == 0)); then
  echo "install-deps: all ${#packages[@]} packages already installed"
  exit 0
fi

sudo=()
if [[ $(id -u) -ne 0 ]]; then sudo=(sudo); fi
echo "install-deps: installing ${missing[*]}"
"${sudo[@]}" apt-get update
DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y --no-install-recommends "${missing[@]}"

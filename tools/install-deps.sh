#!/usr/bin/env bash
# Installs the Debian packages vkrt needs, on Debian 12 (bookworm) or 13 (trixie).
# Idempotent: when everything is already installed it changes nothing and does
# not even run `apt-get update`.
#
# The Vulkan driver is Mesa 25's lavapipe (software Vulkan): 1.6x faster than
# Mesa 22's on the same kernels, with the same images, and without Mesa 22's
# silent 65,535-iteration loop cap (docs/platform.md). Debian 13 ships it as
# mesa-vulkan-drivers. On Debian 12 it comes from Debian's own
# bookworm-backports suite: an apt source signed by the Debian archive keyring
# (on the mirror the machine already uses), from which only
# mesa-vulkan-drivers and the versions it requires (libdrm) are taken; apt
# gives backports priority 100, so nothing else is ever upgraded from it.
# Debian 12's stock Mesa 22 stays tested: tools/fetch-old-lavapipe.sh unpacks
# it into the build tree for `vkrt regress --driver` without installing it.
set -euo pipefail

packages=(
  # build
  cmake ninja-build g++ pkg-config
  # Vulkan: loader and headers, validation layers for tests (lavapipe below)
  libvulkan-dev vulkan-validationlayers
  # run-time GLSL compiler, maths, window, images, scene files, options, tests;
  # glslang-tools because glslang-dev's CMake package refers to glslangValidator
  # and find_package fails without it (it is only a Recommends, not installed here)
  glslang-dev glslang-tools libglm-dev libglfw3-dev libopenexr-dev libtomlplusplus-dev libcli11-dev libstb-dev libboost-dev libgtest-dev
  # mesh files: OBJ, PLY and glTF through one API; glTF's JSON for what assimp does not report (extensions)
  libassimp-dev nlohmann-json3-dev
  # tools/fuzz.sh: libFuzzer needs clang (clang++-14) and its runtime
  clang-14 libclang-rt-14-dev
  # a real X display for the viewer's tests
  xvfb xauth
  # the render farm's test runs a real single-node Slurm cluster (tools/slurm/local-cluster.sh)
  slurm-wlm munge
)
backports_source=/etc/apt/sources.list.d/vkrt-bookworm-backports.sources

codename=$( (. /etc/os-release && echo "${VERSION_CODENAME:-}") 2>/dev/null || true)

# Empty (and status 0, so `set -e` assignments survive) for a package dpkg has never seen.
installed_version() { dpkg-query -W -f='${Status} ${Version}' "$1" 2>/dev/null | sed -n 's/^install ok installed //p' || true; }

# The URI of the Debian mirror this machine already uses for `bookworm`
# (deb822 .sources stanzas or one-line .list entries), so that backports come
# from the same place and no mirror is chosen here.
bookworm_mirror() {
  local files=(/etc/apt/sources.list /etc/apt/sources.list.d/*.list /etc/apt/sources.list.d/*.sources)
  local file
  for file in "${files[@]}"; do
    [[ -f $file ]] || continue
    if [[ $file == *.sources ]]; then
      awk 'BEGIN { RS = ""; FS = "\n" }
           { uri = ""; ok = 0
             for (i = 1; i <= NF; i++) {
               if ($i ~ /^URIs:/) { sub(/^URIs:[ \t]*/, "", $i); split($i, u, /[ \t]+/); uri = u[1] }
               if ($i ~ /^Suites:/ && $i ~ /[ \t]bookworm([ \t]|$)/) ok = 1
             }
             if (ok && uri != "") { print uri; exit } }' "$file"
    else
      awk '$1 == "deb" { sub(/\[[^]]*\][ \t]*/, ""); if ($3 == "bookworm") { print $2; exit } }' "$file"
    fi
  done | head -n 1
}

has_backports_source() {
  grep -rqsE '(^|[[:space:]])bookworm-backports([[:space:]]|$)' /etc/apt/sources.list /etc/apt/sources.list.d/ 2>/dev/null
}

missing=()
for package in "${packages[@]}"; do
  [[ -n $(installed_version "$package") ]] || missing+=("$package")
done

# lavapipe: Mesa 25, from bookworm-backports on Debian 12.
driver=mesa-vulkan-drivers
add_backports=false
if [[ $codename == bookworm ]]; then
  version=$(installed_version mesa-vulkan-drivers)
  if [[ -z $version ]] || dpkg --compare-versions "$version" lt 25; then
    driver=mesa-vulkan-drivers/bookworm-backports
    missing+=("$driver")
    has_backports_source || add_backports=true
  fi
else
  [[ -n $(installed_version mesa-vulkan-drivers) ]] || missing+=("$driver")
  if [[ $codename != trixie ]]; then
    echo "install-deps: warning: vkrt is tested on Debian 12 (bookworm) and 13 (trixie), this is '${codename:-unknown}'" >&2
  fi
fi

if ((${#missing[@]} == 0)); then
  echo "install-deps: all ${#packages[@]} packages and Mesa 25 lavapipe already installed"
  exit 0
fi

sudo=()
if [[ $(id -u) -ne 0 ]]; then sudo=(sudo); fi
if $add_backports; then
  mirror=$(bookworm_mirror)
  if [[ -z $mirror ]]; then
    echo "install-deps: error: no apt source for 'bookworm' found in /etc/apt/sources.list{,.d}, so no mirror for" \
      "bookworm-backports; add one, or add bookworm-backports yourself" >&2
    exit 1
  fi
  echo "install-deps: adding Debian's bookworm-backports suite from $mirror as $backports_source (for Mesa 25 lavapipe)"
  printf 'Types: deb\nURIs: %s\nSuites: bookworm-backports\nComponents: main\nSigned-By: /usr/share/keyrings/debian-archive-keyring.gpg\n' \
    "$mirror" | "${sudo[@]}" tee "$backports_source" >/dev/null
fi
echo "install-deps: installing ${missing[*]}"
"${sudo[@]}" apt-get update
# `PACKAGE/SUITE` takes that package from the suite and lets apt take from it
# only the dependency versions it requires.
DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y --no-install-recommends "${missing[@]}"

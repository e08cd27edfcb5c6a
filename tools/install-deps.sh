#!/usr/bin/env bash
# Installs the Debian packages vkrt needs, on Debian 12 (bookworm) or 13 (trixie).
# Idempotent: when everything is already installed it changes nothing and does
# not even run `apt-get update`.
#
# The Vulkan driver is lavapipe (software Vulkan), the newest Debian builds:
# on Debian 12 Mesa 25 from Debian's own bookworm-backports suite (1.6x faster
# than the stock Mesa 22, and without Mesa 22's silent 65,535-iteration loop
# cap, docs/platform.md); on Debian 13 Mesa 26 from trixie-backports (1.1-1.9x
# faster than the stock Mesa 25, 4x faster kernel compiles; README "Which
# Vulkan driver you get"). Either suite is an apt source signed by the Debian
# archive keyring, on the mirror the machine already uses, from which only
# mesa-vulkan-drivers and the versions it requires are taken; apt gives
# backports priority 100, so nothing else is ever upgraded from it.
# Debian 12's stock Mesa 22 stays tested: tools/fetch-old-lavapipe.sh unpacks
# it into the build tree for `vkrt regress --driver` without installing it.
set -euo pipefail

packages=(
  # build; git, because the repository checks (tools/check-repository-paths.sh) read the tracked files
  cmake ninja-build g++ pkg-config git
  # Vulkan: loader and headers, validation layers for tests (lavapipe below)
  libvulkan-dev vulkan-validationlayers
  # run-time GLSL compiler, maths, window, images, scene files, options, tests;
  # glslang-tools because glslang-dev's CMake package refers to glslangValidator
  # and find_package fails without it (it is only a Recommends, not installed here)
  glslang-dev glslang-tools libglm-dev libglfw3-dev libopenexr-dev libtomlplusplus-dev libcli11-dev libstb-dev libboost-dev libgtest-dev
  # mesh files: OBJ, PLY and glTF through one API; glTF's JSON for what assimp does not report (extensions)
  libassimp-dev nlohmann-json3-dev
  # vkrt regress --flakes/--skips: regular expressions in linear time (deqp-runner's Rust regex is RE2's kind)
  libre2-dev
  # tools/fuzz.sh: libFuzzer needs clang and its runtime, the release's own
  # (clang-14 on Debian 12, clang-19 on Debian 13) through the metapackages
  clang libclang-rt-dev
  # a real X display for the viewer's tests
  xvfb xauth
  # the render farm's test runs a real single-node Slurm cluster (tools/slurm/local-cluster.sh)
  slurm-wlm munge
  # the Python module (python/, docs/python.md): its binding library and headers, NumPy, its tests,
  # and the virtual environment tools/setup.sh makes (python3-venv; pip for `pip install .`)
  pybind11-dev python3-dev python3-numpy python3-pytest python3-venv python3-pip
  # examples/convergence.py plots with matplotlib (and the suite runs it)
  python3-matplotlib
)

codename=$( (. /etc/os-release && echo "${VERSION_CODENAME:-}") 2>/dev/null || true)

# Empty (and status 0, so `set -e` assignments survive) for a package dpkg has never seen.
installed_version() { dpkg-query -W -f='${Status} ${Version}' "$1" 2>/dev/null | sed -n 's/^install ok installed //p' || true; }

# The URI of the Debian mirror this machine already uses for the release
# $codename (deb822 .sources stanzas or one-line .list entries), so that
# backports come from the same place and no mirror is chosen here.
release_mirror() {
  local files=(/etc/apt/sources.list /etc/apt/sources.list.d/*.list /etc/apt/sources.list.d/*.sources)
  local file
  for file in "${files[@]}"; do
    [[ -f $file ]] || continue
    if [[ $file == *.sources ]]; then
      awk -v release="$codename" 'BEGIN { RS = ""; FS = "\n" }
           { uri = ""; ok = 0
             for (i = 1; i <= NF; i++) {
               if ($i ~ /^URIs:/) { sub(/^URIs:[ \t]*/, "", $i); split($i, u, /[ \t]+/); uri = u[1] }
               if ($i ~ /^Suites:/ && $i ~ ("[ \t]" release "([ \t]|$)")) ok = 1
             }
             if (ok && uri != "") { print uri; exit } }' "$file"
    else
      awk -v release="$codename" '$1 == "deb" { sub(/\[[^]]*\][ \t]*/, ""); if ($3 == release) { print $2; exit } }' "$file"
    fi
  done | head -n 1
}

has_backports_source() {
  grep -rqsE "(^|[[:space:]])$backports([[:space:]]|\$)" /etc/apt/sources.list /etc/apt/sources.list.d/ 2>/dev/null
}

missing=()
for package in "${packages[@]}"; do
  [[ -n $(installed_version "$package") ]] || missing+=("$package")
done

# lavapipe: the release's backports build when the installed one is older.
case $codename in
  bookworm) mesa_major=25 ;;
  trixie) mesa_major=26 ;;
  *) mesa_major=
     echo "install-deps: warning: vkrt is tested on Debian 12 (bookworm) and 13 (trixie), this is '${codename:-unknown}'" >&2 ;;
esac
backports=$codename-backports
backports_source=/etc/apt/sources.list.d/vkrt-$backports.sources
add_backports=false
mesa_version=$(installed_version mesa-vulkan-drivers)
if [[ -n $mesa_major ]]; then
  if [[ -z $mesa_version ]] || dpkg --compare-versions "$mesa_version" lt "$mesa_major"; then
    missing+=("mesa-vulkan-drivers/$backports")
    has_backports_source || add_backports=true
  fi
elif [[ -z $mesa_version ]]; then
  missing+=(mesa-vulkan-drivers)
fi
if ((${#missing[@]} == 0)); then
  echo "install-deps: all ${#packages[@]} packages and Mesa ${mesa_version:-?} lavapipe already installed"
  exit 0
fi

sudo=()
if [[ $(id -u) -ne 0 ]]; then sudo=(sudo); fi
if $add_backports; then
  mirror=$(release_mirror)
  if [[ -z $mirror ]]; then
    echo "install-deps: error: no apt source for '$codename' found in /etc/apt/sources.list{,.d}, so no mirror for" \
      "$backports; add one, or add $backports yourself" >&2
    exit 1
  fi
  echo "install-deps: adding Debian's $backports suite from $mirror as $backports_source (for Mesa $mesa_major lavapipe)"
  printf 'Types: deb\nURIs: %s\nSuites: %s\nComponents: main\nSigned-By: /usr/share/keyrings/debian-archive-keyring.gpg\n' \
    "$mirror" "$backports" | "${sudo[@]}" tee "$backports_source" >/dev/null
fi
echo "install-deps: installing ${missing[*]}"
"${sudo[@]}" apt-get update
# `PACKAGE/SUITE` takes that package from the suite and lets apt take from it
# only the dependency versions it requires.
DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y --no-install-recommends "${missing[@]}"

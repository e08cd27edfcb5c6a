#!/usr/bin/env bash
# Checks that the README's two set-up commands work on a fresh Debian 13
# (trixie) system, as a new user would run them; with --release bookworm the
# same on a fresh Debian 12. Run it before landing a change to the build or
# to the dependencies (.ci/run runs it for Debian 13).
#
# Usage (as root, on a Debian or Debian-derived host):
#   sudo tools/check-debian13.sh           reuse the chroot if it exists, else make it
#   sudo tools/check-debian13.sh --fresh   delete the chroot and make a new one
#   sudo tools/check-debian13.sh --release bookworm   check Debian 12 instead
#                                               (chroot /var/tmp/vkrt-debian12)
#   sudo tools/check-debian13.sh --chroot DIR   use DIR instead of the default
#                                               (default: $VKRT_DEBIAN13_CHROOT or
#                                               /var/tmp/vkrt-debian13)
#
# What it does:
#   1. makes a minimal chroot of the release with `debootstrap --variant=minbase`
#      (debootstrap is installed with apt if missing); the Debian archive is
#      the one the host's own apt sources use, so no mirror is written here;
#   2. clones this repository's committed HEAD (not the working tree: commit
#      first) into /root/vkrt inside the chroot, replacing any earlier clone;
#   3. runs `tools/setup.sh render` and then `tools/setup.sh test` in it as
#      root, with /proc, /sys, /dev, /dev/pts, /dev/shm and a private /tmp
#      mounted, all unmounted again on any exit;
#   4. prints a PASS/FAIL line per command with its duration, the compiler,
#      Mesa and Vulkan header versions found in the chroot, and exits 0 only
#      if both commands passed. Full logs are kept in the chroot's
#      /root/vkrt-logs and their paths are printed.
#
# A second run reuses the chroot (its packages stay installed), so it costs
# only the build and the tests. The build uses every core the host has.
set -euo pipefail

suite=trixie
chroot_dir=
fresh=0

usage() { sed -n '2,/^set -euo/{/^set -euo/d;s/^# \{0,1\}//;p}' "$0"; }

while (($# > 0)); do
  case $1 in
    --fresh) fresh=1 ;;
    --release)
      [[ $# -ge 2 && ($2 == trixie || $2 == bookworm) ]] \
        || { echo "check-debian13: --release takes trixie (Debian 13) or bookworm (Debian 12)" >&2; exit 2; }
      suite=$2; shift ;;
    --chroot)
      [[ $# -ge 2 ]] || { echo "check-debian13: --chroot needs a directory" >&2; exit 2; }
      chroot_dir=$2; shift ;;
    -h|--help) usage; exit 0 ;;
    *) echo "check-debian13: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
  shift
done

case $suite in
  trixie) debian="Debian 13"; chroot_dir=${chroot_dir:-${VKRT_DEBIAN13_CHROOT:-/var/tmp/vkrt-debian13}} ;;
  bookworm) debian="Debian 12"; chroot_dir=${chroot_dir:-/var/tmp/vkrt-debian12} ;;
esac

log() { printf 'check-debian13: %s\n' "$*"; }
die() { printf 'check-debian13: error: %s\n' "$*" >&2; exit 1; }

[[ $(id -u) -eq 0 ]] || die "debootstrap, mount and chroot need root: run it with sudo"
# Under sudo the clone belongs to another user; git refuses such a repository
# unless it is named safe.
git() { command git -c safe.directory='*' "$@"; }
repo=$(git -C "$(dirname "${BASH_SOURCE[0]}")" rev-parse --show-toplevel) \
  || die "this script must run from a git clone of the repository"
head=$(git -C "$repo" rev-parse HEAD)
[[ $chroot_dir == /* && $chroot_dir != / ]] || die "the chroot directory must be an absolute path other than /"

# --- the Debian archive, from the host's apt sources --------------------------

host_codename=$(. /etc/os-release 2>/dev/null && echo "${VERSION_CODENAME:-}")

# host_apt_sources: "URI SUITE" for every enabled source of the host (tools/apt-sources.sh).
# shellcheck source=tools/apt-sources.sh
. "$(dirname "${BASH_SOURCE[0]}")/apt-sources.sh"

# The archive is the source that serves the host's own release (its suite is
# exactly the host's codename); the security archive serves CODENAME-security.
find_archive() {
  local suffix=$1
  [[ -n $host_codename ]] || return 0
  host_apt_sources | awk -v want="$host_codename$suffix" '$2 == want { print $1; exit }'
}

mirror=${VKRT_DEBIAN_MIRROR:-$(find_archive "")}
security_mirror=${VKRT_DEBIAN_SECURITY_MIRROR:-$(find_archive "-security")}
[[ -n $mirror ]] || die "no Debian archive found in the host's apt sources \
(/etc/apt/sources.list, /etc/apt/sources.list.d/*.list or *.sources) for the host's release \
'${host_codename:-unknown}'; set VKRT_DEBIAN_MIRROR to a Debian archive URI"

# --- mounts, unmounted on any exit -------------------------------------------

mounted=()
mount_in_chroot() { # mount ARGS... TARGET (TARGET relative to the chroot)
  local target=$chroot_dir${*: -1}
  mkdir -p "$target"
  if mountpoint -q "$target"; then return 0; fi
  mount "${@:1:$#-1}" "$target"
  mounted+=("$target")
}
unmount_all() {
  local i
  for ((i = ${#mounted[@]} - 1; i >= 0; i--)); do
    umount -R "${mounted[i]}" 2>/dev/null || umount -R -l "${mounted[i]}" 2>/dev/null \
      || echo "check-debian13: warning: could not unmount ${mounted[i]}" >&2
  done
  mounted=()
}
trap unmount_all EXIT
trap 'exit 130' INT TERM

# Lists whatever is still mounted below the chroot (for example after a run
# that was killed with SIGKILL), so that the chroot is never deleted through
# a bind mount of the host's /dev.
mounts_below_chroot() {
  awk -v root="$chroot_dir/" '{ gsub(/\\040/, " ", $2); if (index($2 "/", root) == 1) print $2 }' /proc/mounts
}

# --- the chroot ---------------------------------------------------------------

ready_marker=$chroot_dir/.vkrt-debian13-ready
timings=()
started=$(date +%s)

if ((fresh)) && [[ -e $chroot_dir ]]; then
  if [[ -n $(mounts_below_chroot) ]]; then
    die "still mounted below $chroot_dir (unmount first): $(mounts_below_chroot | tr '\n' ' ')"
  fi
  log "--fresh: deleting $chroot_dir"
  rm -rf --one-file-system "$chroot_dir"
fi

if [[ ! -e $ready_marker ]]; then
  if ! command -v debootstrap >/dev/null; then
    log "installing debootstrap on the host"
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends debootstrap
  fi
  if [[ -e $chroot_dir ]]; then
    [[ -z $(mounts_below_chroot) ]] || die "still mounted below $chroot_dir: $(mounts_below_chroot | tr '\n' ' ')"
    log "$chroot_dir is an unfinished chroot: deleting it"
    rm -rf --one-file-system "$chroot_dir"
  fi
  keyring=()
  if [[ -f /usr/share/keyrings/debian-archive-keyring.gpg ]]; then
    keyring=(--keyring=/usr/share/keyrings/debian-archive-keyring.gpg)
  fi
  log "debootstrap --variant=minbase $suite $chroot_dir $mirror"
  t0=$(date +%s)
  debootstrap --variant=minbase "${keyring[@]}" "$suite" "$chroot_dir" "$mirror" \
    >"$chroot_dir.debootstrap.log" 2>&1 \
    || die "debootstrap failed; see $chroot_dir.debootstrap.log (and $chroot_dir/debootstrap/debootstrap.log)"
  rm -f "$chroot_dir.debootstrap.log"
  # The sources a fresh installation of the release has: the release, its updates and
  # its security archive.
  {
    printf 'Types: deb\nURIs: %s\nSuites: %s %s-updates\nComponents: main\n' "$mirror" "$suite" "$suite"
    printf 'Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg\n'
    if [[ -n $security_mirror ]]; then
      printf '\nTypes: deb\nURIs: %s\nSuites: %s-security\nComponents: main\n' "$security_mirror" "$suite"
      printf 'Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg\n'
    fi
  } >"$chroot_dir/etc/apt/sources.list.d/debian.sources"
  rm -f "$chroot_dir/etc/apt/sources.list"
  # Packages must not start services inside the chroot.
  printf '#!/bin/sh\nexit 101\n' >"$chroot_dir/usr/sbin/policy-rc.d"
  chmod 755 "$chroot_dir/usr/sbin/policy-rc.d"
  touch "$ready_marker"
  timings+=("debootstrap: $(($(date +%s) - t0)) s")
else
  log "reusing $chroot_dir (--fresh to rebuild it)"
fi
cp -L /etc/resolv.conf "$chroot_dir/etc/resolv.conf" 2>/dev/null || true

mount_in_chroot -t proc proc /proc
mount_in_chroot -t sysfs sysfs /sys
# The host's cgroup hierarchy, whatever its version: slurmd (the render farm's
# test) refuses to start without one ("No filesystem mounted on /sys/fs/cgroup").
if mountpoint -q /sys/fs/cgroup; then
  mount_in_chroot --rbind /sys/fs/cgroup /sys/fs/cgroup
  mount --make-rslave "$chroot_dir/sys/fs/cgroup"
fi
mount_in_chroot --bind /dev /dev
mount_in_chroot --bind /dev/pts /dev/pts
mount_in_chroot -t tmpfs -o mode=1777 shm /dev/shm
mount_in_chroot -t tmpfs -o mode=1777 tmpfs /tmp

# --- a fresh clone of the committed HEAD -------------------------------------

clone=$chroot_dir/root/vkrt
logs=$chroot_dir/root/vkrt-logs
rm -rf --one-file-system "$clone" "$logs"
mkdir -p "$logs"
if [[ -n $(git -C "$repo" status --porcelain --untracked-files=no) ]]; then
  log "note: the working tree has uncommitted changes; they are NOT checked (only HEAD is)"
fi
git clone --quiet --no-hardlinks "$repo" "$clone"
git -C "$clone" checkout --quiet --detach "$head"
log "checking $(git -C "$repo" log -1 --format='%h %s' "$head" | cut -c1-100)"

# --- the README's commands ----------------------------------------------------

in_chroot() {
  chroot "$chroot_dir" /usr/bin/env -i HOME=/root PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
    LANG=C.UTF-8 TERM=dumb DEBIAN_FRONTEND=noninteractive "$@"
}

results=()
failed=0
run_step() { # NAME COMMAND...
  local name=$1; shift
  local logfile=$logs/$name.log t0 rc=0
  log "running '$*' in the chroot (log: $logfile)"
  t0=$(date +%s)
  in_chroot /bin/sh -c 'cd /root/vkrt && exec "$@"' sh "$@" >"$logfile" 2>&1 || rc=$?
  local seconds=$(($(date +%s) - t0))
  if ((rc == 0)); then
    results+=("PASS  $* ($seconds s)")
  else
    results+=("FAIL  $* (exit $rc after $seconds s; log: $logfile)")
    failed=1
    echo "----- last 40 lines of $logfile -----"
    tail -n 40 "$logfile"
    echo "-----"
  fi
  return $rc
}

run_step setup-render tools/setup.sh render || true
# The Python module from the environment the set-up made (docs/python.md): it
# imports, and its image equals `vkrt render`'s at the same seed and lavapipe
# vector width, bit for bit (the module runs at the width of its process;
# `vkrt render --vector-width auto` may start itself again at 512 bits).
run_step python-module .venv/bin/python -c "
import subprocess, numpy, vkrt
r = vkrt.render(vkrt.Scene.load('scenes/default.toml'), spp=4, seed=3)
print(r.image.shape)
bits = r.metadata.get('vectorWidth')  # lavapipe's width: absent on other devices
width = ['--vector-width', str(bits)] if bits else []
subprocess.run(['build/vkrt', 'render', 'scenes/default.toml', '--spp', '4', '--seed', '3', '-o', 'python-check.exr']
               + width, check=True)
assert numpy.array_equal(r.image, vkrt.read_exr('python-check.exr')[0]['image']), 'the images differ'
print('equal to vkrt render')
" || true
run_step setup-test tools/setup.sh test || true

version_of() { in_chroot dpkg-query -W -f='${Version}' "$1" 2>/dev/null || echo "not installed"; }
echo
echo "== $debian check of $(git -C "$repo" rev-parse --short "$head") in $chroot_dir =="
echo "Debian:         $(cat "$chroot_dir/etc/debian_version")"
echo "g++:            $(in_chroot g++ -dumpfullversion 2>/dev/null || echo 'not installed')"
echo "cmake:          $(version_of cmake)"
echo "Mesa (lavapipe): $(version_of mesa-vulkan-drivers)"
echo "Vulkan headers: $(version_of libvulkan-dev)"
echo "glslang:        $(version_of glslang-dev)"
echo "toml++:         $(version_of libtomlplusplus-dev)"
grep -h -E '^(100% tests passed|[0-9]+% tests passed)' "$logs/setup-test.log" 2>/dev/null | sed 's/^/ctest:          /' || true
for t in "${timings[@]}"; do echo "$t"; done
for r in "${results[@]}"; do echo "$r"; done
total=$(($(date +%s) - started))
if ((failed)); then
  echo "FAIL: $debian check failed (total $total s)"
  exit 1
fi
echo "PASS: both README commands work on $debian (total $total s)"

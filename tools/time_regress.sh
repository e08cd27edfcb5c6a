#!/usr/bin/env bash
# Measures how long the default regression suite takes, as the README quotes
# it: `vkrt regress --jobs J` once with cold caches (an empty SPIR-V cache and
# Mesa shader cache: every kernel compiled, as on a fresh machine) and once
# warm (both caches kept from the first run), whole process, wall seconds.
#   tools/time_regress.sh [--vkrt build/vkrt] [--jobs 2] [VKRT REGRESS OPTIONS...]
# Prints one line per run and exits with the suite's status if it failed.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
vkrt=$root/build/vkrt
jobs=$(nproc)
while (($# > 0)); do
  case $1 in
    --vkrt) vkrt=$2; shift 2 ;;
    --jobs) jobs=$2; shift 2 ;;
    -h|--help) sed -n '2,7{s/^# \{0,1\}//;p}' "$0"; exit 0 ;;
    *) break ;;
  esac
done
work=$(mktemp -d "${TMPDIR:-/tmp}/vkrt-time-regress.XXXXXX")
trap 'rm -rf "$work"' EXIT
export VKRT_CACHE_DIR=$work/spirv MESA_SHADER_CACHE_DIR=$work/mesa
for run in cold warm; do
  start=$(date +%s.%N)
  status=0
  "$vkrt" regress --jobs "$jobs" --report-dir "$work/report-$run" "$@" >"$work/$run.log" 2>&1 || status=$?
  end=$(date +%s.%N)
  printf 'time_regress: %s caches, --jobs %s: %.1f s (exit %d; %s)\n' "$run" "$jobs" \
    "$(echo "$end - $start" | bc)" "$status" "$("$vkrt" --version | tail -n 1)"
  if ((status != 0)); then tail -n 20 "$work/$run.log" >&2; exit "$status"; fi
done

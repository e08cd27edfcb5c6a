#!/usr/bin/env bash
# Merges the shards tools/farm/shard.sh wrote (docs/farm.md): the merge step
# of every farm (Slurm's merge job, the Kubernetes merge Job, tools/farm/local.sh).
#
#   tools/farm/merge.sh --shards N --out DIR [-o FRAME.exr] [--allow-missing]
#
# Reads DIR/shard-I-of-N.exr for I = 0 ... N-1 and writes DIR/frame.exr (or
# FRAME.exr) with `vkrt merge`, which checks that the shards belong together
# and writes atomically. A missing shard file is an error naming every
# missing one, unless --allow-missing, which merges those present (the merged
# EXR records its true spp and the missing sample ranges).
# The vkrt executable is $VKRT, else build/vkrt of this checkout.
set -euo pipefail

usage() {
  echo "usage: tools/farm/merge.sh --shards N --out DIR [-o FRAME.exr] [--allow-missing]" >&2
  exit 2
}

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
source "$here/common.sh"
shards="" out="" frame="" allow_missing=false
while (($#)); do
  case $1 in
    --shards | --out | -o)
      (($# >= 2)) || fail "$1 needs a value"
      case $1 in --shards) shards=$2 ;; --out) out=$2 ;; -o) frame=$2 ;; esac
      shift 2 ;;
    --allow-missing) allow_missing=true; shift ;;
    -h | --help) usage ;;
    *) fail "unknown argument $1" ;;
  esac
done
[[ -n $shards && -n $out ]] || usage
shards=$(count --shards "$shards")
frame=${frame:-$out/frame.exr}

vkrt=${VKRT:-$here/../../build/vkrt}
[[ -x $vkrt ]] || fail "no vkrt executable at $vkrt (build it, or set VKRT)"

present=() missing=()
for ((i = 0; i < shards; ++i)); do
  file=$out/shard-$i-of-$shards.exr
  if [[ -f $file ]]; then present+=("$file"); else missing+=("$file"); fi
done
if ((${#missing[@]})); then
  if ! $allow_missing || ((${#present[@]} == 0)); then
    fail "${#missing[@]} of $shards shards missing: ${missing[*]}$($allow_missing || echo ' (re-run them, or pass --allow-missing)')"
  fi
  echo "merge.sh: warning: merging without ${missing[*]}" >&2
fi

args=(merge "${present[@]}" -o "$frame")
! $allow_missing || args+=(--allow-missing)
exec "$vkrt" "${args[@]}"

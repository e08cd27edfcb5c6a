#!/usr/bin/env bash
# Renders one shard of a frame (docs/farm.md). The one entry point of every
# farm: Slurm array tasks (tools/slurm/shard.sbatch), Kubernetes Indexed Job
# pods (tools/k8s/render-job.yaml) and local processes (tools/farm/local.sh)
# all run this script.
#
#   tools/farm/shard.sh SCENE --shards N --spp S --out DIR [--index I] [--seed K]
#                       [--device D] [-- EXTRA vkrt render OPTIONS]
#
# The shard index is --index, else the scheduler's variable:
# $SLURM_ARRAY_TASK_ID (Slurm job arrays), $JOB_COMPLETION_INDEX (Kubernetes
# Indexed Jobs), $VKRT_SHARD_INDEX (anything else). The shard is written to
# DIR/shard-I-of-N.exr, a fixed name, so re-running a failed shard replaces
# exactly its file; vkrt writes it atomically (a temporary file renamed into
# place), so a shard killed half-way leaves no half-written file behind.
# The vkrt executable is $VKRT, else build/vkrt of this checkout.
set -euo pipefail

usage() {
  echo "usage: tools/farm/shard.sh SCENE --shards N --spp S --out DIR [--index I] [--seed K] [--device D] [-- vkrt render options]" >&2
  exit 2
}

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
source "$here/common.sh"
scene="" shards="" spp="" out="" index="" seed=1 device=""
extra=()
while (($#)); do
  case $1 in
    --shards | --spp | --out | --index | --seed | --device)
      (($# >= 2)) || fail "$1 needs a value"
      case $1 in
        --shards) shards=$2 ;; --spp) spp=$2 ;; --out) out=$2 ;;
        --index) index=$2 ;; --seed) seed=$2 ;; --device) device=$2 ;;
      esac
      shift 2 ;;
    --) shift; extra=("$@"); break ;;
    -h | --help) usage ;;
    -*) fail "unknown option $1 (options after -- go to vkrt render)" ;;
    *) [[ -z $scene ]] || fail "more than one scene given ('$scene' and '$1')"; scene=$1; shift ;;
  esac
done
[[ -n $scene && -n $shards && -n $spp && -n $out ]] || usage

if [[ -z $index ]]; then
  for variable in SLURM_ARRAY_TASK_ID JOB_COMPLETION_INDEX VKRT_SHARD_INDEX; do
    if [[ -n ${!variable:-} ]]; then index=${!variable}; index_from="\$$variable"; break; fi
  done
  [[ -n $index ]] || fail "no shard index: pass --index, or set SLURM_ARRAY_TASK_ID, JOB_COMPLETION_INDEX or VKRT_SHARD_INDEX"
else
  index_from="--index"
fi
shards=$(count --shards "$shards")
whole_number "$index" && ((10#$index < shards)) ||
  fail "$index_from = '$index': expected a shard index 0 ... $((shards - 1)) for --shards $shards"
index=$((10#$index))

vkrt=${VKRT:-$here/../../build/vkrt}
[[ -x $vkrt ]] || fail "no vkrt executable at $vkrt (build it, or set VKRT)"
mkdir -p "$out"

args=(render "$scene" --spp "$spp" --seed "$seed" --variance --shard "$index/$shards"
  -o "$out/shard-$index-of-$shards.exr")
[[ -z $device ]] || args+=(--device "$device")
echo "shard.sh: shard $index of $shards ($index_from) on $(hostname -s): $vkrt ${args[*]} ${extra[*]}" >&2
exec "$vkrt" "${args[@]}" "${extra[@]}"

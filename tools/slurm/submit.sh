#!/usr/bin/env bash
# Submits a sharded render to Slurm (docs/farm.md): a job array with one task
# per shard (tools/slurm/shard.sbatch, SLURM_ARRAY_TASK_ID -> --shard) and a
# merge job (tools/slurm/merge.sbatch) chained with --dependency=afterok and
# --kill-on-invalid-dep=yes, so a failed shard cancels the merge instead of
# leaving it pending forever.
#
#   tools/slurm/submit.sh SCENE --shards N --spp S --out DIR [--seed K]
#       [--tasks LIST] [--sbatch-arg ARG]... [--no-check] [--wait] [-- vkrt render options]
#
# Prints "shards JOBID" and "merge JOBID" on stdout. Shard I is written to
# DIR/shard-I-of-N.exr, the merged frame to DIR/frame.exr, logs to DIR/logs/.
# DIR, the scene, this checkout and the vkrt executable must be on a file
# system every node sees; point $VKRT_CACHE_DIR there too, so that one node's
# compiled kernel is every node's cache hit.
#
#   --tasks LIST      submit only these array tasks (sbatch --array syntax:
#                     "2", "1,3", "0-7"), then the merge of all N: re-running
#                     a failed shard. The file names are fixed, so the new
#                     shard replaces the failed one and the merge reads it.
#   --sbatch-arg ARG  passed to both sbatch calls (repeat it): --partition=gpu,
#                     --gres=gpu:1, --time=1:00:00, ...
#   --no-check        do not check the scene with `vkrt info` before submitting
#   --wait            wait for the merge job to end; the exit status says
#                     whether it completed
# The vkrt executable is $VKRT, else build/vkrt of this checkout.
set -euo pipefail

usage() {
  echo "usage: tools/slurm/submit.sh SCENE --shards N --spp S --out DIR [--seed K] [--tasks LIST]" \
    "[--sbatch-arg ARG]... [--no-check] [--wait] [-- vkrt render options]  (options: the comment at its top)" >&2
  exit 2
}

slurm_dir=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
farm_dir=$(cd "$slurm_dir/../farm" && pwd)
source "$farm_dir/common.sh"
scene="" shards="" spp="" out="" seed=1 tasks="" check=true wait=false
sbatch_args=() extra=()
while (($#)); do
  case $1 in
    --shards | --spp | --out | --seed | --tasks | --sbatch-arg)
      (($# >= 2)) || fail "$1 needs a value"
      case $1 in
        --shards) shards=$2 ;; --spp) spp=$2 ;; --out) out=$2 ;; --seed) seed=$2 ;;
        --tasks) tasks=$2 ;; --sbatch-arg) sbatch_args+=("$2") ;;
      esac
      shift 2 ;;
    --no-check) check=false; shift ;;
    --wait) wait=true; shift ;;
    --) shift; extra=("$@"); break ;;
    -h | --help) usage ;;
    -*) fail "unknown option $1 (options after -- go to vkrt render)" ;;
    *) [[ -z $scene ]] || fail "more than one scene given ('$scene' and '$1')"; scene=$1; shift ;;
  esac
done
[[ -n $scene && -n $shards && -n $spp && -n $out ]] || usage

# ---- checks before anything is submitted
[[ -f $scene ]] || fail "scene $scene: no such file"
shards=$(count --shards "$shards")
spp=$(count --spp "$spp")
((shards <= spp)) || fail "--shards $shards of --spp $spp would leave some shards without samples; use at most --spp shards"
whole_number "$seed" || fail "--seed $seed: expected a whole number"
array=0-$((shards - 1))
if [[ -n $tasks ]]; then
  [[ $tasks =~ ^[0-9]+(-[0-9]+)?(,[0-9]+(-[0-9]+)?)*$ ]] ||
    fail "--tasks $tasks: expected task indices and ranges such as 2, 1,3 or 0-7"
  for number in ${tasks//[,-]/ }; do
    ((10#$number < shards)) || fail "--tasks $tasks: task $number is not a shard of --shards $shards (0 ... $((shards - 1)))"
  done
  array=$tasks
fi
command -v sbatch >/dev/null || fail "sbatch not found: run this where Slurm's commands are (slurm-client)"
vkrt=$(realpath -e "${VKRT:-$slurm_dir/../../build/vkrt}" 2>/dev/null) && [[ -x $vkrt ]] ||
  fail "no vkrt executable at ${VKRT:-$slurm_dir/../../build/vkrt} (build it, or set VKRT)"
scene=$(realpath -e "$scene")
mkdir -p "$out/logs"
out=$(realpath -e "$out")
if $check; then
  "$vkrt" info "$scene" >/dev/null || fail "the scene does not load (above); nothing was submitted"
fi

# ---- the array and its merge
# sbatch runs copies of the batch scripts, so they find the farm scripts and
# vkrt through the environment (--export=ALL keeps the rest of it, for
# VKRT_CACHE_DIR and the Vulkan settings).
environment=ALL,VKRT_FARM_DIR=$farm_dir,VKRT=$vkrt
shard_job=$(sbatch --parsable --export="$environment" --array="$array" \
  --output="$out/logs/shard-%a-of-$shards.log" "${sbatch_args[@]}" \
  "$slurm_dir/shard.sbatch" "$scene" --shards "$shards" --spp "$spp" --seed "$seed" --out "$out" -- "${extra[@]}")
shard_job=${shard_job%%;*}
merge_job=$(sbatch --parsable --export="$environment" --dependency="afterok:$shard_job" --kill-on-invalid-dep=yes \
  --output="$out/logs/merge.log" "${sbatch_args[@]}" \
  "$slurm_dir/merge.sbatch" --shards "$shards" --out "$out")
merge_job=${merge_job%%;*}
echo "shards $shard_job"
echo "merge $merge_job"
echo "submit.sh: array job $shard_job (tasks $array of $shards), merge job $merge_job -> $out/frame.exr" >&2

$wait || exit 0

# ---- --wait: until the merge job leaves the queue
job_state() { scontrol show job "$1" -o 2>/dev/null | sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p'; }
while :; do
  state=$(job_state "$merge_job")
  case $state in
    PENDING | RUNNING | CONFIGURING | COMPLETING | SUSPENDED | REQUEUED | RESIZING) sleep 0.5 ;;
    *) break ;;
  esac
done
if [[ $state == COMPLETED ]]; then
  echo "submit.sh: merge job $merge_job completed: $out/frame.exr" >&2
  exit 0
fi
echo "submit.sh: merge job $merge_job ended ${state:-without a record}; shard logs in $out/logs/" >&2
exit 1

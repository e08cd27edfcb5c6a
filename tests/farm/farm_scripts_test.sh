#!/usr/bin/env bash
# The farm's entry scripts without a scheduler (docs/farm.md):
# tools/farm/shard.sh takes its index from the variables Kubernetes Indexed
# Jobs and Slurm arrays set, tools/farm/merge.sh merges what it wrote, and
# tools/farm/local.sh runs shards as local processes and merges them; every
# merged frame equals a single-process render of the same samples, and bad
# indices, missing shards and failed shards are refused by name.
#   farm_scripts_test.sh VKRT SOURCE_DIR
set -euo pipefail
vkrt=$1 root=$2
source "$root/tests/farm/farm_test_lib.sh"
shard=$root/tools/farm/shard.sh merge=$root/tools/farm/merge.sh local=$root/tools/farm/local.sh

render_single

step "Kubernetes Indexed Job: JOB_COMPLETION_INDEX picks the shard"
for i in 0 1 2 3; do
  JOB_COMPLETION_INDEX=$i "$shard" "$scene" --shards 4 --spp "$spp" --seed "$seed" --out "$work/k8s" \
    ${device:+--device "$device"} -- "${size[@]}"
done
for i in 0 1 2 3; do [[ -f $work/k8s/shard-$i-of-4.exr ]] || fail "JOB_COMPLETION_INDEX=$i wrote no shard-$i-of-4.exr"; done
"$merge" --shards 4 --out "$work/k8s"
expect_equals_single "$work/k8s/frame.exr"

step "Slurm array: SLURM_ARRAY_TASK_ID picks the shard; a re-run replaces its file"
SLURM_ARRAY_TASK_ID=1 "$shard" "$scene" --shards 4 --spp "$spp" --seed "$seed" --out "$work/k8s" \
  ${device:+--device "$device"} -- "${size[@]}"
"$merge" --shards 4 --out "$work/k8s" -o "$work/k8s/again.exr"
expect_equals_single "$work/k8s/again.exr"

step "bad shard indices and counts are refused by name"
expect_failure "no shard index" env -u SLURM_ARRAY_TASK_ID -u JOB_COMPLETION_INDEX -u VKRT_SHARD_INDEX \
  "$shard" "$scene" --shards 4 --spp "$spp" --out "$work/bad"
expect_failure "\$JOB_COMPLETION_INDEX = '4': expected a shard index 0 ... 3" \
  env JOB_COMPLETION_INDEX=4 "$shard" "$scene" --shards 4 --spp "$spp" --out "$work/bad"
expect_failure "\$SLURM_ARRAY_TASK_ID = 'x'" \
  env SLURM_ARRAY_TASK_ID=x "$shard" "$scene" --shards 4 --spp "$spp" --out "$work/bad"
expect_failure "--shards 0: expected a whole number of at least 1" \
  "$shard" "$scene" --index 0 --shards 0 --spp "$spp" --out "$work/bad"
expect_failure "--shard 3/4" "$shard" "$scene" --index 3 --shards 4 --spp 2 --out "$work/bad"
[[ ! -e $work/bad/shard-0-of-4.exr && ! -e $work/bad/shard-3-of-4.exr ]] || fail "a refused shard wrote a file"

step "merge.sh: a missing shard is named, nothing is written; --allow-missing merges the rest"
mkdir -p "$work/gap"
cp "$work/k8s/shard-0-of-4.exr" "$work/k8s/shard-1-of-4.exr" "$work/k8s/shard-3-of-4.exr" "$work/gap/"
expect_failure "1 of 4 shards missing: $work/gap/shard-2-of-4.exr" "$merge" --shards 4 --out "$work/gap"
[[ ! -e $work/gap/frame.exr ]] || fail "merge.sh wrote a frame with a shard missing"
"$merge" --shards 4 --out "$work/gap" --allow-missing
[[ -f $work/gap/frame.exr ]] || fail "merge.sh --allow-missing wrote no frame"

step "local.sh: one process per device, then the merge"
devices=${device:-0},${device:-0}
"$local" "$scene" --spp "$spp" --seed "$seed" --out "$work/local" --devices "$devices" --shards 4 -- "${size[@]}"
expect_equals_single "$work/local/frame.exr"

step "local.sh: a failed shard is named and nothing is merged"
cat >"$work/flaky-vkrt" <<FLAKY
#!/bin/sh
case " \$* " in *" 2/4 "*) echo "flaky-vkrt: failing shard 2 on purpose" >&2; exit 3 ;; esac
exec "$vkrt" "\$@"
FLAKY
chmod +x "$work/flaky-vkrt"
expect_failure "shard 2 (exit 3, $work/flaky/logs/shard-2-of-4.log) failed" \
  env VKRT="$work/flaky-vkrt" "$local" "$scene" --spp "$spp" --seed "$seed" --out "$work/flaky" \
  --devices "$devices" --shards 4 -- "${size[@]}"
[[ ! -e $work/flaky/frame.exr ]] || fail "local.sh merged although a shard failed"
grep -q "failing shard 2 on purpose" "$work/flaky/logs/shard-2-of-4.log" || fail "the failed shard's log lacks its error"

echo "farm scripts: all checks passed" >&2

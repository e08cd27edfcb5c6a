#!/usr/bin/env bash
# The Slurm farm on a real single-node Slurm (docs/farm.md): starts one
# (tools/slurm/local-cluster.sh, in a temporary folder, stopped by its PIDs on
# any exit), submits a 4-task array plus its chained merge with
# tools/slurm/submit.sh, and checks the merged frame against a single-process
# render of the same samples. Then a shard that fails must cancel the merge
# (--kill-on-invalid-dep), and re-running that one shard and the merge
# (--tasks) must give the same frame.
#   slurm_test.sh VKRT SOURCE_DIR        exit 77 (skipped) when not root
set -euo pipefail
vkrt=$1 root=$2
if [[ $(id -u) -ne 0 ]]; then
  echo "skipped: a local Slurm cluster needs root (munged runs as user munge, slurmd as root)" >&2
  exit 77
fi
source "$root/tests/farm/farm_test_lib.sh"
submit=$root/tools/slurm/submit.sh cluster=$work/cluster

step "starting a single-node Slurm cluster in $cluster"
cleanup_steps+=("'$root/tools/slurm/local-cluster.sh' stop '$cluster'")
started=$(date +%s.%N)
chmod 0755 "$work" # munged runs as user munge and must reach its socket in $cluster
exports=$("$root/tools/slurm/local-cluster.sh" start "$cluster") || fail "the Slurm cluster did not start"
eval "$exports"
echo "node idle after $(awk "BEGIN { printf \"%.1f\", $(date +%s.%N) - $started }") s" >&2
render_single

# The job's state; for an array, its tasks' states, each once.
job_state() { scontrol show job "$1" -o | sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p' | sort -u | paste -sd ' '; }
job_id() { awk -v kind="$1" '$1 == kind { print $2 }' <<<"$2"; }

step "a 4-task array and its merge"
ids=$("$submit" "$scene" --shards 4 --spp "$spp" --seed "$seed" --out "$work/run" --wait -- "${size[@]}" \
  "${device_args[@]}") || fail "submit.sh --wait failed; logs: $(tail -n 5 "$work"/run/logs/*.log)"
for i in 0 1 2 3; do
  [[ -f $work/run/shard-$i-of-4.exr ]] || fail "array task $i wrote no shard"
  grep -q "shard $i of 4 (\$SLURM_ARRAY_TASK_ID)" "$work/run/logs/shard-$i-of-4.log" ||
    fail "task $i did not take its index from SLURM_ARRAY_TASK_ID"
done
array_state=$(job_state "$(job_id shards "$ids")")
[[ $array_state == COMPLETED ]] || fail "the array job's tasks are $array_state, expected COMPLETED"
expect_equals_single "$work/run/frame.exr"

step "a failed shard cancels the merge instead of leaving it pending"
cat >"$work/flaky-vkrt" <<FLAKY
#!/bin/sh
[ "\${SLURM_ARRAY_TASK_ID:-}" = 2 ] && { echo "flaky-vkrt: failing task 2 on purpose" >&2; exit 3; }
exec "$vkrt" "\$@"
FLAKY
chmod +x "$work/flaky-vkrt"
status=0
ids=$(VKRT=$work/flaky-vkrt "$submit" "$scene" --shards 4 --spp "$spp" --seed "$seed" --out "$work/retry" --wait \
  -- "${size[@]}" "${device_args[@]}") || status=$?
((status == 1)) || fail "submit.sh --wait returned $status with a failed shard (expected 1)"
merge_state=$(job_state "$(job_id merge "$ids")")
[[ $merge_state == CANCELLED ]] || fail "the merge job is $merge_state, expected CANCELLED"
[[ -z $(squeue -h) ]] || fail "jobs left in the queue: $(squeue -h)"
[[ ! -e $work/retry/frame.exr && ! -e $work/retry/shard-2-of-4.exr ]] || fail "files written by a failed render"
for i in 0 1 3; do [[ -f $work/retry/shard-$i-of-4.exr ]] || fail "shard $i missing although it succeeded"; done

step "re-running the failed shard, then the merge"
"$submit" "$scene" --shards 4 --spp "$spp" --seed "$seed" --out "$work/retry" --tasks 2 --wait \
  -- "${size[@]}" "${device_args[@]}" >/dev/null || fail "re-running shard 2 failed: $(cat "$work"/retry/logs/*.log)"
expect_equals_single "$work/retry/frame.exr"

step "bad submissions are refused before anything is queued"
expect_failure "--tasks 4: task 4 is not a shard of --shards 4" \
  "$submit" "$scene" --shards 4 --spp "$spp" --out "$work/bad" --tasks 4
expect_failure "--shards 0/4" "$submit" "$scene" --shards 0/4 --spp "$spp" --out "$work/bad"
expect_failure "scene $work/none.toml: no such file" "$submit" "$work/none.toml" --shards 4 --spp "$spp" --out "$work/bad"
printf '[camera]\nfov = "wide"\n' >"$work/broken.toml"
expect_failure "broken.toml:1:1: camera: missing required key" "$submit" "$work/broken.toml" --shards 4 --spp "$spp" --out "$work/bad"
[[ -z $(squeue -h) ]] || fail "a refused submission queued jobs: $(squeue -h)"

echo "slurm: all checks passed" >&2

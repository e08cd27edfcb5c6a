#!/usr/bin/env bash
# A farm on one machine (docs/farm.md): renders the shards of a frame as local
# processes, one per device, then merges them.
#
#   tools/farm/local.sh SCENE --spp S --out DIR [--devices LIST] [--shards N]
#                       [--jobs J] [--seed K] [-- vkrt render options]
#
#   --devices LIST  comma-separated `vkrt devices` indices or names, e.g. 0,1;
#                   default: the default device, once
#   --shards N      shards of the frame (default: one per device)
#   --jobs J        processes at once (default: one per device); process k
#                   renders on device k mod D the shards I with I mod J = k,
#                   one after the other
# Shards go to DIR/shard-I-of-N.exr (tools/farm/shard.sh), logs to DIR/logs/,
# the merged frame to DIR/frame.exr (tools/farm/merge.sh). When a shard fails
# nothing is merged and the exit status is 1; running the same command again
# renders every shard again (shard files are replaced atomically).
set -euo pipefail

usage() {
  echo "usage: tools/farm/local.sh SCENE --spp S --out DIR [--devices LIST] [--shards N] [--jobs J] [--seed K] [-- vkrt render options]" >&2
  exit 2
}

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
source "$here/common.sh"
scene="" spp="" out="" devices="" shards="" jobs="" seed=1
extra=()
while (($#)); do
  case $1 in
    --spp | --out | --devices | --shards | --jobs | --seed)
      (($# >= 2)) || fail "$1 needs a value"
      case $1 in
        --spp) spp=$2 ;; --out) out=$2 ;; --devices) devices=$2 ;;
        --shards) shards=$2 ;; --jobs) jobs=$2 ;; --seed) seed=$2 ;;
      esac
      shift 2 ;;
    --) shift; extra=("$@"); break ;;
    -h | --help) usage ;;
    -*) fail "unknown option $1 (options after -- go to vkrt render)" ;;
    *) [[ -z $scene ]] || fail "more than one scene given ('$scene' and '$1')"; scene=$1; shift ;;
  esac
done
[[ -n $scene && -n $spp && -n $out ]] || usage
[[ -f $scene ]] || fail "scene $scene: no such file"

device_list=("")
if [[ -n $devices ]]; then
  IFS=, read -r -a device_list <<<"$devices"
  for device in "${device_list[@]}"; do [[ -n $device ]] || fail "--devices $devices: an empty device name"; done
fi
shards=${shards:-${#device_list[@]}}
jobs=${jobs:-${#device_list[@]}}
spp=$(count --spp "$spp")
shards=$(count --shards "$shards")
jobs=$(count --jobs "$jobs")
((shards <= spp)) || fail "--shards $shards of --spp $spp would leave some shards without samples"
((jobs <= shards)) || jobs=$shards

mkdir -p "$out/logs"
stop_file=$out/logs/local.stop
rm -f "$out"/logs/shard-*-of-"$shards".status "$stop_file"

# Process k: its device, then its shards one after the other; each shard's
# exit status goes to a file, since a background subshell's own is lost.
run_slot() {
  local k=$1 device=${device_list[$(($1 % ${#device_list[@]}))]} i status
  for ((i = k; i < shards; i += jobs)); do
    [[ ! -e $stop_file ]] || break
    status=0
    "$here/shard.sh" "$scene" --index "$i" --shards "$shards" --spp "$spp" --seed "$seed" --out "$out" \
      ${device:+--device "$device"} -- "${extra[@]}" >"$out/logs/shard-$i-of-$shards.log" 2>&1 || status=$?
    echo "$status" >"$out/logs/shard-$i-of-$shards.status"
  done
}

started=$(date +%s.%N)
pids=()
for ((k = 0; k < jobs; ++k)); do
  run_slot "$k" &
  pids+=($!)
done
# Ctrl-C or TERM stops every shard: SIGINT to each running vkrt (the slots'
# children; shard.sh execs vkrt), which writes the samples it has.
stop_shards() {
  local list=${pids[*]}
  touch "$stop_file"
  pkill -INT -P "${list// /,}" 2>/dev/null || true
  wait
  echo "local.sh: stopped; nothing merged (interrupted shards can be merged with tools/farm/merge.sh --allow-missing)" >&2
  exit 130
}
trap stop_shards INT TERM
wait "${pids[@]}"
trap - INT TERM

failed=()
for ((i = 0; i < shards; ++i)); do
  status=$(cat "$out/logs/shard-$i-of-$shards.status" 2>/dev/null || echo missing)
  [[ $status == 0 ]] || failed+=("$i (exit $status, $out/logs/shard-$i-of-$shards.log)")
done
if ((${#failed[@]})); then
  printf 'local.sh: error: shard %s failed\n' "${failed[@]}" >&2
  echo "local.sh: nothing merged" >&2
  exit 1
fi
echo "local.sh: $shards shards on ${#device_list[@]} device(s), $jobs at once, in $(awk "BEGIN { printf \"%.2f\", $(date +%s.%N) - $started }") s" >&2
exec "$here/merge.sh" --shards "$shards" --out "$out"

# Shared by the farm's script tests (sourced): a temporary folder removed on
# exit, a small scene, a single-process render to hold shards against, and
# checks that fail the test with a message.
# Expects: vkrt=<executable>, root=<source folder>.

work=$(mktemp -d "${TMPDIR:-/tmp}/vkrt-farm-test.XXXXXX")
cleanup_steps=()
cleanup() {
  local step
  for step in "${cleanup_steps[@]}"; do eval "$step" || true; done
  rm -rf "$work"
}
trap cleanup EXIT

scene=$root/scenes/validation/diffuse-box.toml
size=(--width 32 --height 24)
spp=16 seed=5
device=${VKRT_TEST_DEVICE:-}
device_args=()
[[ -z $device ]] || device_args=(--device "$device")
export VKRT=$vkrt VKRT_CACHE_DIR=$work/cache

fail() {
  echo "FAILED: $*" >&2
  exit 1
}
step() { echo "--- $*" >&2; }

# The one-process render of the same samples (seed, spp, size) as every sharded one.
render_single() {
  "$vkrt" render "$scene" --spp "$spp" --seed "$seed" --variance "${size[@]}" "${device_args[@]}" -o "$work/single.exr"
}

# The merged frame equals the single run to float rounding: relMSE below
# 1e-10, where the sampling noise of 16 spp is many orders of magnitude larger.
expect_equals_single() {
  local frame=$1 report
  [[ -f $frame ]] || fail "no merged frame $frame"
  report=$("$vkrt" compare "$frame" "$work/single.exr" --max-relmse 1e-10) ||
    fail "$frame differs from the single-process render:"$'\n'"$report"
  echo "$report" | grep -E 'relMSE|max' >&2
}

# Runs a command that must fail with a message containing `expected`.
expect_failure() {
  local expected=$1 output status=0
  shift
  output=$("$@" 2>&1) || status=$?
  ((status != 0)) || fail "expected '$*' to fail, it succeeded:"$'\n'"$output"
  [[ $output == *"$expected"* ]] || fail "'$*' failed without saying '$expected':"$'\n'"$output"
}

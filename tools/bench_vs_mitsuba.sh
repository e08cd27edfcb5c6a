#!/usr/bin/env bash
# vkrt against Mitsuba 3 on the same scenes: efficiency (1 / (MSE x whole-process
# time)), steady-state samples/s, 64-spp latency and start-up, several runs,
# medians and ratios, as Markdown. All options are tools/bench_vs_mitsuba.py's:
#   tools/bench_vs_mitsuba.sh [--runs 3] [--spp 128] [--scenes A.toml ...] [--quick] [--help]
# env: VKRT (vkrt binary, default build/vkrt), DRJIT_LIBLLVM_PATH (libLLVM >= 16
# for Mitsuba's llvm_ad_rgb; found automatically when Debian's libllvm19 is installed).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
python=$root/.venv-mitsuba/bin/python
if [[ ! -x $python ]] || ! "$python" -c 'import mitsuba, numpy' 2>/dev/null; then
  cat >&2 <<MSG
bench_vs_mitsuba: error: no usable Mitsuba environment at $root/.venv-mitsuba.
Create it once (from $root) with
    python3 -m venv .venv-mitsuba && .venv-mitsuba/bin/pip install -r tools/requirements-mitsuba.txt
(tools/make_reference.py does the same on its first render).
For the fast llvm_ad_rgb variant also: apt-get install libllvm19
MSG
  exit 2
fi
exec "$python" "$root/tools/bench_vs_mitsuba.py" "$@"

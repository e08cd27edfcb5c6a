#!/usr/bin/env python3
"""Where a scene's render kernel gets its size once every call is inlined.

lavapipe inlines every function call, and its compile time grows far faster
than the inlined size (docs/performance.md, "Staged kernels"), so what costs
the first frame is a function's size times the number of copies of it the
kernel's call sites make. This compiles a scene's kernel with `vkrt info`
(into an empty SPIR-V cache), disassembles it (spirv-dis, Debian's
spirv-tools) and prints, for the functions that contribute most:

  own x copies   the instructions of its own body times its inlined copies
  inlined        its size with every callee inlined, per copy

Usage: tools/kernel_size.py SCENE [--vkrt build/vkrt] [--top 30] [--json FILE]
       [-- extra vkrt info options, e.g. --uber]
"""
import argparse
import collections
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile


def disassemble(spv):
    if shutil.which("spirv-dis") is None:
        sys.exit("kernel_size.py: spirv-dis not found (apt install spirv-tools)")
    return subprocess.run(["spirv-dis", "--no-header", spv], capture_output=True, text=True, check=True).stdout


def functions_of(text):
    """Each function's own instruction count and the functions it calls."""
    names = dict(re.findall(r'OpName (%\S+) "([^"]*)"', text))
    funcs, current = {}, None
    for line in text.splitlines():
        start = re.match(r"\s*(%\S+) = OpFunction ", line)
        if start:
            current = start.group(1)
            funcs[current] = {"own": 0, "calls": collections.Counter()}
            continue
        if current is None:
            continue
        if "OpFunctionEnd" in line:
            current = None
            continue
        funcs[current]["own"] += 1
        call = re.search(r"OpFunctionCall %\S+ (%\S+)", line)
        if call:
            funcs[current]["calls"][call.group(1)] += 1
    entry = re.search(r"OpEntryPoint \w+ (%\S+)", text).group(1)
    return funcs, names, entry


def inlined_sizes(funcs, entry):
    """Copies of each function in the fully inlined entry point, and each one's inlined size."""
    order, seen = [], set()

    def visit(f):  # post-order: callees first
        if f in seen:
            return
        seen.add(f)
        for callee in funcs[f]["calls"]:
            visit(callee)
        order.append(f)

    visit(entry)
    inlined = {}
    for f in order:
        inlined[f] = funcs[f]["own"] + sum(inlined[c] * k for c, k in funcs[f]["calls"].items())
    copies = collections.Counter({entry: 1})
    for f in reversed(order):  # callers before callees
        for callee, k in funcs[f]["calls"].items():
            copies[callee] += copies[f] * k
    return order, copies, inlined


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scene")
    parser.add_argument("--vkrt", default="build/vkrt")
    parser.add_argument("--top", type=int, default=30)
    parser.add_argument("--json", help="also write the table as JSON here")
    args, extra = parser.parse_known_args()
    args.extra = [a for a in extra if a != "--"]  # more `vkrt info` options, after --
    with tempfile.TemporaryDirectory(prefix="kernel-size-") as cache:
        info_json = os.path.join(cache, "info.json")
        env = dict(os.environ, VKRT_CACHE_DIR=cache)
        run = subprocess.run([args.vkrt, "info", args.scene, "--json", info_json, *args.extra], env=env,
                             capture_output=True, text=True)
        if run.returncode != 0:
            sys.exit(f"kernel_size.py: vkrt info {args.scene} failed:\n{run.stderr}")
        with open(info_json) as f:
            kernel = json.load(f)["kernel"]
        spv = os.path.join(cache, kernel["cacheKey"] + ".spv")
        if not os.path.exists(spv):
            sys.exit(f"kernel_size.py: no SPIR-V at {spv}")
        funcs, names, entry = functions_of(disassemble(spv))
    order, copies, inlined = inlined_sizes(funcs, entry)
    label = lambda f: names.get(f, f).split("(")[0]
    rows = sorted(order, key=lambda f: funcs[f]["own"] * copies[f], reverse=True)[: args.top]
    print(f"{args.scene}: {kernel['spirvBytes']} bytes of SPIR-V, {inlined[entry]} instructions inlined")
    print(f"{'own x copies':>12} {'copies':>6} {'inlined':>8}  function")
    table = []
    for f in rows:
        table.append({"function": label(f), "own": funcs[f]["own"], "copies": copies[f], "inlined": inlined[f]})
        print(f"{funcs[f]['own'] * copies[f]:>12} {copies[f]:>6} {inlined[f]:>8}  {label(f)}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"scene": args.scene, "inlinedTotal": inlined[entry], "functions": table}, f, indent=1)


if __name__ == "__main__":
    main()

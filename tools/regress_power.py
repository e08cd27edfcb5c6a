#!/usr/bin/env python3
"""How much driver breakage does `vkrt regress` catch? Runs the suite under
injected SPIR-V faults (`vkrt regress --inject FAULT`, src/gpu/SpirvFault.h)
and, as the control, without one under other seeds (false alarms).

    tools/regress_power.py [--vkrt build/vkrt] [--faults F1,F2,...]
        [--ladder classes|quick|legal|rare|memory|rayquery|loops|none] [--accel own|driver]
        [--control-seeds N] [--filter CASE ...] [--jobs 2] [--case-timeout S] [--out DIR] [--json FILE]

Ladders: classes (each arithmetic class at 1e-2, the comparisons, NaN),
quick (FMul and Sqrt at 1e-1 ... 1e-3), legal (what a conformant driver may
do: the suite must pass every one; a failure there is a false alarm), rare
(a product off by half in 1 of 10 ... 1 of 10^6 results), memory (a
storage-buffer load or texel fetch that reads its neighbour, always or in 1
of 10 ... 10^4), rayquery (the t a ray query reports, scaled; run it with
--accel driver), loops (every loop cut after 65535 ... 100 passes of an
invocation in all), none (only the clean run and the control runs).

Each fault is one whole suite run (its kernels compile afresh: the faulty
SPIR-V is new to the driver's cache). A fault is caught when the run fails;
the table names the cases that failed, and how many instructions of the
suite's kernels the fault changes (a fault with none cannot be caught). A
clean run comes first (its SPIR-V cache is what that count reads); the
control runs use --seed-offset 1..N with no fault: every failure there, or
under a legal variation, is a false alarm. Prints a markdown table
(docs/regress.md quotes it) and optionally writes JSON.
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

ARITHMETIC = ["FMul", "FAdd", "FDiv", "Sqrt", "InverseSqrt", "Exp", "Log", "Pow", "Sin", "Cos", "Atan2", "Acos"]
LADDERS = {
    # Every arithmetic class at the target size, the comparisons and NaN handling.
    "classes": [f"scale:{c}:0.01" for c in ARITHMETIC] + ["compare:lt-le", "compare:gt-ge", "nan-minmax"],
    # A size ladder for the two commonest classes, and the comparisons.
    "quick": [f"scale:{c}:{e}" for c in ("FMul", "Sqrt") for e in ("0.1", "0.01", "0.001")]
    + ["compare:lt-le", "compare:gt-ge"],
    # What a conformant driver may do, which the suite must NOT flag: fused
    # multiply-adds where SPIR-V allows contraction, and transcendentals as far
    # off as the Vulkan specification's precision table lets them be ("Precision
    # and Operation of SPIR-V Instructions"): sin and cos to an absolute 2^-11
    # on [-pi, pi] (a relative 4.4e-4 stays within it, with lavapipe's own 1.5
    # ulp), acos and atan2 to 4096 ulp (2.4e-4 relative is 4000 ulp at most).
    "legal": ["contract", "scale:Sin:4.4e-4", "scale:Sin:-4.4e-4", "scale:Cos:4.4e-4", "scale:Cos:-4.4e-4",
              "scale:Acos:2.4e-4", "scale:Atan2:-2.4e-4"],
    # Faults in 1 of N results: an FMul off by half where a hash of its bits
    # picks it (src/gpu/SpirvFault.h), from 1 in 10 to 1 in a million.
    "rare": [f"scale:FMul:0.5:1in{n}" for n in (10, 100, 1000, 10**4, 10**5, 10**6)],
    # Memory: a storage-buffer element load that reads the next element (BVH
    # nodes, triangles, materials, texels of material textures), and a texel
    # fetch of the lat-long map one texel to the right; always, then in 1 of N.
    "memory": ["neighbour-load"] + [f"neighbour-load:1in{n}" for n in (10, 100, 1000, 10**4)]
    + ["texel-offset"] + [f"texel-offset:1in{n}" for n in (10, 100, 1000)],
    # Control flow: every loop ends once the invocation has made N passes in
    # all; N = 65535 is Mesa 22 lavapipe's real bug (docs/platform.md), the
    # calibration point.
    "loops": [f"loop-cut:{n}" for n in (65535, 10000, 1000, 100)],
    # No fault: the clean run and the --control-seeds runs only.
    "none": [],
    # Ray queries (--accel driver): the committed t the driver reports, scaled.
    "rayquery": [f"scale:RayQueryT:{e}" for e in ("0.01", "0.001", "1e-4")],
}
LEGAL = set(LADDERS["legal"])


# ---------------------------------------------------------------- census
# How many instructions each fault would change in the kernels the suite
# runs: a fault with nothing to change cannot be caught, and is reported as
# such, not as missed. The same rules as src/gpu/SpirvFault.cpp, on the clean
# SPIR-V that a run with its own VKRT_CACHE_DIR leaves there.

GLSL_NUMBERS = {"Sqrt": 31, "InverseSqrt": 32, "Exp": 27, "Log": 28, "Pow": 26, "Sin": 13, "Cos": 14,
                "Atan2": 25, "Acos": 17, "Exp2": 29, "Log2": 30, "Fma": 50}
CORE_OPCODES = {"FMul": 133, "FAdd": 129, "FSub": 131, "FDiv": 136, "RayQueryT": 6018}
COMPARE_OPCODES = {"lt-le": {184, 185, 188, 189}, "gt-ge": {186, 187, 190, 191}}
MINMAX_NUMBERS = {37, 40, 79, 80}
NO_CONTRACTION = 42


def instructions(path: Path):
    """(opcode, operand words) of each instruction of a SPIR-V file."""
    data = path.read_bytes()
    words = [int.from_bytes(data[i:i + 4], "little") for i in range(0, len(data) - 3, 4)]
    if len(words) < 5 or words[0] != 0x07230203:
        return
    at = 5
    while at < len(words):
        count = words[at] >> 16
        if count == 0:
            return
        yield words[at] & 0xFFFF, words[at + 1:at + count]
        at += count


def count_element_loads(path: Path) -> int:
    """Loads through an access chain into a storage buffer's runtime array at
    a computed index (or a chain that goes on from one): what neighbour-load
    changes."""
    types, pointers, structs, runtime_arrays, constants, int32 = set(), {}, {}, set(), {}, set()
    result_types, chains, in_function, loads = {}, set(), False, 0
    for opcode, ops in instructions(path):
        if 19 <= opcode < 39 and ops:
            types.add(ops[0])
        if opcode == 21 and len(ops) >= 2 and ops[1] == 32:
            int32.add(ops[0])
        elif opcode == 32 and len(ops) >= 3:
            pointers[ops[0]] = (ops[1], ops[2])
        elif opcode == 30 and ops:
            structs[ops[0]] = ops[1:]
        elif opcode == 29 and ops:
            runtime_arrays.add(ops[0])
        elif opcode == 43 and len(ops) == 3:
            constants[ops[1]] = ops[2]
        elif opcode == 54:
            in_function = True
        if (in_function or opcode in (43, 44, 59)) and len(ops) >= 2 and ops[0] in types:
            result_types[ops[1]] = ops[0]
        if opcode in (65, 66) and len(ops) >= 4:
            base = ops[2]
            if base in chains:
                chains.add(ops[1])
            elif len(ops) >= 5:
                storage, pointee = pointers.get(result_types.get(base), (None, None))
                members = structs.get(pointee, [])
                member = constants.get(ops[3])
                if (storage == 12 and member is not None and member < len(members)
                        and members[member] in runtime_arrays and ops[4] not in constants
                        and result_types.get(ops[4]) in int32):
                    chains.add(ops[1])
        elif opcode == 61 and len(ops) >= 3 and ops[2] in chains:
            loads += 1
    return loads


def count_loop_headers(path: Path) -> int:
    """Loop headers whose branch can go to the loop's merge block: what loop-cut changes."""
    headers, merge = 0, None
    for opcode, ops in instructions(path):
        if opcode == 246 and len(ops) >= 2:
            merge = ops[0]
            continue
        if merge is not None:
            headers += (opcode == 249 and len(ops) == 1) or (opcode == 250 and len(ops) >= 3 and merge in ops[1:3])
        merge = None
    return headers


def count_fault_sites(path: Path, fault: str) -> int:
    """The instructions `fault` would change in one module."""
    glsl_set, float32, precise, products = None, set(), set(), {}
    kind, *rest = fault.split(":")
    if kind == "neighbour-load":
        return count_element_loads(path)
    if kind == "loop-cut":
        return count_loop_headers(path)
    sites = 0
    for opcode, ops in instructions(path):
        if opcode == 11 and bytes(b for w in ops[1:] for b in w.to_bytes(4, "little")).rstrip(b"\0") == b"GLSL.std.450":
            glsl_set = ops[0]
        elif opcode == 22 and len(ops) >= 2 and ops[1] == 32:
            float32.add(ops[0])
        elif opcode == 23 and ops[1] in float32:
            float32.add(ops[0])
        elif opcode == 71 and len(ops) >= 2 and ops[1] == NO_CONTRACTION:
            precise.add(ops[0])
        elif kind == "scale" and rest and rest[0] in CORE_OPCODES:
            sites += opcode == CORE_OPCODES[rest[0]] and ops[0] in float32
        elif kind == "scale" and rest:
            sites += opcode == 12 and ops[2] == glsl_set and ops[3] == GLSL_NUMBERS[rest[0]] and ops[0] in float32
        elif kind == "compare" and rest:
            sites += opcode in COMPARE_OPCODES[rest[0]]
        elif kind == "texel-offset":
            sites += opcode == 95
        elif kind == "nan-minmax":
            sites += opcode == 12 and ops[2] == glsl_set and ops[3] in MINMAX_NUMBERS
        elif kind == "contract" and glsl_set is not None and len(ops) == 4 and ops[1] not in precise:
            if opcode == 133:
                products[ops[1]] = ops[0]
            elif opcode in (129, 131):
                sites += products.get(ops[2]) == ops[0] or (opcode == 129 and products.get(ops[3]) == ops[0])
    return sites


def census(spirv_dir: Path, faults: list[str]) -> dict[str, int]:
    modules = sorted(spirv_dir.rglob("*.spv"))
    return {fault: sum(count_fault_sites(m, fault) for m in modules) for fault in faults}


# ---------------------------------------------------------------- runs

def run_suite(args, out: Path, extra: list[str], env: dict | None = None) -> dict:
    """One `vkrt regress` run: exit status, failing cases, seconds."""
    out.mkdir(parents=True, exist_ok=True)
    command = [args.vkrt, "regress", "--jobs", str(args.jobs), "--report-dir", str(out), *extra]
    if args.accel:
        command += ["--accel", args.accel]
    if args.case_timeout:
        command += ["--case-timeout", str(args.case_timeout)]
    for case in args.filter or []:
        command += ["--filter", case]
    start = time.monotonic()
    done = subprocess.run(command, capture_output=True, text=True, env={**os.environ, **(env or {})})
    seconds = time.monotonic() - start
    if done.returncode not in (0, 4):  # 4: a case failed (src/app/ExitCodes.h)
        sys.exit(f"regress_power: {' '.join(command)} exited {done.returncode}:\n{done.stderr[-2000:]}")
    failed = []
    results = out / "results.csv"
    if results.exists():
        with results.open() as f:
            failed = [row[0] for row in csv.reader(f) if len(row) >= 2 and row[1] != "Pass"]
    return {"exit": done.returncode, "failed": failed, "seconds": round(seconds, 1)}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vkrt", default=str(ROOT / "build" / "vkrt"))
    parser.add_argument("--faults", help="comma-separated fault specs (default: the ladder)")
    parser.add_argument("--ladder", choices=sorted(LADDERS), default="classes")
    parser.add_argument("--control-seeds", type=int, default=0, help="unmodified runs with --seed-offset 1..N")
    parser.add_argument("--filter", action="append", help="only these cases (vkrt regress --filter)")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--case-timeout", type=float,
                        help="vkrt regress --case-timeout: a fault that makes a case hang (a BVH walk sent in a "
                             "circle) costs this, not the default minutes, twice")
    parser.add_argument("--accel", choices=["own", "driver"], help="traversal backend of every run (rayquery: driver)")
    parser.add_argument("--out", help="keep each run's report here (default: a temporary folder)")
    parser.add_argument("--json", help="also write the rows as JSON")
    args = parser.parse_args()
    faults = args.faults.split(",") if args.faults else LADDERS[args.ladder]
    temporary = None if args.out else tempfile.TemporaryDirectory(prefix="vkrt-power-")
    out = Path(args.out or temporary.name)

    # A clean run first, with a SPIR-V cache of its own: the control at the
    # suite's own seeds, and the kernels the census counts in.
    spirv = out / "census-spirv"
    clean = run_suite(args, out / "clean", [], {"VKRT_CACHE_DIR": str(spirv)})
    sites = census(spirv, faults)
    rows = [{"fault": "none", "caught": clean["exit"] != 0, "sites": None, **clean}]
    print(f"regress_power: clean run: {'FALSE ALARM' if clean['exit'] else 'pass'} ({clean['seconds']} s)",
          file=sys.stderr)
    for fault in faults:
        result = run_suite(args, out / fault.replace(":", "_"), ["--inject", fault])
        rows.append({"fault": fault, "caught": result["exit"] != 0, "sites": sites[fault], **result})
        verdict = ("FALSE ALARM" if rows[-1]["caught"] else "pass") if fault in LEGAL else \
            ("caught" if rows[-1]["caught"] else "MISSED")
        print(f"regress_power: {fault}: {verdict} "
              f"({len(result['failed'])} cases, {result['seconds']} s)", file=sys.stderr)
    for seed in range(1, args.control_seeds + 1):
        result = run_suite(args, out / f"control-{seed}", ["--seed-offset", str(seed)])
        rows.append({"fault": f"none (--seed-offset {seed})", "caught": result["exit"] != 0, "sites": None,
                     **result})
        print(f"regress_power: control seed {seed}: {'FALSE ALARM' if rows[-1]['caught'] else 'pass'}",
              file=sys.stderr)

    print("| fault | instructions it changes | suite | cases that failed | seconds |")
    print("| --- | ---: | --- | --- | ---: |")
    for row in rows:
        control = row["fault"].startswith("none") or row["fault"] in LEGAL
        verdict = ("false alarm" if row["caught"] else "passes") if control else \
            ("caught" if row["caught"] else "not used by the kernels" if row["sites"] == 0 else "**missed**")
        cases = ", ".join(f"`{c}`" for c in row["failed"][:6]) + (" …" if len(row["failed"]) > 6 else "")
        sites = "" if row["sites"] is None else str(row["sites"])
        failed = f"{len(row['failed'])}: {cases}" if row["failed"] else "0"
        print(f"| `{row['fault']}` | {sites} | {verdict} | {failed} | {row['seconds']} |")
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())

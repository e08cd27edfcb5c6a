#!/usr/bin/env python3
"""How much driver breakage does `vkrt regress` catch? Runs the suite under
injected SPIR-V faults (`vkrt regress --inject FAULT`, src/gpu/SpirvFault.h)
and, as the control, without one under other seeds (false alarms).

    tools/regress_power.py [--vkrt build/vkrt] [--faults F1,F2,...] [--ladder classes|quick|legal]
        [--control-seeds N] [--filter CASE ...] [--jobs 2] [--out DIR] [--json FILE]

Ladders: classes (each arithmetic class at 1e-2, the comparisons, NaN),
quick (FMul and Sqrt at 1e-1 ... 1e-3), legal (what a conformant driver may
do: the suite must pass every one; a failure there is a false alarm).

Each fault is one whole suite run (its kernels compile afresh: the faulty
SPIR-V is new to the driver's cache). A fault is caught when the run fails;
the table names the cases that failed. The control runs use --seed-offset 1..N
with no fault: every failure there is a false alarm. Prints a markdown table
(docs/regress.md quotes it) and optionally writes JSON.
"""
from __future__ import annotations

import argparse
import csv
import json
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
    "legal": ["contract", "scale:Sin:4.4e-4", "scale:Cos:-4.4e-4", "scale:Acos:2.4e-4", "scale:Atan2:-2.4e-4"],
}
LEGAL = set(LADDERS["legal"])


def run_suite(args, out: Path, extra: list[str]) -> dict:
    """One `vkrt regress` run: exit status, failing cases, seconds."""
    out.mkdir(parents=True, exist_ok=True)
    command = [args.vkrt, "regress", "--jobs", str(args.jobs), "--report-dir", str(out), *extra]
    for case in args.filter or []:
        command += ["--filter", case]
    start = time.monotonic()
    done = subprocess.run(command, capture_output=True, text=True)
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
    parser.add_argument("--out", help="keep each run's report here (default: a temporary folder)")
    parser.add_argument("--json", help="also write the rows as JSON")
    args = parser.parse_args()
    faults = args.faults.split(",") if args.faults else LADDERS[args.ladder]
    temporary = None if args.out else tempfile.TemporaryDirectory(prefix="vkrt-power-")
    out = Path(args.out or temporary.name)

    rows = []
    for fault in faults:
        result = run_suite(args, out / fault.replace(":", "_"), ["--inject", fault])
        rows.append({"fault": fault, "caught": result["exit"] != 0, **result})
        verdict = ("FALSE ALARM" if rows[-1]["caught"] else "pass") if fault in LEGAL else \
            ("caught" if rows[-1]["caught"] else "MISSED")
        print(f"regress_power: {fault}: {verdict} "
              f"({len(result['failed'])} cases, {result['seconds']} s)", file=sys.stderr)
    for seed in range(1, args.control_seeds + 1):
        result = run_suite(args, out / f"control-{seed}", ["--seed-offset", str(seed)])
        rows.append({"fault": f"none (--seed-offset {seed})", "caught": result["exit"] != 0, **result})
        print(f"regress_power: control seed {seed}: {'FALSE ALARM' if rows[-1]['caught'] else 'pass'}",
              file=sys.stderr)

    print("| fault | suite | cases that failed | seconds |")
    print("| --- | --- | --- | ---: |")
    for row in rows:
        control = row["fault"].startswith("none") or row["fault"] in LEGAL
        verdict = ("false alarm" if row["caught"] else "passes") if control else \
            ("caught" if row["caught"] else "**missed**")
        cases = ", ".join(f"`{c}`" for c in row["failed"][:6]) + (" …" if len(row["failed"]) > 6 else "")
        print(f"| `{row['fault']}` | {verdict} | {len(row['failed'])}: {cases} | {row['seconds']} |"
              if row["failed"] else f"| `{row['fault']}` | {verdict} | 0 | {row['seconds']} |")
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())

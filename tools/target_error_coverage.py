#!/usr/bin/env python3
"""Does `--target-error T` keep its promise? For every validation scene with
a reference (tests/references/validation/NAME/mean.exr, Mitsuba 3), render
SEEDS runs up to MAX spp with `--report` and `--reference`: each run's CSV
holds, at every checkpoint (1, 2, 4, ... spp), vkrt's estimated relMSE and
the true relMSE against the reference. Stop rules are then replayed on those
trajectories for each target: where would the rule have stopped, and was the
true relMSE there at most T? The oracle stops at the first checkpoint whose
true relMSE is at most T.

    tools/target_error_coverage.py [--vkrt build/vkrt] [--seeds 20] [--max-spp 4096]
        [--targets 0.03,0.01,0.003] [--scenes conductor,plastic,...] [--json out.json] [--cache DIR]

The true relMSE has the reference's own noise subtracted (its variance.exr
over reference^2 + 0.01, the relMSE's epsilon), so that a target below the
reference's noise is still judged fairly. Prints, per rule and target: the
share of runs whose true relMSE at the stop is at most T (the promise is 95 %),
the median spp, and the median ratio of spp to the oracle's. Runs are cached
in --cache (default: a temporary directory) by scene, seed and max spp.
"""
from __future__ import annotations

import argparse
import csv
import json
import math
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
EPSILON = 0.01  # src/render/ErrorMetrics.h: kRelMseEpsilon
try:
    import vkrt  # noqa: E402
except ImportError:
    sys.path.insert(0, str(ROOT / "build" / "python"))
    import vkrt  # noqa: E402


def reference_noise(name: str) -> float:
    """The reference's own relMSE: mean of its variance over reference^2 + epsilon."""
    import numpy as np
    folder = ROOT / "tests" / "references" / "validation" / name
    mean, _ = vkrt.read_exr(folder / "mean.exr")
    variance_file = folder / "variance.exr"
    if not variance_file.exists():
        return 0.0
    var, _ = vkrt.read_exr(variance_file)
    m, v = mean["image"].astype(np.float64), var["image"].astype(np.float64)
    finite = np.isfinite(m) & np.isfinite(v)
    return float(np.mean(v[finite] / (m[finite] ** 2 + EPSILON)))


def trajectory(args, name: str, seed: int, cache: Path) -> list[dict]:
    """One run's checkpoints: spp, estimated and true relMSE (reference noise subtracted)."""
    report = cache / f"{name}-seed{seed}-max{args.max_spp}.csv"
    if not report.exists():
        scene = ROOT / "scenes" / "validation" / f"{name}.toml"
        reference = ROOT / "tests" / "references" / "validation" / name / "mean.exr"
        command = [args.vkrt, "render", str(scene), "--spp", str(args.max_spp), "--seed", str(seed),
                   "--report", str(report), "--reference", str(reference), "-o", "/dev/null"]
        done = subprocess.run(command, capture_output=True, text=True)
        if done.returncode != 0:
            sys.exit(f"target_error_coverage: {' '.join(command)} failed:\n{done.stderr}")
    rows = []
    with report.open() as f:
        lines = [line for line in f if not line.startswith("#")]
    for row in csv.DictReader(lines):
        rows.append({"spp": int(row["spp"]), "estimated": float(row["est_relmse"]),
                     "true": float(row["relmse"])})
    return rows


# --------------------------------------------------------------- stop rules
# Each rule sees the checkpoints up to the current one (estimates only, never
# the true error) and says whether to stop there.

def rule_point_estimate(history, target):
    """Today's rule: the estimate below the target."""
    return history[-1]["estimated"] < target


def rule_settled(history, target, min_spp=16, growth=1.25):
    """The estimate below the target, at least min_spp, and the per-sample
    variance (estimate x spp) no longer growing: at most `growth` times the
    previous checkpoint's (a heavy tail still being found makes it grow)."""
    now = history[-1]
    if now["spp"] < min_spp or len(history) < 2 or not now["estimated"] < target:
        return False
    before = history[-2]
    return now["estimated"] * now["spp"] <= growth * before["estimated"] * before["spp"]


RULES = {
    "estimate < T (today)": rule_point_estimate,
    "settled, >= 16 spp": rule_settled,
    "settled, >= 32 spp": lambda h, t: rule_settled(h, t, min_spp=32),
}


def stop_of(rows, rule, target):
    for i in range(len(rows)):
        if rule(rows[: i + 1], target):
            return rows[i]
    return rows[-1]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vkrt", default=str(ROOT / "build" / "vkrt"))
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--max-spp", type=int, default=4096)
    parser.add_argument("--targets", default="0.03,0.01,0.003")
    parser.add_argument("--scenes", help="comma-separated names (default: every scene with a reference)")
    parser.add_argument("--cache", help="keep the runs' reports here")
    parser.add_argument("--json", help="also write the table as JSON")
    args = parser.parse_args()
    targets = [float(t) for t in args.targets.split(",")]
    references = ROOT / "tests" / "references" / "validation"
    names = args.scenes.split(",") if args.scenes else sorted(
        p.name for p in references.iterdir() if (p / "mean.exr").exists()
        and (ROOT / "scenes" / "validation" / f"{p.name}.toml").exists())
    temporary = None if args.cache else tempfile.TemporaryDirectory(prefix="vkrt-coverage-")
    cache = Path(args.cache or temporary.name)
    cache.mkdir(parents=True, exist_ok=True)

    runs = {}
    for name in names:
        noise = reference_noise(name)
        runs[name] = []
        for seed in range(args.seeds):
            rows = trajectory(args, name, seed, cache)
            for row in rows:
                row["true"] = max(0.0, row["true"] - noise)
            runs[name].append(rows)

    table = []
    for rule_name, rule in RULES.items():
        for target in targets:
            met, spps, ratios = 0, [], []
            for name in names:
                for rows in runs[name]:
                    stop = stop_of(rows, rule, target)
                    oracle = next((r for r in rows if r["true"] <= target), rows[-1])
                    met += stop["true"] <= target
                    spps.append(stop["spp"])
                    ratios.append(stop["spp"] / oracle["spp"])
            count = len(spps)
            table.append({"rule": rule_name, "target": target, "runs": count, "met": met,
                          "share": met / count, "medianSpp": statistics.median(spps),
                          "medianSppOverOracle": statistics.median(ratios)})
    print(f"{len(names)} scenes x {args.seeds} seeds, up to {args.max_spp} spp")
    print(f"{'rule':<26} {'target':>8} {'met':>9} {'share':>7} {'median spp':>11} {'spp/oracle':>11}")
    for row in table:
        print(f"{row['rule']:<26} {row['target']:>8g} {row['met']:>4}/{row['runs']:<4} {row['share']:>7.1%} "
              f"{row['medianSpp']:>11g} {row['medianSppOverOracle']:>11.2f}")
    if args.json:
        Path(args.json).write_text(json.dumps({"scenes": names, "seeds": args.seeds, "rows": table}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""Does `--target-error T` keep its promise (a true relMSE <= T in at least 95 % of runs)?

For every validation scene with a reference (tests/references/validation/NAME/
mean.exr, Mitsuba 3), SEEDS runs of each target T:

  vkrt render SCENE --target-error T --spp MAX --seed S --report R --reference REF

The report's last row is the stop: its spp and the true relMSE there. A run
that reaches MAX spp first did not stop on the target and is counted apart
(`capped`). The same seeds are also rendered once to MAX spp with a report at
every power of two: the oracle, the fewest spp whose true relMSE meets T
(interpolated as 1 / spp between the checkpoints around it), is what the rule's
cost is measured against; and --replay replays rules on those trajectories
(estimates only) without running vkrt again.

    tools/target_error_coverage.py [--vkrt build/vkrt] [--seeds 20] [--max-spp 1024]
        [--targets 0.03,0.01,0.003] [--scenes conductor,plastic,...] [--sampler auto] [--replay]
        [--json out.json] [--cache DIR] [--verbose]

The true relMSE has the reference's own noise subtracted (its variance.exr
over reference^2 + 0.01, the relMSE's epsilon), so that a target near the
reference's noise is still judged fairly. Prints, per target (and rule): runs
that met it of those that stopped on it, the share, runs capped, the median
spp and the median ratio of spp to the oracle's. Runs are cached in --cache
(default: a temporary directory) by scene, seed, target and MAX spp.
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


def run_report(args, name: str, seed: int, report: Path, extra: list[str]) -> list[dict]:
    """Renders (unless the report is cached) and returns its rows."""
    if not report.exists():
        scene = ROOT / "scenes" / "validation" / f"{name}.toml"
        reference = ROOT / "tests" / "references" / "validation" / name / "mean.exr"
        command = [args.vkrt, "render", str(scene), "--spp", str(args.max_spp), "--seed", str(seed),
                   "--sampler", args.sampler, "--report", str(report), "--reference", str(reference),
                   "-o", "/dev/null", *extra]
        done = subprocess.run(command, capture_output=True, text=True)
        if done.returncode != 0:
            sys.exit(f"target_error_coverage: {' '.join(command)} failed:\n{done.stderr}")
    with report.open() as f:
        lines = [line for line in f if not line.startswith("#")]
    return [{"spp": int(row["spp"]), "estimated": float(row["est_relmse"]),
             "upper": float(row["est_relmse_upper"]), "dof": float(row["est_dof"]),
             "true": float(row["relmse"])} for row in csv.DictReader(lines)]


def oracle_spp(rows: list[dict], target: float) -> float:
    """The fewest spp whose true relMSE meets the target, interpolated as 1 / spp
    between the checkpoints around the first that meets it; the last spp if none does."""
    for before, after in zip([None] + rows[:-1], rows):
        if after["true"] <= target:
            if before is None or not before["true"] > target:
                return after["spp"]
            # true ~ c / spp^k between the two checkpoints
            slope = math.log(after["spp"] / before["spp"]) / math.log(before["true"] / max(after["true"], 1e-30))
            return min(after["spp"], before["spp"] * (before["true"] / target) ** slope)
    return rows[-1]["spp"]


# --------------------------------------------------------------- replayed rules
# Each sees the checkpoints up to the current one (estimates only, never the
# true error) and says whether to stop there. Checkpoints are powers of two
# here; vkrt's own rule also looks where it expects the target met.

def rule_point_estimate(history, target):
    """The estimate below the target."""
    return history[-1]["estimated"] < target


def rule_upper_bound(history, target):
    """vkrt's rule: the estimate's upper confidence bound below the target."""
    return history[-1]["upper"] < target


RULES = {
    "estimate < T": rule_point_estimate,
    "upper bound < T": rule_upper_bound,
}


def replayed_stop(rows, rule, target):
    """The checkpoint where the rule stops, or None where it never does (the spp cap)."""
    for i in range(len(rows)):
        if rule(rows[: i + 1], target):
            return rows[i]
    return None


def summarize(label, target, stops):
    """stops: (name, seed, stop row or None, oracle spp) per run."""
    met, capped, spps, ratios, missed = 0, 0, [], [], []
    for name, seed, stop, oracle in stops:
        if stop is None:
            capped += 1
            continue
        met += stop["true"] <= target
        if stop["true"] > target:
            missed.append(f"{name}/{seed}@{stop['spp']}:{stop['true'] / target:.2f}T")
        spps.append(stop["spp"])
        ratios.append(stop["spp"] / oracle)
    count = len(spps)
    return {"rule": label, "target": target, "stopped": count, "capped": capped, "met": met,
            "share": met / count if count else math.nan,
            "medianSpp": statistics.median(spps) if spps else math.nan,
            "medianSppOverOracle": statistics.median(ratios) if ratios else math.nan, "missed": missed}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vkrt", default=str(ROOT / "build" / "vkrt"))
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--max-spp", type=int, default=1024)
    parser.add_argument("--targets", default="0.03,0.01,0.003")
    parser.add_argument("--scenes", help="comma-separated names (default: every scene with a reference)")
    parser.add_argument("--sampler", default="auto", choices=["auto", "sobol", "independent"],
                        help="vkrt's --sampler (auto: Sobol', whose 8 batches give the estimate)")
    parser.add_argument("--replay", action="store_true", help="also replay rules on the power-of-two trajectories")
    parser.add_argument("--cache", help="keep the runs' reports here")
    parser.add_argument("--json", help="also write the table as JSON")
    parser.add_argument("--verbose", action="store_true", help="name the runs that missed the target")
    args = parser.parse_args()
    targets = [float(t) for t in args.targets.split(",")]
    references = ROOT / "tests" / "references" / "validation"
    names = args.scenes.split(",") if args.scenes else sorted(
        p.name for p in references.iterdir() if (p / "mean.exr").exists()
        and (ROOT / "scenes" / "validation" / f"{p.name}.toml").exists())
    temporary = None if args.cache else tempfile.TemporaryDirectory(prefix="vkrt-coverage-")
    cache = Path(args.cache or temporary.name)
    cache.mkdir(parents=True, exist_ok=True)

    def denoised(rows, noise):
        for row in rows:
            row["true"] = max(0.0, row["true"] - noise)
        return rows

    sampler = "" if args.sampler == "auto" else f"-{args.sampler}"  # in the cache's file names
    trajectories, direct = {}, {}
    for name in names:
        noise = reference_noise(name)
        for seed in range(args.seeds):
            trajectories[name, seed] = denoised(
                run_report(args, name, seed, cache / f"{name}-seed{seed}-max{args.max_spp}{sampler}.csv", []), noise)
            for target in targets:
                report = cache / f"{name}-seed{seed}-target{target:g}-max{args.max_spp}{sampler}.csv"
                rows = denoised(run_report(args, name, seed, report, ["--target-error", str(target)]), noise)
                # The last row is the stop; at the cap with the bound still above the target it is not one.
                last = rows[-1]
                direct[name, seed, target] = last if last["upper"] < target else None

    table = []
    for target in targets:
        table.append(summarize("vkrt --target-error", target, [
            (name, seed, direct[name, seed, target], oracle_spp(trajectories[name, seed], target))
            for name in names for seed in range(args.seeds)]))
    if args.replay:
        for label, rule in RULES.items():
            for target in targets:
                table.append(summarize(f"replayed: {label}", target, [
                    (name, seed, replayed_stop(rows, rule, target), oracle_spp(rows, target))
                    for (name, seed), rows in trajectories.items()]))

    print(f"{len(names)} scenes x {args.seeds} seeds, up to {args.max_spp} spp, sampler {args.sampler}")
    print(f"{'rule':<28} {'target':>7} {'met/stopped':>12} {'share':>7} {'capped':>7} {'median spp':>11} "
          f"{'spp/oracle':>11}")
    for row in table:
        print(f"{row['rule']:<28} {row['target']:>7g} {row['met']:>5}/{row['stopped']:<6} {row['share']:>7.1%} "
              f"{row['capped']:>7} {row['medianSpp']:>11g} {row['medianSppOverOracle']:>11.2f}")
        if args.verbose and row["missed"]:
            print("    missed: " + " ".join(row["missed"]))
    if args.json:
        Path(args.json).write_text(json.dumps({"scenes": names, "seeds": args.seeds, "maxSpp": args.max_spp,
                                               "sampler": args.sampler, "rows": table}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""Interleaved A/B benchmark of vkrt builds (or shader trees) on the validation scenes.

Each round renders every scene with every build, in alternating order (the
order reverses every other round), with seed 100 + round, and measures:
vkrt's own samples/s, the whole-process wall time, and the MSE against the
committed Mitsuba reference (tests/references/validation/<scene>/mean.exr,
`vkrt compare`'s MSE, through vkrt's Python module). It prints a Markdown table of medians with
efficiency = 1 / (MSE x whole-process seconds) and its ratio to the first build.

A build is NAME=BINARY, or NAME=BINARY@SHADER_DIR to run a binary on another
shader tree (VKRT_SHADER_DIR), which is how timing-only shader edits are
compared without rebuilding:

    tools/bench_ab.py before=old/build/vkrt after=build/vkrt \\
        --scenes glass,mirror,lights --rounds 3 --spp 256

Extra arguments for every render go after `--`, e.g. `-- --sampler independent`.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
try:
    import vkrt  # reads and compares the images (docs/python.md)
except ImportError:  # a build tree: its package
    sys.path.insert(0, str(REPO / "build" / "python"))
    import vkrt


def parse_build(text):
    if "=" not in text:
        sys.exit(f"bench_ab: error: build '{text}': expected NAME=BINARY[@SHADER_DIR]")
    name, rest = text.split("=", 1)
    binary, _, shaders = rest.partition("@")
    if not os.access(binary, os.X_OK):
        sys.exit(f"bench_ab: error: build '{name}': {binary} is not an executable")
    if shaders and not (Path(shaders) / "kernels").is_dir():
        sys.exit(f"bench_ab: error: build '{name}': {shaders} has no kernels/ folder")
    return name, binary, shaders


def render(build, scene, spp, seed, out, extra):
    """vkrt's samples/s (its --json machine output) and the whole process's wall time."""
    name, binary, shaders = build
    env = dict(os.environ)
    if shaders:
        env["VKRT_SHADER_DIR"] = shaders
    facts = out + ".json"
    start = time.monotonic()
    result = subprocess.run([binary, "render", str(scene), "--spp", str(spp), "--seed", str(seed), "-o", out,
                             "--json", facts] + extra, capture_output=True, text=True, env=env)
    wall = time.monotonic() - start
    if result.returncode != 0:
        sys.exit(f"bench_ab: error: build '{name}' failed on {scene}:\n{result.stdout}{result.stderr}")
    return json.loads(Path(facts).read_text())["samplesPerSecond"], wall


def mse_against_reference(image, reference):
    """The MSE `vkrt compare` reports."""
    return vkrt.measure_error(vkrt.read_exr(image)[0]["image"], vkrt.read_exr(reference)[0]["image"])["mse"]


def main(argv):
    extra = []
    if "--" in argv:
        extra = argv[argv.index("--") + 1:]
        argv = argv[:argv.index("--")]
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("builds", nargs="+", help="NAME=BINARY[@SHADER_DIR], the first is the baseline")
    parser.add_argument("--scenes", default="glass,mirror,diffuse-box,lights,environment-sky",
                        help="validation scene names, comma-separated")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--spp", type=int, default=256)
    args = parser.parse_args(argv)
    if args.rounds < 1 or args.spp < 1:
        parser.error("--rounds and --spp must be at least 1")
    builds = [parse_build(b) for b in args.builds]
    scenes = [s for s in args.scenes.split(",") if s]
    for scene in scenes:
        if not (REPO / "scenes/validation" / f"{scene}.toml").is_file():
            parser.error(f"--scenes: no scenes/validation/{scene}.toml")
        if not (REPO / "tests/references/validation" / scene / "mean.exr").is_file():
            parser.error(f"--scenes: {scene} has no reference in tests/references/validation/")

    results = {}
    with tempfile.TemporaryDirectory(prefix="bench_ab-") as tmp:
        for round_index in range(args.rounds):
            order = builds if round_index % 2 == 0 else builds[::-1]
            for scene in scenes:
                for build in order:
                    out = str(Path(tmp) / f"{build[0]}.exr")
                    rate, wall = render(build, REPO / "scenes/validation" / f"{scene}.toml", args.spp,
                                        100 + round_index, out, extra)
                    mse = mse_against_reference(out,
                                                REPO / "tests/references/validation" / scene / "mean.exr")
                    results.setdefault((scene, build[0]), []).append((rate, wall, mse))

    print(f"{args.rounds} rounds, {args.spp} spp, medians; efficiency = 1 / (MSE x whole-process s)\n")
    print("| scene | build | samples/s | whole s | MSE | efficiency | vs " + builds[0][0] + " |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for scene in scenes:
        baseline = None
        for name, _, _ in builds:
            runs = results[(scene, name)]
            rate = statistics.median(r[0] for r in runs)
            wall = statistics.median(r[1] for r in runs)
            mse = statistics.median(r[2] for r in runs)
            efficiency = 1.0 / (mse * wall) if mse > 0 else float("inf")
            baseline = baseline or efficiency
            print(f"| {scene} | {name} | {rate / 1e6:.3g} M | {wall:.2f} | {mse:.3g} | {efficiency:.3g} | "
                  f"{efficiency / baseline:.2f} |")


if __name__ == "__main__":
    main(sys.argv[1:])

#!/usr/bin/env python3
"""Cost of the microfacet materials: samples/s of each validation scene that
uses them against a Lambert-only version of the same scene (every conductor,
rough_dielectric, plastic and pbr material replaced by a lambert of albedo
0.5; everything else equal), interleaved renders, medians and ratios.

    tools/bench_materials.py [--runs 5] [--spp 256] [--vkrt build/vkrt] [SCENE ...]

Default scenes: scenes/validation/{conductor,plastic,rough-glass}.toml.
Both versions of a scene are rendered alternately RUNS times each (the same
seed), so drift on a shared machine hits both alike; kernels are compiled
before timing. Prints one row per scene: median Msamples/s of each and the
ratio Lambert / materials (the slowdown the materials cost)."""
from __future__ import annotations

import argparse
import re
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
NEW_KINDS = ("conductor", "rough_dielectric", "plastic", "pbr")


def lambert_only(text: str) -> str:
    """The scene with every [materials.X] table of a microfacet kind replaced by a grey lambert."""
    out, block, replace = [], [], False

    def flush():
        nonlocal block, replace
        if replace:
            out.append(block[0])
            out.append('type = "lambert"\nalbedo = 0.5\n\n')
        else:
            out.extend(block)
        block, replace = [], False

    for line in text.splitlines(keepends=True):
        if line.startswith("["):
            flush()
        block.append(line)
        match = re.match(r'\s*type\s*=\s*"(\w+)"', line)
        if match and block[0].startswith("[materials.") and match.group(1) in NEW_KINDS:
            replace = True
    flush()
    return "".join(out)


def samples_per_second(vkrt: str, scene: Path, spp: int, out: Path) -> float:
    result = subprocess.run([vkrt, "render", str(scene), "--spp", str(spp), "--seed", "1", "-o", str(out)],
                            capture_output=True, text=True, check=True)
    match = re.search(r"([\d.]+) (k|M)samples/s", result.stdout + result.stderr)
    if not match:
        sys.exit(f"bench_materials: no samples/s in vkrt's output: {result.stdout}{result.stderr}")
    return float(match.group(1)) * (1e-3 if match.group(2) == "k" else 1.0)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scenes", nargs="*", type=Path)
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--spp", type=int, default=256)
    parser.add_argument("--vkrt", default=str(ROOT / "build" / "vkrt"))
    args = parser.parse_args()
    scenes = args.scenes or [ROOT / "scenes" / "validation" / f"{n}.toml" for n in ("conductor", "plastic", "rough-glass")]
    print(f"{'scene':14s} {'materials Ms/s':>15s} {'lambert Ms/s':>13s} {'ratio':>6s}")
    with tempfile.TemporaryDirectory() as tmp:
        for scene in scenes:
            plain = scene.parent / f".{scene.stem}-lambert.toml"  # beside it: relative paths keep working
            plain.write_text(lambert_only(scene.read_text()))
            try:
                out = Path(tmp) / "out.exr"
                for s in (scene, plain):  # compile both kernels before timing
                    samples_per_second(args.vkrt, s, 1, out)
                rich, flat = [], []
                for _ in range(args.runs):
                    rich.append(samples_per_second(args.vkrt, scene, args.spp, out))
                    flat.append(samples_per_second(args.vkrt, plain, args.spp, out))
            finally:
                plain.unlink()
            a, b = statistics.median(rich), statistics.median(flat)
            print(f"{scene.stem:14s} {a:15.3f} {b:13.3f} {b / a:6.2f}")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Cost of the microfacet materials: samples/s of each validation scene that
uses them against a Lambert-only version of the same scene (every conductor,
rough_dielectric, plastic and pbr material replaced by a lambert of albedo
0.5; everything else equal), interleaved renders, medians and ratios.

    tools/bench_materials.py [--runs 5] [--spp 256] [--vkrt build/vkrt] [SCENE ...]

Default scenes: scenes/validation/{conductor,plastic,rough-glass,textured}.toml.
A scene with textures gets a third version: the same materials with every
texture replaced by the constant 0.5 and without normal maps (the cost of the
textures alone). The versions of a scene are rendered alternately RUNS times
each (the same seed), so drift on a shared machine hits them alike; kernels
are compiled before timing. Prints one row per scene: median Msamples/s of
each and the ratios Lambert / materials (the slowdown the materials cost)
and constants / textured."""
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


TEXTURE_VALUE = re.compile(r"^(\s*\w+\s*=\s*)\{[^}]*\btexture\s*=[^}]*\}", re.M)


def untextured(text: str) -> str:
    """The scene with every texture table replaced by the constant 0.5 and normal maps removed."""
    text = re.sub(r"^\s*normal_map\s*=\s*\{[^}]*\}\s*\n", "", text, flags=re.M)
    return TEXTURE_VALUE.sub(lambda m: m.group(1) + "0.5", text)


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
    names = ("conductor", "plastic", "rough-glass", "textured")
    scenes = args.scenes or [ROOT / "scenes" / "validation" / f"{n}.toml" for n in names]
    print(f"{'scene':14s} {'materials Ms/s':>15s} {'lambert Ms/s':>13s} {'ratio':>6s} "
          f"{'constants Ms/s':>15s} {'ratio':>6s}")
    with tempfile.TemporaryDirectory() as tmp:
        for scene in scenes:
            text = scene.read_text()
            # Beside the scene: its relative paths keep working.
            versions = {"lambert": (scene.parent / f".{scene.stem}-lambert.toml", untextured(lambert_only(text)))}
            if untextured(text) != text:
                versions["constants"] = (scene.parent / f".{scene.stem}-constants.toml", untextured(text))
            for path, body in versions.values():
                path.write_text(body)
            try:
                out = Path(tmp) / "out.exr"
                files = [scene] + [path for path, _ in versions.values()]
                for f in files:  # compile every kernel before timing
                    samples_per_second(args.vkrt, f, 1, out)
                rates = {f: [] for f in files}
                for _ in range(args.runs):
                    for f in files:
                        rates[f].append(samples_per_second(args.vkrt, f, args.spp, out))
            finally:
                for path, _ in versions.values():
                    path.unlink()
            median = {f: statistics.median(r) for f, r in rates.items()}
            a = median[scene]
            b = median[versions["lambert"][0]]
            row = f"{scene.stem:14s} {a:15.3f} {b:13.3f} {b / a:6.2f}"
            if "constants" in versions:
                c = median[versions["constants"][0]]
                row += f" {c:15.3f} {c / a:6.2f}"
            print(row)


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Cost of the microfacet materials: samples/s of each validation scene that
uses them against a Lambert-only version of the same scene (every conductor,
rough_dielectric, plastic and pbr material replaced by a lambert of albedo
0.5; everything else equal), interleaved renders, medians and ratios.

    tools/bench_materials.py [--runs 5] [--spp 256] [--device llvmpipe] [SCENE ...]

Default scenes: scenes/validation/{conductor,plastic,rough-glass,textured}.toml.
A scene with textures gets a third version: the same materials with every
texture replaced by the constant 0.5 and without normal maps (the cost of the
textures alone). The versions of a scene are rendered alternately RUNS times
each (the same seed), so drift on a shared machine hits them alike; kernels
are compiled before timing. Prints one row per scene: median Msamples/s of
each and the ratios Lambert / materials (the slowdown the materials cost)
and constants / textured.

Renders through the Python module (docs/python.md): the build's package
(build/python) or an installed one; samples/s is the render's pixels x spp
over its render seconds (the command line's figure; the kernel compile and
start-up are not in it)."""
from __future__ import annotations

import argparse
import re
import statistics
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
try:
    import vkrt
except ImportError:  # a build tree: its package
    sys.path.insert(0, str(ROOT / "build" / "python"))
    import vkrt
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


def samples_per_second(scene: "vkrt.Scene", spp: int, device: str) -> float:
    """Millions of samples per second of one render (seed 1)."""
    result = vkrt.render(scene, spp=spp, seed=1, device=device)
    height, width = result.image.shape[:2]
    return width * height * result.spp / result.render_seconds * 1e-6


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scenes", nargs="*", type=Path)
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--spp", type=int, default=256)
    parser.add_argument("--device", default="", help="a device index or part of its name (vkrt.devices())")
    args = parser.parse_args()
    names = ("conductor", "plastic", "rough-glass", "textured")
    scenes = args.scenes or [ROOT / "scenes" / "validation" / f"{n}.toml" for n in names]
    print(f"{'scene':14s} {'materials Ms/s':>15s} {'lambert Ms/s':>13s} {'ratio':>6s} "
          f"{'constants Ms/s':>15s} {'ratio':>6s}")
    for path in scenes:
        text = path.read_text()
        # Parsed with the scene's folder as base, so its relative paths keep working.
        versions = {"materials": vkrt.Scene.load(path),
                    "lambert": vkrt.Scene.from_toml(untextured(lambert_only(text)), base_dir=path.parent)}
        if untextured(text) != text:
            versions["constants"] = vkrt.Scene.from_toml(untextured(text), base_dir=path.parent)
        for scene in versions.values():  # compile every kernel before timing
            samples_per_second(scene, 1, args.device)
        rates = {name: [] for name in versions}
        for _ in range(args.runs):
            for name, scene in versions.items():
                rates[name].append(samples_per_second(scene, args.spp, args.device))
        median = {name: statistics.median(r) for name, r in rates.items()}
        a, b = median["materials"], median["lambert"]
        row = f"{path.stem:14s} {a:15.3f} {b:13.3f} {b / a:6.2f}"
        if "constants" in median:
            c = median["constants"]
            row += f" {c:15.3f} {c / a:6.2f}"
        print(row)


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Cost of many lights: samples/s and the estimated error of one scene lit by
1, 100, 10,000 and 100,000 lights of one kind (point, spot or directional),
their total power the same at every count.

    tools/bench_lights.py [--vkrt build/vkrt] [--kind point] [--counts 1,100,10000,100000]
                          [--spp 64] [--runs 3] [--integrator path] [--json FILE]

The scene: a floor, a back wall, three spheres and a box (lambert, conductor,
plastic), lit by N lights of the kind on a jittered grid over the floor (point
and spot lights 2-4 units up, spots aimed down; suns from directions spread
over the upper sky). Each count is rendered RUNS times (the same seed;
interleaved: every count once, then again), at SPP samples per pixel with
--variance, through `vkrt render --json` (docs/machine-output.md). Printed per
count: the median Msamples/s (render seconds only, the kernel compiled
before), its ratio to one light, the estimated relMSE at SPP, and the
efficiency 1 / (relMSE x seconds) relative to one light's. Kernels are
compiled once per count before timing.
"""
from __future__ import annotations

import argparse
import json
import math
import random
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

SCENE_HEAD = """\
[render]
integrator = "{integrator}"
max_depth = 4

[camera]
eye = [0.0, 2.2, 6.0]
target = [0.0, 0.5, 0.0]
up = [0.0, 1.0, 0.0]
fov = 50
width = 160
height = 120

[background]
color = [0.0, 0.0, 0.0]

[materials.floor]
type = "lambert"
albedo = [0.6, 0.58, 0.55]

[materials.copper]
type = "conductor"
metal = "Cu"
roughness = 0.3

[materials.plastic]
type = "plastic"
diffuse = [0.15, 0.5, 0.7]
roughness = 0.2

[[objects]]
shape = "box"
material = "floor"
min = [-6.0, -0.2, -6.0]
max = [6.0, 0.0, 6.0]

[[objects]]
shape = "box"
material = "floor"
min = [-6.0, 0.0, -3.1]
max = [6.0, 4.0, -3.0]

[[objects]]
shape = "sphere"
material = "copper"
center = [-1.4, 0.6, 0.0]
radius = 0.6

[[objects]]
shape = "sphere"
material = "plastic"
center = [0.2, 0.45, 1.0]
radius = 0.45

[[objects]]
shape = "sphere"
material = "floor"
center = [1.6, 0.7, -0.8]
radius = 0.7

[[objects]]
shape = "box"
material = "plastic"
min = [-0.4, 0.0, -1.8]
max = [0.4, 1.4, -1.0]
"""


def light_entries(kind: str, count: int, seed: int = 1) -> str:
    """N lights of one kind, their total power that of one light of the kind."""
    rng = random.Random(seed)
    side = max(1, math.ceil(math.sqrt(count)))
    lines = []
    for i in range(count):
        gx, gz = i % side, i // side
        x = -5.0 + 10.0 * (gx + rng.random()) / side
        z = -2.8 + 8.0 * (gz + rng.random()) / side
        y = 2.0 + 2.0 * rng.random()
        if kind == "point":
            v = 40.0 / count
            lines.append(f'[[lights]]\ntype = "point"\nposition = [{x:.5f}, {y:.5f}, {z:.5f}]\n'
                         f"intensity = [{v:.6g}, {v * 0.9:.6g}, {v * 0.8:.6g}]\n")
        elif kind == "spot":
            v = 60.0 / count
            lines.append(f'[[lights]]\ntype = "spot"\nposition = [{x:.5f}, {y:.5f}, {z:.5f}]\n'
                         f"direction = [{rng.uniform(-0.3, 0.3):.4f}, -1.0, {rng.uniform(-0.3, 0.3):.4f}]\n"
                         f"intensity = [{v:.6g}, {v * 0.9:.6g}, {v * 0.8:.6g}]\n"
                         "inner_cone_angle = 30\nouter_cone_angle = 45\n")
        else:
            v = 3.0 / count
            phi = 2.0 * math.pi * rng.random()
            cos_theta = 0.3 + 0.7 * rng.random()
            sin_theta = math.sqrt(1.0 - cos_theta * cos_theta)
            lines.append(f'[[lights]]\ntype = "directional"\n'
                         f"direction = [{sin_theta * math.cos(phi):.5f}, {-cos_theta:.5f}, "
                         f"{sin_theta * math.sin(phi):.5f}]\n"
                         f"irradiance = [{v:.6g}, {v * 0.9:.6g}, {v * 0.8:.6g}]\n")
    return "\n".join(lines)


def render(vkrt: str, scene: Path, spp: int, out: Path) -> dict:
    facts = out.with_suffix(".json")
    cmd = [vkrt, "render", str(scene), "--spp", str(spp), "--variance", "--seed", "1",
           "-o", str(out), "--json", str(facts)]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"bench_lights: {' '.join(cmd)} failed ({done.returncode}):\n{done.stderr}")
    return json.loads(facts.read_text())


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vkrt", default=str(ROOT / "build" / "vkrt"))
    parser.add_argument("--kind", choices=("point", "spot", "directional"), default="point")
    parser.add_argument("--counts", default="1,100,10000,100000")
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--integrator", choices=("path", "whitted"), default="path")
    parser.add_argument("--json", help="also write the rows as JSON to this file")
    args = parser.parse_args()
    counts = [int(c) for c in args.counts.split(",")]

    with tempfile.TemporaryDirectory(prefix="vkrt-bench-lights-") as tmp:
        work = Path(tmp)
        scenes = {}
        for n in counts:
            scenes[n] = work / f"lights-{n}.toml"
            scenes[n].write_text(SCENE_HEAD.format(integrator=args.integrator) + "\n" +
                                 light_entries(args.kind, n))
            render(args.vkrt, scenes[n], 1, work / f"warm-{n}.exr")  # the kernel compiled
        runs = {n: [] for n in counts}
        for _ in range(args.runs):
            for n in counts:
                runs[n].append(render(args.vkrt, scenes[n], args.spp, work / f"r-{n}.exr"))

    rows = []
    for n in counts:
        rate = statistics.median(r["samplesPerSecond"] for r in runs[n])
        seconds = statistics.median(r["renderSeconds"] for r in runs[n])
        rel_mse = statistics.median(r["errorEstimate"]["relMse"] for r in runs[n])
        rows.append({"lights": n, "kind": args.kind, "msamplesPerSecond": rate / 1e6,
                     "renderSeconds": seconds, "relMse": rel_mse, "kernel": runs[n][0]["kernel"]})
    base = rows[0]
    print(f"{args.kind} lights, {args.integrator}, {args.spp} spp, median of {args.runs}; "
          f"device {runs[counts[0]][0]['device']['driver']}")
    print(f"{'lights':>8} {'Msamples/s':>11} {'rate/1 light':>13} {'relMSE':>10} {'efficiency/1 light':>19}")
    for row in rows:
        efficiency = (base["relMse"] * base["renderSeconds"]) / (row["relMse"] * row["renderSeconds"])
        row["rateRatio"] = row["msamplesPerSecond"] / base["msamplesPerSecond"]
        row["efficiencyRatio"] = efficiency
        print(f"{row['lights']:>8} {row['msamplesPerSecond']:>11.3f} {row['rateRatio']:>13.3f} "
              f"{row['relMse']:>10.4g} {efficiency:>19.3f}")
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())

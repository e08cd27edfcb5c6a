#!/usr/bin/env python3
"""Closest-hit ray throughput of vkrt (lavapipe) against Mitsuba 3 on the same scenes.

What a path tracer's sample costs is mostly its rays. This isolates them:

* Mitsuba: the camera's rays for every pixel, one wavefront of width x height x
  --spp rays, through `scene.ray_intersect` (the full surface interaction,
  as its path tracer asks for), timed after one untimed call that compiles
  the kernel; Mrays/s = rays / seconds, median of --runs.
* vkrt: the same scene with every light removed, rendered with the Whitted
  integrator at max_depth 1: a camera ray, its closest hit and the hit's
  description, and no shadow ray. Mrays/s = width x height x --spp / vkrt's
  own rendering time, median of --runs.

* the device's own traversal: the same vkrt render with `--accel driver`
  (VK_KHR_ray_query over acceleration structures the driver builds; the
  same rays and hits, docs/architecture.md "Two traversal backends"); the
  column is left empty on a device without ray queries.

The ratio bounds what any change to the rest of the integrator can gain: a
sample costs at least its rays.

    tools/bench_rays.py [--runs 3] [--spp 16] [--width 320 --height 240] [SCENE.toml ...]

Needs .venv-mitsuba and vkrt's Python module (docs/python.md: the build's
package, build/python, is found without installing). Default scenes: the
validation scenes with meshes.
"""
import argparse
import re
import statistics
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO / "tools"))
try:
    import vkrt
except ImportError:  # a build tree: its package
    sys.path.insert(0, str(REPO / "build" / "python"))
    import vkrt


def rays_only_scene(text):
    """The scene's TOML without light sources (its [[lights]] tables and every
    emission), rendered by the Whitted integrator at max_depth 1. Emitting
    objects stay, as plain geometry: both renderers trace the same surfaces."""
    lines, in_lights = [], False
    for line in text.splitlines():
        header = re.match(r"\s*\[", line)
        if header:
            in_lights = line.strip().startswith("[[lights]]")
        if in_lights or re.match(r"\s*emission\s*=", line):
            continue
        if re.match(r"\s*(integrator|max_depth)\s*=", line):
            continue
        lines.append(line)
        if line.strip() == "[render]":
            lines += ['integrator = "whitted"', "max_depth = 1"]
    if "[render]" not in text:
        lines += ["[render]", 'integrator = "whitted"', "max_depth = 1"]
    return "\n".join(lines) + "\n"


def vkrt_mrays(scene, args, accel="own"):
    # Parsed with the scene's folder as base: relative mesh paths keep working.
    rays_only = vkrt.Scene.from_toml(rays_only_scene(scene.read_text()), base_dir=scene.parent)
    rates = []
    for run in range(args.runs + 1):
        try:
            result = vkrt.render(rays_only, spp=args.spp, seed=run, width=args.width, height=args.height,
                                 accel=accel, device=args.device)
        except ValueError as error:
            if accel == "driver" and "lacks" in str(error):
                return None  # a device without ray queries
            sys.exit(f"bench_rays: error: vkrt on {scene}: {error}")
        if run > 0:  # the first run fills the caches
            rates.append(args.width * args.height * args.spp / result.render_seconds / 1e6)
    return statistics.median(rates)


def mitsuba_mrays(scene, args, work):
    import drjit as dr
    import mitsuba as mi
    import to_mitsuba
    to_mitsuba._note = lambda message: None
    d = to_mitsuba.convert(str(scene), files_dir=Path(work) / scene.stem, spp=1)
    d["sensor"]["film"]["width"] = args.width
    d["sensor"]["film"]["height"] = args.height
    mi_scene = mi.load_dict(d)
    sensor = mi_scene.sensors()[0]
    count = args.width * args.height * args.spp
    index = dr.arange(mi.UInt32, count)
    pixel = index // args.spp
    x = mi.Float(pixel % args.width)
    y = mi.Float(pixel // args.width)
    sampler = mi.load_dict({"type": "independent"})
    sampler.seed(0, count)
    position = mi.Point2f((x + sampler.next_1d()) / args.width, (y + sampler.next_1d()) / args.height)
    rays, _ = sensor.sample_ray(0.0, 0.5, position, mi.Point2f(0.5))
    dr.eval(rays)
    rates = []
    for run in range(args.runs + 1):
        dr.sync_thread()
        start = time.perf_counter()
        si = mi_scene.ray_intersect(rays)
        dr.eval(si.t, si.p, si.n, si.sh_frame.n, si.uv)
        dr.sync_thread()
        seconds = time.perf_counter() - start
        if run > 0:  # the first call compiles the kernel
            rates.append(count / seconds / 1e6)
    return statistics.median(rates)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenes", nargs="*", type=Path)
    parser.add_argument("--device", default="", help="a device index or part of its name (vkrt.devices())")
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--spp", type=int, default=16)
    parser.add_argument("--width", type=int, default=320)
    parser.add_argument("--height", type=int, default=240)
    args = parser.parse_args()
    if args.runs < 1 or args.spp < 1 or args.width < 1 or args.height < 1:
        sys.exit("bench_rays: error: --runs, --spp, --width and --height must be at least 1")
    import mitsuba as mi
    try:
        mi.set_variant("llvm_ad_rgb")
    except (ImportError, AttributeError) as e:
        sys.exit(f"bench_rays: error: Mitsuba's llvm_ad_rgb variant is not available ({e}); set "
                 "DRJIT_LIBLLVM_PATH to a libLLVM >= 16 (Debian: libllvm19)")
    scenes = args.scenes or sorted((REPO / "scenes" / "validation").glob("mesh-*.toml"))
    print(f"{args.width}x{args.height}, {args.spp} rays per pixel, medians of {args.runs}; Mitsuba {mi.__version__} "
          f"llvm_ad_rgb")
    print()
    print("| scene | vkrt Mrays/s | ray query Mrays/s | Mitsuba Mrays/s | vkrt / Mitsuba | ray query / vkrt |")
    print("| --- | --- | --- | --- | --- | --- |")
    with tempfile.TemporaryDirectory() as work:
        for scene in scenes:
            if not scene.is_file():
                sys.exit(f"bench_rays: error: {scene}: no such scene file")
            ours = vkrt_mrays(scene.resolve(), args, accel="own")
            query = vkrt_mrays(scene.resolve(), args, accel="driver")
            theirs = mitsuba_mrays(scene.resolve(), args, work)
            query_text = f"{query:.2f} | " if query else "— | "
            query_ratio = f"{query / ours:.3f}" if query else "—"
            print(f"| {scene.stem} | {ours:.2f} | {query_text}{theirs:.2f} | {ours / theirs:.3f} | {query_ratio} |",
                  flush=True)


if __name__ == "__main__":
    main()

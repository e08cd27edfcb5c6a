#!/usr/bin/env python3
"""Lane occupancy of the path integrator's segment loop on lavapipe.

lavapipe runs 8 invocations of a workgroup in lockstep: one row of 8 pixels of
an 8x8 tile. A pass of the loop that traces one path segment costs the group
one pass whether 1 or 8 of its lanes still have a path, so

    occupancy = segments traced / (8 x passes the groups ran)

where a group runs as many passes as its busiest lane. With S samples per
invocation (path regeneration, `--samples-per-invocation S`) a lane's passes
are the segments of its S samples together.

The kernel hook VKRT_MEASURE_SEGMENTS makes each sample's radiance the number
of segments it traced; one dispatch of S samples per pixel (`--spp S`) then
gives every lane's total as S x its pixel's mean. The script renders each
scene that way (several seeds), groups the pixels into the 8-lane rows the
driver runs, and prints the occupancy and segments per sample for every S.

    tools/lane_occupancy.py [--vkrt build/vkrt] [--per-invocation 1,8]
        [--seeds 4] [--width 320 --height 240] [SCENE.toml ...]

Needs .venv-mitsuba (its Bitmap reads the EXR). Default scenes: the
validation scenes (scenes/validation).
"""
import argparse
import os
import subprocess
import sys
import tempfile
import tomllib
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
LANES = 8


def load_image(path):
    import mitsuba as mi
    import numpy as np
    mi.set_variant("scalar_rgb")
    return np.array(mi.Bitmap(str(path)))[..., 0].astype("float64")


def lane_rows(image):
    """Every 8-lane row of the image, lanes past its right edge as idle (0)."""
    import numpy as np
    height, width = image.shape
    padded = np.zeros((height, (width + LANES - 1) // LANES * LANES))
    padded[:, :width] = image
    return padded.reshape(height, -1, LANES).reshape(-1, LANES)


def measure(vkrt, scene, per_invocation, seeds, size, workdir):
    useful = issued = segments = pixels = 0.0
    for seed in range(seeds):
        out = Path(workdir) / f"segments-{per_invocation}-{seed}.exr"
        command = [vkrt, "render", str(scene), "--spp", str(per_invocation), "--samples-per-invocation",
                   str(per_invocation), "--kernel-define", "VKRT_MEASURE_SEGMENTS=1", "--seed", str(seed),
                   "--width", str(size[0]), "--height", str(size[1]), "-o", str(out)]
        result = subprocess.run(command, capture_output=True, text=True)
        if result.returncode != 0:
            sys.exit(f"lane_occupancy: error: {' '.join(command)} failed:\n{result.stderr}")
        image = load_image(out)
        rows = lane_rows(image * per_invocation)  # each lane's segments over its S samples
        useful += rows.sum()
        issued += LANES * rows.max(axis=1).sum()
        segments += image.sum()
        pixels += image.size
    return useful / issued, segments / pixels


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenes", nargs="*", type=Path)
    parser.add_argument("--vkrt", default=os.environ.get("VKRT", str(REPO / "build" / "vkrt")))
    parser.add_argument("--per-invocation", default="1,8", help="comma-separated samples per invocation")
    parser.add_argument("--seeds", type=int, default=4)
    parser.add_argument("--width", type=int, default=320)
    parser.add_argument("--height", type=int, default=240)
    args = parser.parse_args()
    try:
        counts = [int(text) for text in args.per_invocation.split(",")]
    except ValueError:
        sys.exit(f"lane_occupancy: error: --per-invocation {args.per_invocation}: expected numbers like 1,8")
    if any(c < 1 or c > 64 for c in counts) or args.seeds < 1:
        sys.exit("lane_occupancy: error: --per-invocation values must be 1..64 and --seeds at least 1")
    scenes = args.scenes or sorted((REPO / "scenes" / "validation").glob("*.toml"))
    if not scenes:
        sys.exit("lane_occupancy: error: no scenes given and none found")
    print("| scene | samples per invocation | segments per sample | lane occupancy |")
    print("| --- | --- | --- | --- |")
    with tempfile.TemporaryDirectory() as workdir:
        for scene in scenes:
            if not scene.is_file():
                sys.exit(f"lane_occupancy: error: {scene}: no such scene file")
            integrator = tomllib.loads(scene.read_text()).get("render", {}).get("integrator", "whitted")
            if integrator != "path":
                sys.exit(f"lane_occupancy: error: {scene}: integrator {integrator}; only the path integrator "
                         "regenerates paths (and has the segment hook)")
            for count in counts:
                occupancy, per_sample = measure(args.vkrt, scene, count, args.seeds, (args.width, args.height),
                                                workdir)
                print(f"| {scene.stem} | {count} | {per_sample:.2f} | {occupancy:.1%} |", flush=True)


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""The two traversal backends like for like: the same scene, size, spp, seed,
integrator and paths, only the traversal differs (`--accel own` vs
`--accel driver`). Runs interleave own and driver, ROUNDS times per scene, and
read vkrt's --json: samples/s of the timed render (kernel compile and the
warm-up frame excluded), the start-up time (kernel compile, the driver's
compile, structure builds, the warm-up frame) and, from `vkrt info --json`, what a camera move
costs. Prints per scene the medians and the driver/own ratio of samples/s,
taken round by round (the pairing keeps the ratio meaningful while the
machine's speed drifts).

  tools/bench_backends.py [--vkrt build/vkrt] [--rounds 5] [--spp 64]
                          [--size 320x240] [--device NAME] [SCENE ...]

Default scenes: the suite's mesh and analytic validation scenes. Needs a
device with VK_KHR_ray_query (lavapipe from Mesa 24.1 on, or a GPU)."""
import argparse
import json
import statistics
import subprocess
import sys

DEFAULT_SCENES = [
    "scenes/validation/mesh-cornell.toml",
    "scenes/validation/mesh-bunny-diffuse.toml",
    "scenes/validation/mesh-bunny-glass.toml",
    "scenes/validation/mesh-smooth.toml",
    "scenes/validation/textured.toml",
    "scenes/gltf/lights-camera.gltf",
    "scenes/validation/diffuse-box.toml",
    "scenes/validation/lights.toml",
    "scenes/validation/glass.toml",
]


def run_json(command):
    result = subprocess.run(command, capture_output=True, text=True)
    if result.returncode != 0:
        sys.exit(f"bench_backends: {' '.join(command)} failed ({result.returncode}):\n{result.stderr}")
    return json.loads(result.stdout)


def render(args, scene, accel, seed):
    width, height = args.size.split("x")
    command = [args.vkrt, "render", scene, "--accel", accel, "--spp", str(args.spp), "--seed", str(seed),
               "--width", width, "--height", height, "-o", "/dev/null", "--json", "-"]
    if args.device:
        command += ["--device", args.device]
    return run_json(command)


def camera_move(args, scene, accel):
    command = [args.vkrt, "info", scene, "--accel", accel, "--json", "-"]
    if args.device:
        command += ["--device", args.device]
    return run_json(command)["cameraMoveSeconds"]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--vkrt", default="build/vkrt")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--size", default="320x240")
    parser.add_argument("--device", default="")
    parser.add_argument("scenes", nargs="*", default=DEFAULT_SCENES)
    args = parser.parse_args()

    print(f"{'scene':44} {'own ks/s':>9} {'driver ks/s':>11} {'driver/own':>10} "
          f"{'own start s':>11} {'drv start s':>11} {'own move ms':>11} {'drv move ms':>11}")
    for scene in args.scenes:
        rates = {"own": [], "driver": []}
        first = {"own": [], "driver": []}
        ratios = []
        for round_ in range(args.rounds):
            seed = 100 + round_
            order = ["own", "driver"] if round_ % 2 == 0 else ["driver", "own"]
            this_round = {}
            for accel in order:
                report = render(args, scene, accel, seed)
                if report["accel"] != accel:
                    sys.exit(f"bench_backends: {scene} ran with {report['accel']}, not {accel}")
                this_round[accel] = report["samplesPerSecond"]
                rates[accel].append(report["samplesPerSecond"])
                first[accel].append(report["startupSeconds"])
            ratios.append(this_round["driver"] / this_round["own"])
        moves = {accel: camera_move(args, scene, accel) for accel in ("own", "driver")}
        median = statistics.median
        print(f"{scene:44} {median(rates['own']) / 1e3:9.1f} {median(rates['driver']) / 1e3:11.1f} "
              f"{median(ratios):10.2f} {median(first['own']):11.2f} {median(first['driver']):11.2f} "
              f"{moves['own'] * 1e3:11.2f} {moves['driver'] * 1e3:11.2f}")


if __name__ == "__main__":
    main()

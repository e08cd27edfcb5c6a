#!/usr/bin/env python3
"""vkrt against Blender Cycles on glTF models, as a user would compare them:
the same file, camera and light (tools/compare_cycles.py sets them up), each
renderer measured against its own high-spp image, at equal samples per pixel
and at equal time, whole process and steady state.

    tools/bench_vs_cycles.py [MODEL.gltf ...] [--models DIR] [options]

Set-up, once: tools/setup-cycles-venv.sh (.venv-cycles: bpy, NumPy, OpenEXR;
never a set-up dependency of vkrt). The script re-executes itself there.

For each model:
  1. references: vkrt and Cycles each render --reference-spp samples (seed
     1000); each renderer's error is measured against its own reference, so
     the two renderers' small differences of look do not count as noise;
  2. equal spp: --runs renders of --spp samples each (seeds 1, 2, ...) by
     both; whole-process seconds (the process from start to exit, as the
     user waits: parse, textures, BVH, kernel compile or cache, render,
     write) and steady seconds (vkrt's renderSeconds from --json, Cycles'
     render time after loading the file); relMSE against the reference
     (mean over pixels and channels of (x - ref)^2 / (ref^2 + 0.01)), made
     unbiased for the reference's own noise (divided by 1 + spp / reference
     spp); medians over the runs;
  3. equal time: vkrt with --time-budget set to Cycles' median steady seconds
     at --spp, its relMSE against Cycles';
  4. steady state: --steady-spp samples by both, samples per second and the
     efficiency 1 / (relMSE x seconds).

Efficiency ratios are vkrt's over Cycles' (> 1: vkrt reaches an error in
less time). Both drivers: run it once on the host (Mesa 25 on Debian 12),
then again with vkrt in the Debian 13 chroot of tools/check-debian13.sh
(Mesa 26) through --vkrt-command and --vkrt-root, reusing Cycles' renders
with --cycles-from (Cycles does not depend on the Vulkan driver).

Options (defaults in brackets):
    --models DIR           every folder of DIR holding glTF/*.gltf
    --width/--height       [240 x 180]
    --spp N                [64]
    --steady-spp N         [256]
    --reference-spp N      [1024]
    --runs N               [3]
    --threads N            Cycles' CPU threads [0: all]
    --out DIR              renders and the JSON of each model [bench-vs-cycles/]
    --json FILE            every figure as one JSON object
    --table FILE           a Markdown table of the ratios
    --cycles-from FILE     an earlier run's --json: its Cycles figures and
                           references are reused (same size and spp)
    --vkrt PATH            the vkrt binary [$VKRT, else build/vkrt]
    --vkrt-command CMD     a command line that runs vkrt (split as a shell
                           splits words), e.g. one that enters a chroot;
                           replaces --vkrt
    --vkrt-root DIR        vkrt runs with DIR as its root (a chroot): every
                           file it reads or writes must lie under DIR, and is
                           named to it without the DIR prefix
"""
from __future__ import annotations

import argparse
import json
import shlex
import statistics
import subprocess
import sys
import time
from pathlib import Path

import os

TOOLS = Path(__file__).resolve().parent
VENV = TOOLS.parent / ".venv-cycles"

if __name__ == "__main__" and Path(sys.prefix).resolve() != VENV.resolve():
    # Re-executed with .venv-cycles' Python (bpy, NumPy, OpenEXR), as compare_cycles.py is.
    python = VENV / "bin" / "python"
    if not python.exists():
        sys.exit(f"bench_vs_cycles: error: {VENV} does not exist: run tools/setup-cycles-venv.sh first")
    os.execv(str(python), [str(python), str(Path(__file__).resolve())] + sys.argv[1:])

sys.path.insert(0, str(TOOLS))
import compare_cycles as cc  # noqa: E402
import numpy as np  # noqa: E402

REFERENCE_SEED = 1000


def rel_mse(image: np.ndarray, reference: np.ndarray) -> float:
    return float(np.mean((image - reference) ** 2 / (reference ** 2 + 0.01)))


def unbiased(mse: float, spp: int, reference_spp: int) -> float:
    """The reference's own variance adds spp / reference_spp of the image's to the measured error."""
    return mse / (1.0 + spp / reference_spp)


class Vkrt:
    def __init__(self, args):
        self.command = shlex.split(args.vkrt_command) if args.vkrt_command else [str(cc.find_vkrt(args.vkrt))]
        self.root = Path(args.vkrt_root).resolve() if args.vkrt_root else None

    def path(self, p: Path) -> str:
        p = Path(p).resolve()
        if self.root is None:
            return str(p)
        try:
            return "/" + str(p.relative_to(self.root))
        except ValueError:
            sys.exit(f"bench_vs_cycles: error: {p} is not under --vkrt-root {self.root}")

    def render(self, scene: Path, camera: int, environment: Path | None, out: Path, args, spp: int | None,
               seed: int, budget: float | None = None) -> dict:
        json_path = out.with_suffix(".json")
        command = self.command + ["render", self.path(scene), "--camera", str(camera), "--width", str(args.width),
                                  "--height", str(args.height), "--seed", str(seed), "-o", self.path(out),
                                  "--json", self.path(json_path)]
        command += ["--spp", str(spp)] if spp else []
        command += ["--time-budget", f"{budget:.3f}"] if budget else []
        if environment is not None:
            command += ["--environment", self.path(environment)]
        started = time.perf_counter()
        done = subprocess.run(command, capture_output=True, text=True)
        seconds = time.perf_counter() - started
        if done.returncode != 0:
            raise RuntimeError(f"vkrt exited {done.returncode}: {done.stderr.strip()[-1500:]}")
        facts = json.loads(json_path.read_text())
        return {"whole": seconds, "steady": facts["renderSeconds"], "spp": facts["spp"],
                "device": facts["device"]["name"], "driver": facts["device"]["driver"]}


def cycles_render(copy: Path, setup: dict, out: Path, args, spp: int, seed: int) -> dict:
    run_args = argparse.Namespace(width=args.width, height=args.height, cycles_spp=spp, seed=seed,
                                  threads=args.threads)
    result = cc.run_cycles(copy, setup["camera"], setup["lights"], setup["white_world"], run_args, out)
    return {"whole": result["seconds"], "steady": result["facts"]["render_seconds"], "spp": spp,
            "blender": result["facts"].get("blender")}


def prepare(source: Path, work: Path, args) -> dict:
    """The temporary copy both renderers read, its camera, lights and world (compare_cycles' rules)."""
    gltf = json.loads(source.read_text())
    cc.strip_by_design(gltf)
    cc.make_default_material_explicit(gltf)
    camera, _ = cc.choose_camera(gltf, source.parent)
    lights = cc.punctual_lights(gltf, source.parent)
    environment = None
    if not lights:
        environment = work / "white.exr"
        if not environment.exists():
            cc.write_white_exr(environment)
    camera_index = cc.add_camera(gltf, camera, args.width / args.height)
    return {"copy": cc.write_temporary_copy(source, gltf), "camera": camera, "camera_index": camera_index,
            "lights": lights, "white_world": not lights, "environment": environment}


def median_of(runs: list, key: str) -> float:
    return statistics.median(r[key] for r in runs)


def bench_model(name: str, source: Path, args, vkrt: Vkrt, work: Path, cycles_before: dict | None) -> dict:
    setup = prepare(source, work, args)
    row = {"model": name}
    try:
        # vkrt's references and runs.
        v_ref_exr = work / f"{name}.vkrt.ref.exr"
        row["vkrt_reference"] = vkrt.render(setup["copy"], setup["camera_index"], setup["environment"], v_ref_exr,
                                            args, args.reference_spp, REFERENCE_SEED)
        v_ref = cc.read_exr(v_ref_exr)
        v_runs = []
        for run in range(args.runs):
            exr = work / f"{name}.vkrt.{run}.exr"
            r = vkrt.render(setup["copy"], setup["camera_index"], setup["environment"], exr, args, args.spp, run + 1)
            r["relmse"] = unbiased(rel_mse(cc.read_exr(exr), v_ref), args.spp, args.reference_spp)
            v_runs.append(r)
        exr = work / f"{name}.vkrt.steady.exr"
        v_steady = vkrt.render(setup["copy"], setup["camera_index"], setup["environment"], exr, args,
                               args.steady_spp, 99)
        v_steady["relmse"] = unbiased(rel_mse(cc.read_exr(exr), v_ref), args.steady_spp, args.reference_spp)
        # Cycles' (or an earlier run's).
        if cycles_before:
            c = cycles_before
        else:
            c_ref_exr = work / f"{name}.cycles.ref.exr"
            c = {"reference": cycles_render(setup["copy"], setup, c_ref_exr, args, args.reference_spp,
                                            REFERENCE_SEED), "reference_exr": str(c_ref_exr), "runs": []}
            c_ref = cc.read_exr(c_ref_exr)
            for run in range(args.runs):
                out = work / f"{name}.cycles.{run}.exr"
                r = cycles_render(setup["copy"], setup, out, args, args.spp, run + 1)
                r["relmse"] = unbiased(rel_mse(cc.read_exr(out), c_ref), args.spp, args.reference_spp)
                c["runs"].append(r)
            out = work / f"{name}.cycles.steady.exr"
            c["steady"] = cycles_render(setup["copy"], setup, out, args, args.steady_spp, 99)
            c["steady"]["relmse"] = unbiased(rel_mse(cc.read_exr(out), c_ref), args.steady_spp, args.reference_spp)
        # Equal time: vkrt given Cycles' steady seconds at --spp.
        exr = work / f"{name}.vkrt.equal-time.exr"
        budget = median_of(c["runs"], "steady")
        v_equal = vkrt.render(setup["copy"], setup["camera_index"], setup["environment"], exr, args, None, 77,
                              budget=budget)
        v_equal["relmse"] = unbiased(rel_mse(cc.read_exr(exr), v_ref), v_equal["spp"], args.reference_spp)
    finally:
        setup["copy"].unlink(missing_ok=True)
    row.update(vkrt_runs=v_runs, vkrt_steady=v_steady, vkrt_equal_time=v_equal, cycles=c)
    v_mse, c_mse = median_of(v_runs, "relmse"), median_of(c["runs"], "relmse")
    row["ratios"] = {
        "relmse_at_equal_spp": v_mse / c_mse,
        "efficiency_whole_process": (c_mse * median_of(c["runs"], "whole")) / (v_mse * median_of(v_runs, "whole")),
        "efficiency_steady": (c["steady"]["relmse"] * c["steady"]["steady"]) /
                             (v_steady["relmse"] * v_steady["steady"]),
        "samples_per_second_steady": (v_steady["spp"] / v_steady["steady"]) /
                                     (c["steady"]["spp"] / c["steady"]["steady"]),
        "relmse_at_equal_time": c_mse / v_equal["relmse"],
        "whole_process_seconds": median_of(v_runs, "whole") / median_of(c["runs"], "whole"),
    }
    return row


def markdown(rows: list, args) -> str:
    device = next((r["vkrt_runs"][0]["driver"] for r in rows if "vkrt_runs" in r), "?")
    blender = next((r["cycles"]["runs"][0].get("blender") for r in rows if "cycles" in r), "?")
    lines = [f"vkrt ({device}) against Cycles (Blender {blender}), {args.width}x{args.height}, "
             f"{args.spp} spp ({args.runs} runs, medians), steady {args.steady_spp} spp, each against its own "
             f"{args.reference_spp}-spp image (tools/bench_vs_cycles.py). Ratios are vkrt's over Cycles'.", "",
             "| model | vkrt s (whole) | Cycles s (whole) | relMSE ratio, equal spp | efficiency, whole process | "
             "efficiency, steady | samples/s, steady | error ratio at equal time |",
             "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"]
    for r in rows:
        if "error" in r:
            lines.append(f"| {r['model']} | {r['error'][:120]} | | | | | | |")
            continue
        q = r["ratios"]
        lines.append(f"| {r['model']} | {median_of(r['vkrt_runs'], 'whole'):.2f} | "
                     f"{median_of(r['cycles']['runs'], 'whole'):.2f} | {q['relmse_at_equal_spp']:.2f} | "
                     f"{q['efficiency_whole_process']:.2f} | {q['efficiency_steady']:.2f} | "
                     f"{q['samples_per_second_steady']:.2f} | {q['relmse_at_equal_time']:.2f} |")
    good = [r["ratios"] for r in rows if "ratios" in r]
    if good:
        gm = lambda key: float(np.exp(np.mean([np.log(q[key]) for q in good])))  # noqa: E731
        lines.append(f"| **geometric mean** | | | {gm('relmse_at_equal_spp'):.2f} | "
                     f"{gm('efficiency_whole_process'):.2f} | {gm('efficiency_steady'):.2f} | "
                     f"{gm('samples_per_second_steady'):.2f} | {gm('relmse_at_equal_time'):.2f} |")
    return "\n".join(lines) + "\n"


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("files", nargs="*", type=Path)
    p.add_argument("--models", type=Path)
    p.add_argument("--width", type=int, default=240)
    p.add_argument("--height", type=int, default=180)
    p.add_argument("--spp", type=int, default=64)
    p.add_argument("--steady-spp", type=int, default=256)
    p.add_argument("--reference-spp", type=int, default=1024)
    p.add_argument("--runs", type=int, default=3)
    p.add_argument("--threads", type=int, default=0)
    p.add_argument("--out", type=Path, default=Path("bench-vs-cycles"))
    p.add_argument("--json")
    p.add_argument("--table")
    p.add_argument("--cycles-from", type=Path)
    p.add_argument("--vkrt")
    p.add_argument("--vkrt-command")
    p.add_argument("--vkrt-root")
    args = p.parse_args(argv)
    for name in ("width", "height", "spp", "steady_spp", "reference_spp", "runs"):
        if getattr(args, name) < 1:
            p.error(f"--{name.replace('_', '-')} must be at least 1")
    if args.threads < 0:
        p.error("--threads must be 0 (all) or more")
    if not args.files and not args.models:
        p.error("name .gltf files or --models DIR")
    return args


def main(argv) -> int:
    args = parse_args(argv)
    models = [(f.stem, f) for f in args.files]
    if args.models:
        if not args.models.is_dir():
            sys.exit(f"bench_vs_cycles: error: --models {args.models}: not a folder")
        models += cc.model_files(args.models)
    for name, f in models:
        if not f.is_file():
            sys.exit(f"bench_vs_cycles: error: {f}: no such file")
    before = {}
    if args.cycles_from:
        earlier = json.loads(args.cycles_from.read_text())
        same = all(earlier["settings"][k] == getattr(args, k)
                   for k in ("width", "height", "spp", "steady_spp", "reference_spp"))
        if not same:
            sys.exit(f"bench_vs_cycles: error: --cycles-from {args.cycles_from}: rendered at other settings "
                     f"({earlier['settings']})")
        before = {r["model"]: r["cycles"] for r in earlier["models"] if "cycles" in r}
    args.out.mkdir(parents=True, exist_ok=True)
    vkrt = Vkrt(args)
    rows = []
    for name, source in models:
        cc.log(f"{name}")
        try:
            rows.append(bench_model(name, source, args, vkrt, args.out, before.get(name)))
        except (RuntimeError, ValueError, KeyError) as error:
            rows.append({"model": name, "error": str(error)})
            cc.log(f"{name}: {error}")
    settings = {k: getattr(args, k) for k in ("width", "height", "spp", "steady_spp", "reference_spp", "runs")}
    document = {"settings": settings, "models": rows}
    if args.json:
        Path(args.json).write_text(json.dumps(document, indent=1) + "\n")
    table = markdown(rows, args)
    if args.table:
        Path(args.table).write_text(table)
    print(table, end="")
    return 1 if any("error" in r for r in rows) else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

#!/usr/bin/env python3
"""How long a glTF model takes to show its first frame, cold and warm, whole
process (what a user waits for `vkrt render MODEL.gltf --spp 1`).

    tools/bench_startup.py [MODEL.gltf ...] [--models DIR] [--runs 3] [--json FILE] [--table FILE]

Cold: every cache empty (a fresh folder each run for vkrt's SPIR-V cache,
$VKRT_CACHE_DIR, its texture cache inside it, and Mesa's shader cache,
$MESA_SHADER_CACHE_DIR), as on the first render of a model on a new machine.
Warm: the same command again with those caches filled. Each run is timed
from the process's start to its exit; medians of --runs. A cold `vkrt info
--json` run (fresh caches too) gives the split of a cold start: parse,
textures, mesh files, BVH, glslang, set-up and first frame (the driver's
compile of the kernel and one frame).

Needs only Python's standard library (it runs in a Debian 13 chroot to
measure Mesa 26). --vkrt PATH picks the binary [$VKRT, else build/vkrt].
--compare A=BINARY[@SHADER_DIR] B=BINARY[@SHADER_DIR] times two builds (or
shader trees, through VKRT_SHADER_DIR) instead, interleaved: each of --runs
pairs runs both, in an order that reverses every other pair, and the table
gives both medians and the median of the pairs' B/A ratios, cold and warm.
"""
from __future__ import annotations

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


def model_files(directory: Path) -> list[tuple[str, Path]]:
    found = []
    for sub in sorted(p for p in directory.iterdir() if p.is_dir()):
        files = sorted((sub / "glTF").glob("*.gltf")) or sorted(sub.glob("*.gltf"))
        files = [f for f in files if not f.name.startswith((".", "_"))]
        if files:
            found.append((sub.name, files[0]))
    return found


def run(command: list[str], caches: Path, shaders: str | None = None) -> tuple[float, subprocess.CompletedProcess]:
    env = dict(os.environ, VKRT_CACHE_DIR=str(caches / "spirv"), MESA_SHADER_CACHE_DIR=str(caches / "mesa"))
    env.pop("VKRT_TEXTURE_CACHE_DIR", None)  # inside VKRT_CACHE_DIR
    if shaders:
        env["VKRT_SHADER_DIR"] = shaders
    started = time.perf_counter()
    done = subprocess.run(command, capture_output=True, text=True, env=env)
    return time.perf_counter() - started, done


def bench_model(vkrt: str, model: Path, runs: int, work: Path) -> dict:
    render = [vkrt, "render", str(model), "--spp", "1", "-o", str(work / "frame.exr")]
    cold, warm = [], []
    for r in range(runs):
        caches = Path(tempfile.mkdtemp(prefix="cold-", dir=work))
        seconds, done = run(render, caches)
        if done.returncode != 0:
            raise RuntimeError(f"vkrt exited {done.returncode}: {done.stderr.strip()[-800:]}")
        cold.append(seconds)
        seconds, done = run(render, caches)
        if done.returncode != 0:
            raise RuntimeError(f"vkrt exited {done.returncode}: {done.stderr.strip()[-800:]}")
        warm.append(seconds)
    caches = Path(tempfile.mkdtemp(prefix="info-", dir=work))
    _, done = run([vkrt, "info", str(model), "--json", "-"], caches)
    if done.returncode != 0:
        raise RuntimeError(f"vkrt info exited {done.returncode}: {done.stderr.strip()[-800:]}")
    info = json.loads(done.stdout)
    return {"cold": statistics.median(cold), "warm": statistics.median(warm), "cold_runs": cold, "warm_runs": warm,
            "cold_split": info["startup"], "device": info["device"]}


def cold_and_warm(binary: str, shaders: str | None, model: Path, work: Path) -> tuple[float, float]:
    """One cold start (fresh caches) and one warm start after it."""
    render = [binary, "render", str(model), "--spp", "1", "-o", str(work / "frame.exr")]
    caches = Path(tempfile.mkdtemp(prefix="cold-", dir=work))
    seconds = []
    for _ in ("cold", "warm"):
        elapsed, done = run(render, caches, shaders)
        if done.returncode != 0:
            raise RuntimeError(f"{binary} exited {done.returncode}: {done.stderr.strip()[-800:]}")
        seconds.append(elapsed)
    return seconds[0], seconds[1]


def compare_model(builds: list, model: Path, runs: int, work: Path) -> dict:
    times = {name: [] for name, _, _ in builds}
    for r in range(runs):
        for name, binary, shaders in builds if r % 2 == 0 else builds[::-1]:
            times[name].append(cold_and_warm(binary, shaders, model, work))
    (a, _, _), (b, _, _) = builds
    row = {"runs": times}
    for k, kind in enumerate(("cold", "warm")):
        row[kind] = {name: statistics.median(t[k] for t in times[name]) for name in times}
        row[kind + "_ratio"] = statistics.median(tb[k] / ta[k] for ta, tb in zip(times[a], times[b]))
    return row


def compare_markdown(rows: list, builds: list) -> str:
    a, b = builds[0][0], builds[1][0]
    lines = [f"Start-up of `vkrt render MODEL --spp 1`, whole process, {a} against {b} interleaved: medians and "
             f"the median of the pairs' {b}/{a} ratios (tools/bench_startup.py --compare).", "",
             f"| model | cold s, {a} | {b} | ratio | warm s, {a} | {b} | ratio |",
             "| --- | ---: | ---: | ---: | ---: | ---: | ---: |"]
    for r in rows:
        if "error" in r:
            lines.append(f"| {r['model']} | {r['error'][:100]} | | | | | |")
            continue
        lines.append(f"| {r['model']} | {r['cold'][a]:.2f} | {r['cold'][b]:.2f} | {r['cold_ratio']:.2f} | "
                     f"{r['warm'][a]:.2f} | {r['warm'][b]:.2f} | {r['warm_ratio']:.2f} |")
    return "\n".join(lines) + "\n"


def parse_build(spec: str) -> tuple[str, str, str | None]:
    name, sep, rest = spec.partition("=")
    if not sep or not name or not rest:
        raise argparse.ArgumentTypeError(f"--compare {spec}: expected NAME=BINARY or NAME=BINARY@SHADER_DIR")
    binary, _, shaders = rest.partition("@")
    return name, binary, shaders or None


def markdown(rows: list) -> str:
    driver = next((r["device"]["driver"] for r in rows if "device" in r), "?")
    lines = [f"Start-up of `vkrt render MODEL --spp 1`, whole process, medians ({driver}; tools/bench_startup.py). "
             "The split is a cold `vkrt info` run's.", "",
             "| model | cold s | warm s | cold split: parse, textures, mesh files + BVH, glslang, set-up, "
             "first frame (driver compile) |",
             "| --- | ---: | ---: | --- |"]
    for r in rows:
        if "error" in r:
            lines.append(f"| {r['model']} | {r['error'][:100]} | | |")
            continue
        s = r["cold_split"]
        lines.append(f"| {r['model']} | {r['cold']:.2f} | {r['warm']:.2f} | {s['parseSeconds']:.2f}, "
                     f"{s['texturesSeconds']:.2f}, {s['meshFilesSeconds'] + s['bvhSeconds']:.2f}, "
                     f"{s['glslangSeconds']:.2f}, {s['setupSeconds']:.2f}, {s['firstFrameSeconds']:.2f} |")
    return "\n".join(lines) + "\n"


def main(argv) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("files", nargs="*", type=Path)
    p.add_argument("--models", type=Path)
    p.add_argument("--runs", type=int, default=3)
    p.add_argument("--json")
    p.add_argument("--table")
    p.add_argument("--vkrt", default=os.environ.get("VKRT") or str(REPO / "build" / "vkrt"))
    p.add_argument("--compare", nargs=2, type=parse_build, metavar="NAME=BINARY[@SHADER_DIR]")
    args = p.parse_args(argv)
    if args.runs < 1:
        p.error("--runs must be at least 1")
    models = [(f.stem, f) for f in args.files] + (model_files(args.models) if args.models else [])
    if not models:
        p.error("name .gltf files or --models DIR")
    for _, f in models:
        if not f.is_file():
            p.error(f"{f}: no such file")
    rows = []
    with tempfile.TemporaryDirectory(prefix="vkrt-startup-") as work:
        for name, model in models:
            print(f"bench_startup: {name}", file=sys.stderr, flush=True)
            try:
                if args.compare:
                    rows.append(dict(model=name, **compare_model(args.compare, model, args.runs, Path(work))))
                else:
                    rows.append(dict(model=name, **bench_model(args.vkrt, model, args.runs, Path(work))))
            except RuntimeError as error:
                rows.append({"model": name, "error": str(error)})
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1) + "\n")
    table = compare_markdown(rows, args.compare) if args.compare else markdown(rows)
    if args.table:
        Path(args.table).write_text(table)
    print(table, end="")
    return 1 if any("error" in r for r in rows) else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

#!/usr/bin/env python3
"""vkrt (Vulkan, here lavapipe) against Mitsuba 3 on the same scenes, side by side.

    tools/bench_vs_mitsuba.sh [--runs 3] [--spp 128] [--scenes A.toml B.toml ...] [--quick]
                              [--variant llvm_ad_rgb|scalar_rgb] [--vkrt-sampler auto|sobol|independent]
                              [--mitsuba-samplers independent,multijitter]
                              [--no-cold] [--markdown FILE] [--json FILE]

Run it through tools/bench_vs_mitsuba.sh, which starts this file with the
Python of .venv-mitsuba (made by tools/make_reference.py).

For every scene, both renderers render the same scene (tools/to_mitsuba.py's
conversion, written once to Mitsuba XML before any timing) at the same
resolution, max depth and spp, each render in a fresh process, in interleaved
order (vkrt first in odd runs, Mitsuba first in even runs), after one untimed
warm-up render of every configuration that fills the caches (vkrt's SPIR-V
cache, Mesa's shader cache, Dr.Jit's kernel cache). Per run and renderer:

* main:    --spp N at the reference's resolution (128x96 for the validation
           scenes): whole-process wall and CPU time, and MSE / relMSE against the
           committed 65536-spp Mitsuba reference (tests/references/validation/
           <scene>/mean.exr) computed by `vkrt compare`;
* low:     N/16 spp, same size: with `main` it gives the steady-state rate
           samples/s = pixels x (N - N/16) / (render seconds(N) - render
           seconds(N/16)), where render seconds are what each renderer reports
           for its rendering alone (vkrt's summary line; Mitsuba: time of the
           mi.render calls, synchronised), so start-up, kernel compilation,
           warm-up frames and per-call tracing cancel out;
* latency: 64 spp at 320x240, whole process;
* first:   1 spp at 320x240, whole process (start-up to the first finished
           frame, written to disk), and vkrt's own `vkrt info` first-frame time.

vkrt renders are plain `vkrt render` calls (no --variance/--report/
--target-error), so vkrt's default sampler applies: with --sampler auto that
is the Owen-scrambled Sobol' sampler. --vkrt-sampler independent|sobol passes
--sampler to vkrt explicitly (independent: the throughput levers alone; auto
passes nothing, so binaries older than --sampler still work).

Mitsuba renders each scene once per sampler of --mitsuba-samplers (default
independent and multijitter: Mitsuba's default and, measured, its best at
equal time on these scenes; stratified, ldsampler and orthogonal are also
accepted), each its own column, in the same interleaved runs. multijitter and
stratified round the spp up to a full grid (128 -> 132): the efficiency, which
divides by the time, absorbs that.

Efficiency = 1 / (median MSE x median whole-process seconds of `main`); its
ratio vkrt/Mitsuba is Mitsuba's MSE x seconds over vkrt's (4 = half the RMSE in
equal time). The report gives the ratio against every Mitsuba sampler and
against the best of them for each scene (the highest efficiency); the speed
table compares with that best sampler's process. Cold start-up (once per scene, 1 spp at 320x240): vkrt with empty
SPIR-V and Mesa caches, Mitsuba with an empty Dr.Jit cache (HOME and
XDG_CACHE_HOME pointed at empty folders).

A scene that tools/to_mitsuba.py refuses (the Whitted demo scene
scenes/default.toml: Whitted integrator, phong, glossy, Schlick Fresnel) is
benchmarked as a derived path-traced approximation (see derive_path_scene),
named "<scene> (as path)"; its reference is a --derived-reference-spp Mitsuba
rendering made once and cached in $XDG_CACHE_HOME/vkrt/bench_vs_mitsuba
(0: no reference, no MSE).

Wall-clock ratios depend on other load on the machine (vkrt runs 4 x cores
lavapipe threads, Mitsuba one per core); the CPU-time columns depend on it much
less.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import platform
import re
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import tomllib
from pathlib import Path

TOOLS = Path(__file__).resolve().parent
REPO = TOOLS.parent
REFERENCES = REPO / "tests" / "references" / "validation"
DEFAULT_SCENES = [REPO / "scenes" / "default.toml"] + sorted((REPO / "scenes" / "validation").glob("*.toml"))

# The Mitsuba render process: as little as a Python user of Mitsuba needs.
# argv: variant xml out.exr spp seed pass_spp
MITSUBA_CHILD = r"""
import sys, time, json
variant, xml, out, spp, seed, pass_spp = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4]), int(sys.argv[5]), int(sys.argv[6])
t0 = time.perf_counter()
import mitsuba as mi
import drjit as dr
mi.set_variant(variant)
t1 = time.perf_counter()
scene = mi.load_file(xml)
t2 = time.perf_counter()
passes, left = [], spp
while left > 0:
    passes.append(min(left, pass_spp)); left -= passes[-1]
render = 0.0
acc = None
for p, n in enumerate(passes):
    tr = time.perf_counter()
    img = mi.render(scene, spp=n, seed=seed * 1024 + p)
    dr.eval(img)
    dr.sync_thread()
    render += time.perf_counter() - tr
    if len(passes) == 1:
        acc = img
    else:
        import numpy as np
        a = np.array(img, dtype=np.float64) * n
        acc = a if acc is None else acc + a
t3 = time.perf_counter()
if len(passes) > 1:
    import numpy as np
    acc = mi.TensorXf(np.ascontiguousarray(acc / spp, dtype=np.float32))
mi.Bitmap(acc, mi.Bitmap.PixelFormat.RGB).write(out)
t4 = time.perf_counter()
print(json.dumps({"import": t1 - t0, "load": t2 - t1, "render": render, "write": t4 - t3}))
"""


def log(message: str) -> None:
    print(f"bench_vs_mitsuba: {message}", file=sys.stderr, flush=True)


def fail(message: str, status: int = 2):
    log(f"error: {message}")
    sys.exit(status)


def median(values):
    values = [v for v in values if v is not None and math.isfinite(v)]
    return statistics.median(values) if values else None


MITSUBA_SAMPLERS = ("independent", "multijitter", "stratified", "ldsampler", "orthogonal")


def parse_samplers(text: str):
    names = [n.strip() for n in text.split(",") if n.strip()]
    bad = [n for n in names if n not in MITSUBA_SAMPLERS]
    if bad or not names:
        raise argparse.ArgumentTypeError(f"'{text}': expected a comma-separated list of {', '.join(MITSUBA_SAMPLERS)}")
    return list(dict.fromkeys(names))


def parse_size(text: str):
    m = re.fullmatch(r"(\d+)x(\d+)", text)
    if not m:
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT, got '{text}'")
    return int(m.group(1)), int(m.group(2))


# ----------------------------------------------------------------------------
# Scenes
# ----------------------------------------------------------------------------

def derive_path_scene(src: Path, dst: Path) -> list[str]:
    """Write a path-integrator approximation of a scene that Mitsuba cannot
    render (Whitted, phong, glossy, Schlick Fresnel); return the substitutions."""
    data = tomllib.loads(src.read_text())
    changes = []
    render = data.setdefault("render", {})
    if render.get("integrator", "whitted") != "path":
        render["integrator"] = "path"
        changes.append("integrator whitted -> path")
    for name, m in data.get("materials", {}).items():
        t = m.get("type")
        if t == "phong":
            data["materials"][name] = {"type": "lambert", "albedo": m.get("diffuse", 0.8)}
            changes.append(f"{name}: phong -> lambert (diffuse kept, specular lobe dropped)")
        elif t == "glossy":
            data["materials"][name] = {"type": "mirror", "reflectance": m.get("reflectance", 1.0)}
            changes.append(f"{name}: glossy -> mirror (fresnel none)")
        elif t == "mirror" and m.get("fresnel", "none") != "none":
            data["materials"][name] = {"type": "mirror", "reflectance": m.get("reflectance", 1.0)}
            changes.append(f"{name}: mirror fresnel {m['fresnel']} -> none")
        elif t == "dielectric" and m.get("fresnel", "exact") != "exact":
            m = dict(m)
            m["fresnel"] = "exact"
            data["materials"][name] = m
            changes.append(f"{name}: dielectric Schlick -> exact Fresnel")
    cube = data.get("background", {}).get("cubemap")
    if cube:
        for k, v in cube.items():
            p = Path(v)
            cube[k] = str(p if p.is_absolute() else (src.parent / p).resolve())
    dst.write_text(toml_dumps(data))
    return changes


def toml_dumps(data: dict) -> str:
    """Just enough TOML for vkrt scenes: tables, arrays of tables, numbers,
    strings, booleans and (nested) arrays."""
    def value(v):
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, (int, float)):
            return repr(v)
        if isinstance(v, str):
            return json.dumps(v)
        if isinstance(v, list):
            return "[" + ", ".join(value(x) for x in v) + "]"
        raise TypeError(v)

    out = []

    def table(prefix, t):
        scalars = {k: v for k, v in t.items() if not isinstance(v, dict)
                   and not (isinstance(v, list) and v and isinstance(v[0], dict))}
        if prefix and scalars:
            out.append(f"[{prefix}]")
        for k, v in scalars.items():
            out.append(f"{json.dumps(k)} = {value(v)}")
        if scalars:
            out.append("")
        for k, v in t.items():
            key = f"{prefix}.{json.dumps(k)}" if prefix else json.dumps(k)
            if isinstance(v, dict):
                table(key, v)
            elif isinstance(v, list) and v and isinstance(v[0], dict):
                for item in v:
                    out.append(f"[[{key}]]")
                    for ik, iv in item.items():
                        out.append(f"{json.dumps(ik)} = {value(iv)}")
                    out.append("")

    table("", data)
    return "\n".join(out) + "\n"


class Scene:
    def __init__(self, name, vkrt_path, xml, reference, size, max_depth, notes):
        self.name = name
        self.vkrt_path = vkrt_path  # the TOML vkrt renders
        self.xml = xml              # {((w, h), sampler): Mitsuba XML}
        self.reference = reference  # mean.exr or None
        self.size = size            # (w, h) of the main measurement
        self.max_depth = max_depth
        self.notes = notes


def prepare_scenes(args, work: Path):
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    mi.set_log_level(mi.LogLevel.Warn)
    sys.path.insert(0, str(TOOLS))
    import to_mitsuba

    to_mitsuba._note = lambda message: None  # its notes are about the derived scene's unused materials etc.
    scenes = []
    for path in args.scenes:
        path = Path(path).resolve()
        if not path.is_file():
            fail(f"scene '{path}' does not exist")
        name = path.stem if path.parent.name in ("validation", "scenes") else f"{path.parent.name}/{path.stem}"
        notes = []
        vkrt_path = path
        try:
            to_mitsuba.convert(path, files_dir=work / "probe", envmap_width=64)
        except to_mitsuba.ConversionError as e:
            if not args.derive:
                log(f"skipping {path}: {e}")
                continue
            vkrt_path = work / f"{path.stem}-as-path.toml"
            changes = derive_path_scene(path, vkrt_path)
            name += " (as path)"
            reason = str(e).split(": ", 1)[-1].split(";")[0]
            notes.append(f"{path.relative_to(REPO) if path.is_relative_to(REPO) else path} cannot be rendered by "
                         f"Mitsuba ({reason}); benchmarked as a derived path-traced scene \"{name}\": "
                         + "; ".join(changes))
            log(notes[-1])
        ref = REFERENCES / path.stem / "mean.exr"
        reference = None
        if vkrt_path == path and ref.is_file():
            bmp = mi.Bitmap(str(ref))
            ref_size = (bmp.width(), bmp.height())
            reference = ref
            size = args.size or ref_size
            if size != ref_size:
                notes.append(f"{name}: reference is {ref_size[0]}x{ref_size[1]}, not {size[0]}x{size[1]}: no MSE")
                reference = None
        else:
            size = args.size or (128, 96)
        max_depth = tomllib.loads(vkrt_path.read_text()).get("render", {}).get("max_depth", 5)
        xml = {}
        for w, h in {size, args.latency_size}:
            files = work / f"{path.stem}-files"
            d = to_mitsuba.convert(vkrt_path, files_dir=files, envmap_width=args.envmap_width, spp=1)
            d["sensor"]["film"]["width"] = w
            d["sensor"]["film"]["height"] = h
            for sampler in args.mitsuba_samplers:
                d["sensor"]["sampler"]["type"] = sampler
                xml[((w, h), sampler)] = work / f"{path.stem}-{w}x{h}-{sampler}.xml"
                to_mitsuba.write_xml(d, xml[((w, h), sampler)])
        scenes.append(Scene(name, vkrt_path, xml, reference, size, max_depth, notes))
    return scenes


def derived_reference(args, runner, scene: Scene, work: Path):
    """A Mitsuba reference for a scene without a committed one (a derived scene),
    made once with --derived-reference-spp samples and cached."""
    import hashlib

    import mitsuba as mi

    key = hashlib.sha256("\n".join([scene.vkrt_path.read_text(), f"{scene.size}", f"{args.derived_reference_spp}",
                                    f"{args.envmap_width}", mi.__version__]).encode()).hexdigest()[:16]
    cache = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "vkrt" / "bench_vs_mitsuba"
    path = cache / f"{scene.vkrt_path.stem}-{scene.size[0]}x{scene.size[1]}-{args.derived_reference_spp}spp-{key}.exr"
    if not path.is_file():
        cache.mkdir(parents=True, exist_ok=True)
        log(f"{scene.name}: rendering a {args.derived_reference_spp}-spp Mitsuba reference (once; cached as {path})")
        start = time.perf_counter()
        tmp = work / "reference.exr"
        runner.mitsuba_render(scene, scene.size, args.derived_reference_spp, 999, tmp, sampler=args.mitsuba_samplers[0])
        shutil.move(tmp, path)
        log(f"{scene.name}: reference took {time.perf_counter() - start:.0f} s")
    scene.reference = path
    scene.notes.append(f"{scene.name}: MSE against a {args.derived_reference_spp}-spp Mitsuba ({args.variant}) "
                       f"rendering of the derived scene (its own noise adds about {args.spp}/"
                       f"{args.derived_reference_spp} of the measured MSE to both renderers)")


# ----------------------------------------------------------------------------
# Running the renderers
# ----------------------------------------------------------------------------

class Runner:
    def __init__(self, args, work: Path):
        self.args = args
        self.work = work
        self.vkrt = args.vkrt
        self.python = sys.executable
        self.mitsuba_env = dict(os.environ)
        if args.libllvm:
            self.mitsuba_env["DRJIT_LIBLLVM_PATH"] = args.libllvm
        self.variant = args.variant

    def _run(self, cmd, env=None, what=""):
        """Wall seconds, CPU seconds (user + system, all threads) and output of one process."""
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        start = time.perf_counter()
        p = subprocess.run(cmd, env=env, capture_output=True, text=True)
        seconds = time.perf_counter() - start
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        self.last_cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        if p.returncode != 0:
            fail(f"{what} failed (exit {p.returncode}): {' '.join(map(str, cmd))}\n{p.stdout}{p.stderr}", 1)
        return seconds, p.stdout + p.stderr

    def vkrt_render(self, scene: Scene, size, spp, seed, out, env=None):
        facts = Path(str(out) + ".json")
        cmd = [self.vkrt, "render", str(scene.vkrt_path), "-o", str(out), "--spp", str(spp),
               "--width", str(size[0]), "--height", str(size[1]), "--seed", str(seed), "--json", str(facts)]
        if self.args.vkrt_sampler != "auto":
            cmd += ["--sampler", self.args.vkrt_sampler]
        whole, _ = self._run(cmd, env, "vkrt render")
        j = json.loads(facts.read_text())  # vkrt's machine output (docs/machine-output.md)
        return {"whole": whole, "cpu": self.last_cpu, "render": j["renderSeconds"],
                "reported_rate": j["samplesPerSecond"], "startup": j["startupSeconds"]}

    def vkrt_first_frame(self, scene: Scene):
        facts = self.work / "info.json"
        self._run([self.vkrt, "info", str(scene.vkrt_path), "--json", str(facts)], None, "vkrt info")
        return json.loads(facts.read_text()).get("firstFrameSeconds")

    def mitsuba_render(self, scene: Scene, size, spp, seed, out, env=None, sampler="independent"):
        cmd = [self.python, "-c", MITSUBA_CHILD, self.variant, str(scene.xml[(size, sampler)]), str(out), str(spp),
               str(seed), str(self.args.pass_spp)]
        whole, text = self._run(cmd, env or self.mitsuba_env, "Mitsuba render")
        # The timing line may follow a warning's colour reset code on the same line.
        lines = [ln[ln.index('{"import"'):] for ln in text.splitlines() if '{"import"' in ln]
        if not lines:
            fail(f"no timing line from the Mitsuba process:\n{text}", 1)
        t = json.loads(lines[-1])
        return {"whole": whole, "cpu": self.last_cpu, "render": t["render"], "import": t["import"], "load": t["load"]}

    def mse(self, image, reference):
        """MSE and relMSE as `vkrt compare` measures them, through vkrt's Python module."""
        vkrt = import_vkrt()
        e = vkrt.measure_error(vkrt.read_exr(image)[0]["image"], vkrt.read_exr(reference)[0]["image"])
        return e["mse"], e["rel_mse"]


def import_vkrt():
    """vkrt's Python module (docs/python.md): installed, or the build tree's package."""
    try:
        import vkrt
    except ImportError:
        sys.path.insert(0, str(REPO / "build" / "python"))
        import vkrt
    return vkrt


def cold_env(base: dict, root: Path) -> dict:
    """Environment whose caches are all empty folders under root."""
    root.mkdir(parents=True)
    env = dict(base)
    env.update({"HOME": str(root), "XDG_CACHE_HOME": str(root / "cache"),
                "VKRT_CACHE_DIR": str(root / "vkrt"), "MESA_SHADER_CACHE_DIR": str(root / "mesa"),
                "MESA_GLSL_CACHE_DIR": str(root / "mesa")})
    return env


# ----------------------------------------------------------------------------
# Main
# ----------------------------------------------------------------------------

def choose_variant(args) -> list[str]:
    """Pick the Mitsuba variant for the render processes; notes on fallbacks."""
    notes = []
    if args.variant.startswith("llvm"):
        sys.path.insert(0, str(TOOLS))
        from make_reference import find_libllvm  # noqa: PLC0415

        args.libllvm = find_libllvm()
        m = re.search(r"libLLVM(?:-|\.so\.)(\d+)", os.path.basename(args.libllvm or ""))
        if m and int(m.group(1)) < 16:
            notes.append(f"DRJIT_LIBLLVM_PATH={args.libllvm} is LLVM {m.group(1)}; Dr.Jit needs >= 16: ignoring it")
            os.environ.pop("DRJIT_LIBLLVM_PATH", None)
            args.libllvm = find_libllvm()
        if args.libllvm is None:
            notes.append("no libLLVM >= 16 found (apt-get install libllvm19, or set DRJIT_LIBLLVM_PATH): "
                         "Mitsuba falls back to scalar_rgb, which is several times slower")
            args.variant = "scalar_rgb"
    if args.variant.startswith("llvm"):
        env = dict(os.environ, DRJIT_LIBLLVM_PATH=args.libllvm)
        # A small render, not just an import: a wrong libLLVM can pass set_variant and abort later.
        probe = subprocess.run([sys.executable, "-c", f"import mitsuba as mi; mi.set_variant('{args.variant}'); "
                                "d = mi.cornell_box(); d['sensor']['film']['width'] = 8; "
                                "d['sensor']['film']['height'] = 8; print(mi.render(mi.load_dict(d), spp=1).shape)"],
                               env=env, capture_output=True, text=True)
        if probe.returncode != 0:
            why = (probe.stderr.strip().splitlines() or [f"exit status {probe.returncode}"])[-1]
            notes.append(f"Mitsuba variant {args.variant} does not work with {args.libllvm} ({why}): "
                         "falling back to scalar_rgb")
            args.variant = "scalar_rgb"
    for n in notes:
        log(n)
    return notes


def commit() -> str:
    """The checkout's commit, and whether shaders/, src/ or tools/ differ from it."""
    def git(*a):
        p = subprocess.run(["git", "-C", str(REPO), *a], capture_output=True, text=True)
        return p.stdout.strip() if p.returncode == 0 else ""
    head = git("rev-parse", "--short", "HEAD") or "unknown"
    dirty = git("status", "--porcelain", "--", "shaders", "src", "tools")
    return head + (" (with uncommitted changes)" if dirty else "")


def fmt(x, digits=3):
    if x is None:
        return "—"
    if x == 0:
        return "0"
    if abs(x) >= 1e6:
        return f"{x / 1e6:.{digits}g} M"
    if abs(x) >= 1e3:
        return f"{x / 1e3:.{digits}g} k"
    if abs(x) < 1e-2:
        return f"{x:.{digits}g}"
    return f"{x:.{digits}g}"


def ratio(a, b):
    if a is None or b is None or b == 0:
        return None
    return a / b


def geomean(values):
    values = [v for v in values if v is not None and v > 0]
    return math.exp(sum(math.log(v) for v in values) / len(values)) if values else None


def main(argv) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    ap.add_argument("--scenes", nargs="+", default=None,
                    help="vkrt scenes (default: scenes/default.toml and scenes/validation/*.toml)")
    ap.add_argument("--runs", type=int, default=3, help="timed runs per configuration (default %(default)s)")
    ap.add_argument("--spp", type=int, default=128, help="spp of the main (MSE) render (default %(default)s)")
    ap.add_argument("--size", type=parse_size, default=None,
                    help="WxH of the main render (default: the reference's size, else 128x96)")
    ap.add_argument("--latency-size", type=parse_size, default=(320, 240), help="default %(default)s")
    ap.add_argument("--latency-spp", type=int, default=64, help="default %(default)s")
    ap.add_argument("--quick", action="store_true",
                    help="1 run, 64 spp, three validation scenes, no cold start: a smoke test")
    ap.add_argument("--variant", default="llvm_ad_rgb", choices=["llvm_ad_rgb", "scalar_rgb"])
    ap.add_argument("--no-cold", action="store_true", help="skip the cold-cache start-up measurement")
    ap.add_argument("--no-derive", dest="derive", action="store_false",
                    help="skip scenes Mitsuba cannot render instead of deriving a path-traced approximation")
    ap.add_argument("--vkrt", default=os.environ.get("VKRT", str(REPO / "build" / "vkrt")),
                    help="vkrt binary (default: $VKRT, else build/vkrt)")
    ap.add_argument("--vkrt-sampler", default="auto", choices=["auto", "sobol", "independent"],
                    help="vkrt's --sampler (default %(default)s: no flag, vkrt's own default, which is Sobol' "
                         "for these plain renders; independent: without the Sobol' sampler)")
    ap.add_argument("--mitsuba-samplers", type=parse_samplers, default=["independent", "multijitter"],
                    help="Mitsuba samplers to measure, comma-separated (default independent,multijitter; "
                         f"any of {','.join(MITSUBA_SAMPLERS)})")
    ap.add_argument("--envmap-width", type=int, default=2048,
                    help="width of the equirectangular map Mitsuba gets for a cubemap (default %(default)s; "
                         "tools/to_mitsuba.py's own default, up to 8192, would make Mitsuba load a map of up "
                         "to 400 MB in every process)")
    ap.add_argument("--pass-spp", type=int, default=256,
                    help="largest spp per mi.render call (bounds Mitsuba's memory; default %(default)s)")
    ap.add_argument("--derived-reference-spp", type=int, default=8192,
                    help="spp of the cached Mitsuba reference made for a derived scene (0: none, no MSE; "
                         "default %(default)s)")
    ap.add_argument("--markdown", help="also write the Markdown report here")
    ap.add_argument("--json", help="also write every measurement as JSON here")
    ap.add_argument("--keep", action="store_true", help="keep the work folder (images, XML)")
    args = ap.parse_args(argv)
    args.libllvm = None
    if args.quick:
        args.runs = 1
        args.spp = 64
        args.no_cold = True
        args.derived_reference_spp = 0
        if args.scenes is None:
            args.scenes = [str(REPO / "scenes" / "validation" / f"{s}.toml")
                           for s in ("diffuse-box", "glass", "environment-sky")]
    if args.scenes is None:
        args.scenes = [str(p) for p in DEFAULT_SCENES]
    if args.runs < 1 or args.spp < 16:
        ap.error("--runs must be >= 1 and --spp >= 16")
    if not os.access(args.vkrt, os.X_OK):
        fail(f"no vkrt binary at {args.vkrt} (build it, or pass --vkrt / set VKRT)")
    args.vkrt = str(Path(args.vkrt).resolve())
    low_spp = max(1, args.spp // 16)

    try:
        import mitsuba  # noqa: F401
    except ImportError:
        fail("cannot import mitsuba; create the environment with tools/make_reference.py (it makes "
             ".venv-mitsuba on first use) and run this through tools/bench_vs_mitsuba.sh")

    notes = choose_variant(args)
    work = Path(tempfile.mkdtemp(prefix="vkrt-vs-mitsuba-"))
    try:
        scenes = prepare_scenes(args, work)
        runner = Runner(args, work)
        if args.derived_reference_spp > 0:
            for s in scenes:
                if s.reference is None and s.vkrt_path.parent == work:
                    derived_reference(args, runner, s, work)
        for s in scenes:
            notes += [n for n in s.notes if n not in notes]
        return run(args, runner, scenes, notes, work, low_spp)
    finally:
        if args.keep:
            log(f"kept {work}")
        else:
            shutil.rmtree(work, ignore_errors=True)


def run(args, runner: Runner, scenes, notes, work: Path, low_spp: int) -> int:
    import mitsuba as mi
    import drjit

    started = time.time()
    load_start = os.getloadavg()
    lat = args.latency_size
    samplers = args.mitsuba_samplers
    mitsubas = [f"mitsuba:{m}" for m in samplers]
    results = {s.name: {who: {} for who in ["vkrt"] + mitsubas} for s in scenes}

    def render_as(who):
        if who == "vkrt":
            return runner.vkrt_render
        sampler = who.split(":", 1)[1]
        return lambda *a, **k: runner.mitsuba_render(*a, **k, sampler=sampler)

    def add(scene, renderer, key, value):
        results[scene.name][renderer].setdefault(key, []).append(value)

    # Warm-up: every configuration once, untimed (fills every cache).
    log(f"warming up ({len(scenes)} scenes)")
    for s in scenes:
        for size in {s.size, lat}:
            for who in ["vkrt"] + mitsubas:
                render_as(who)(s, size, 1, 0, work / "warm.exr")
        runner.vkrt_first_frame(s)

    # Cold start-up: once per scene, empty caches.
    if not args.no_cold:
        log("cold start-up (empty caches)")
        for i, s in enumerate(scenes):
            env = cold_env(os.environ, work / f"cold-vkrt-{i}")
            r = runner.vkrt_render(s, lat, 1, 0, work / "cold.exr", env)
            add(s, "vkrt", "cold_first", r["whole"])
            env = cold_env(runner.mitsuba_env, work / f"cold-mitsuba-{i}")
            r = render_as(mitsubas[0])(s, lat, 1, 0, work / "cold.exr", env)
            for who in mitsubas:  # the sampler does not change what a cold start compiles
                add(s, who, "cold_first", r["whole"])

    for run_index in range(args.runs):
        order = ["vkrt"] + mitsubas if run_index % 2 == 0 else mitsubas[::-1] + ["vkrt"]
        log(f"run {run_index + 1}/{args.runs} (order: {' then '.join(order)})")
        seed = 1000 + run_index
        for s in scenes:
            for who in order:
                render = render_as(who)
                out = work / f"{who.replace(':', '-')}-{run_index}.exr"
                r = render(s, s.size, args.spp, seed, out)
                add(s, who, "main_whole", r["whole"])
                add(s, who, "main_cpu", r["cpu"])
                add(s, who, "main_render", r["render"])
                if who == "vkrt":
                    add(s, who, "reported_rate", r["reported_rate"])
                if s.reference is not None:
                    mse, rel = runner.mse(out, s.reference)
                    add(s, who, "mse", mse)
                    add(s, who, "relmse", rel)
                r = render(s, s.size, low_spp, seed + 7919, work / "low.exr")
                add(s, who, "low_render", r["render"])
                add(s, who, "low_whole", r["whole"])
                add(s, who, "low_cpu", r["cpu"])
                r = render(s, lat, args.latency_spp, seed, work / "lat.exr")
                add(s, who, "latency", r["whole"])
                add(s, who, "latency_cpu", r["cpu"])
                r = render(s, lat, 1, seed, work / "first.exr")
                add(s, who, "first", r["whole"])
                if who == "vkrt":
                    add(s, who, "info_first_frame", runner.vkrt_first_frame(s))
                else:
                    add(s, who, "import", r["import"])
                    add(s, who, "load", r["load"])

    # Summaries.
    rows = []
    for s in scenes:
        row = {"scene": s.name, "size": s.size, "max_depth": s.max_depth, "reference": str(s.reference or "")}
        for who in ["vkrt"] + mitsubas:
            m = results[s.name][who]
            pixels = s.size[0] * s.size[1]
            rates = [pixels * (args.spp - low_spp) / (a - b) for a, b in zip(m["main_render"], m["low_render"])
                     if a > b]
            med = {k: median(v) for k, v in m.items()}
            med["rate"] = median(rates)
            cpu_rates = [pixels * (args.spp - low_spp) / (a - b) for a, b in zip(m["main_cpu"], m["low_cpu"]) if a > b]
            med["cpu_rate"] = median(cpu_rates)
            med["efficiency"] = (1.0 / (med["mse"] * med["main_whole"])) if med.get("mse") else None
            med["cpu_efficiency"] = (1.0 / (med["mse"] * med["main_cpu"])) if med.get("mse") else None
            row[who] = med
        # The best Mitsuba sampler for this scene: the highest efficiency (the
        # first sampler where there is no reference to measure error against).
        effs = {who: row[who]["efficiency"] for who in mitsubas if row[who]["efficiency"]}
        best = max(effs, key=effs.get) if effs else mitsubas[0]
        row["mitsuba_best"] = best.split(":", 1)[1]
        row["mitsuba"] = row[best]
        rows.append(row)
    elapsed = time.time() - started

    # Report.
    date = subprocess.run(["date"], capture_output=True, text=True).stdout.strip()
    cpu = next((ln.split(":", 1)[1].strip() for ln in Path("/proc/cpuinfo").read_text().splitlines()
                if ln.startswith("model name")), platform.processor())
    device = subprocess.run([args.vkrt, "devices"], capture_output=True, text=True).stdout.splitlines()
    device = next((d.split(":", 1)[1].strip() for d in device if d.startswith("*")), "?")
    command = "tools/bench_vs_mitsuba.sh " + " ".join(sys.argv[1:])
    sampler = subprocess.run([args.vkrt, "render", "--help"], capture_output=True, text=True).stdout
    sampler = (("--sampler " + args.vkrt_sampler) if args.vkrt_sampler != "auto" else
               "vkrt's default (--sampler auto: Sobol' for plain renders)" if "--sampler" in sampler else
               "independent (this vkrt has no --sampler option)")
    lines = [
        f"- date: {date}; {os.cpu_count()} cores ({cpu}); 1-minute load average {load_start[0]:.1f} at the start, "
        f"{os.getloadavg()[0]:.1f} at the end; timed part {elapsed / 60:.1f} min",
        f"- vkrt: `{args.vkrt}` at commit {commit()} on {device}; sampler: {sampler}",
        f"- Mitsuba {mi.__version__} (Dr.Jit {drjit.__version__}), variant **{args.variant}**, samplers "
        f"{', '.join(samplers)}"
        + (f", DRJIT_LIBLLVM_PATH={args.libllvm}" if args.libllvm and args.variant.startswith("llvm") else ""),
        f"- command: `{command}`",
        f"- {args.runs} run{'s' if args.runs > 1 else ''}, medians; main render {args.spp} spp (rate from {args.spp} − {low_spp} spp); "
        f"latency {args.latency_spp} spp at {lat[0]}x{lat[1]}; warm caches unless marked cold",
    ]
    lines += [f"- note: {n}" for n in notes]
    sizes = sorted({f"{r['size'][0]}x{r['size'][1]}" for r in rows})
    lines += ["", f"**Error and efficiency** ({args.spp} spp at {', '.join(sizes)}; MSE against a high-spp "
                  "Mitsuba reference; efficiency = 1 / (MSE × whole-process wall s); ratio > 1: vkrt better. "
                  "CPU s: user + system time of the whole process, all threads; the CPU-based ratio is "
                  "less sensitive to other load on the machine)", "",
              "| scene | MSE vkrt | " + " | ".join(f"MSE {m}" for m in samplers)
              + " | whole s vkrt | " + " | ".join(f"whole s {m}" for m in samplers)
              + " | " + " | ".join(f"efficiency vs {m}" for m in samplers)
              + " | best Mitsuba | **efficiency vkrt / best** | CPU s vkrt | CPU s best | efficiency by CPU s |",
              "|" + " --- |" * (6 + 3 * len(samplers) + 2)]
    for r in rows:
        v, m = r["vkrt"], r["mitsuba"]
        eff = ratio(v["efficiency"], m["efficiency"])
        r["efficiency_ratio"] = eff
        r["efficiency_ratio_by_sampler"] = {x: ratio(v["efficiency"], r[f"mitsuba:{x}"]["efficiency"])
                                            for x in samplers}
        r["cpu_efficiency_ratio"] = ratio(v["cpu_efficiency"], m["cpu_efficiency"])
        lines.append(f"| {r['scene']} | {fmt(v.get('mse'))} | "
                     + " | ".join(fmt(r[f'mitsuba:{x}'].get('mse')) for x in samplers)
                     + f" | {v['main_whole']:.2f} | "
                     + " | ".join(f"{r[f'mitsuba:{x}']['main_whole']:.2f}" for x in samplers)
                     + " | " + " | ".join(fmt(r["efficiency_ratio_by_sampler"][x]) for x in samplers)
                     + f" | {r['mitsuba_best']} | **{fmt(eff)}** "
                     f"| {v['main_cpu']:.2f} | {m['main_cpu']:.2f} | {fmt(r['cpu_efficiency_ratio'])} |")
    g = geomean([r["efficiency_ratio"] for r in rows])
    lines.append("| **geometric mean** | |" + " |" * len(samplers) + " |" + " |" * len(samplers)
                 + "".join(f" {fmt(geomean([r['efficiency_ratio_by_sampler'][x] for r in rows]))} |" for x in samplers)
                 + f" | **{fmt(g)}** | | | {fmt(geomean([r['cpu_efficiency_ratio'] for r in rows]))} |")

    lines += ["", f"**Speed** (against each scene's best Mitsuba sampler above; samples/s: steady state, start-up removed; per CPU s: the same from CPU time; latency: whole process, "
                  f"{args.latency_spp} spp at {lat[0]}x{lat[1]}; first frame: whole process, 1 spp at "
                  f"{lat[0]}x{lat[1]}; ratios > 1: vkrt faster)", "",
              "| scene | samples/s vkrt | samples/s Mitsuba | **ratio** | per CPU s ratio "
              "| latency s vkrt | latency s Mitsuba | **speed-up** "
              "| first frame s vkrt | first frame s Mitsuba | cold first frame s vkrt | cold Mitsuba |",
              "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in rows:
        v, m = r["vkrt"], r["mitsuba"]
        r["rate_ratio"] = ratio(v["rate"], m["rate"])
        r["cpu_rate_ratio"] = ratio(v["cpu_rate"], m["cpu_rate"])
        r["latency_speedup"] = ratio(m["latency"], v["latency"])
        lines.append(f"| {r['scene']} | {fmt(v['rate'])} | {fmt(m['rate'])} | **{fmt(r['rate_ratio'])}** "
                     f"| {fmt(r['cpu_rate_ratio'])} "
                     f"| {v['latency']:.2f} | {m['latency']:.2f} | **{fmt(r['latency_speedup'])}** "
                     f"| {v['first']:.2f} | {m['first']:.2f} | {fmt(v.get('cold_first'))} | {fmt(m.get('cold_first'))} |")
    lines.append(f"| **geometric mean** | | | **{fmt(geomean([r['rate_ratio'] for r in rows]))}** "
                 f"| {fmt(geomean([r['cpu_rate_ratio'] for r in rows]))} | | | "
                 f"**{fmt(geomean([r['latency_speedup'] for r in rows]))}** | | | | |")
    info_ff = median([x for r in rows for x in results[r['scene']]['vkrt'].get('info_first_frame', [])])
    m_imp = median([x for r in rows for who in mitsubas for x in results[r['scene']][who].get('import', [])])
    m_load = median([x for r in rows for who in mitsubas for x in results[r['scene']][who].get('load', [])])
    v_rep = {r["scene"]: r["vkrt"]["reported_rate"] for r in rows}
    lines += ["",
              f"- vkrt's own first-frame time (`vkrt info`, from set-up start, median over scenes and runs): "
              f"{fmt(info_ff)} s. Mitsuba process: `import mitsuba` + set_variant {fmt(m_imp)} s, "
              f"load_file {fmt(m_load)} s (medians).",
              "- vkrt's self-reported samples/s at " + f"{args.spp} spp: "
              + ", ".join(f"{k} {fmt(x)}" for k, x in v_rep.items()) + "."]
    report = "\n".join(lines)
    print(report)
    if args.markdown:
        Path(args.markdown).write_text(report + "\n")
    if args.json:
        Path(args.json).write_text(json.dumps({"args": {k: (v if not isinstance(v, Path) else str(v))
                                                         for k, v in vars(args).items()},
                                               "results": results, "rows": rows, "notes": notes},
                                              indent=1, default=str))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

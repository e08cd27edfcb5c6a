#!/usr/bin/env python3
"""Render a Mitsuba 3 reference image of a vkrt scene.

    tools/make_reference.py SCENE.toml --out DIR [--spp N] [--runs K]
                            [--variant llvm_ad_rgb|scalar_rgb]

Renders K independent runs (different seeds) of N samples per pixel each and
writes, as float32 RGB OpenEXR (channels R, G, B):

* DIR/mean.exr      per-pixel mean over the K runs (an N*K spp estimate);
* DIR/variance.exr  per-pixel variance of that mean: the sample variance
                    across runs (K - 1 in the denominator) divided by K;
* DIR/README.md     the command, Mitsuba version, variant, spp, runs, date and
                    timing.

The first time, it creates a virtual environment .venv-mitsuba in the
repository root, installs the pinned packages of tools/requirements-mitsuba.txt
into it, and re-executes itself there. llvm_ad_rgb (the default) needs a
libLLVM >= 16 (Debian: apt-get install libllvm19); DRJIT_LIBLLVM_PATH is set
to the newest one found, and without one the script falls back to scalar_rgb.
The conversion is tools/to_mitsuba.py's.
"""
from __future__ import annotations

import argparse
import datetime
import glob
import hashlib
import os
import re
import shlex
import subprocess
import sys
import time
from pathlib import Path

TOOLS = Path(__file__).resolve().parent
REPO = TOOLS.parent
VENV = REPO / ".venv-mitsuba"
REQUIREMENTS = TOOLS / "requirements-mitsuba.txt"
MIN_LLVM = 16


def _log(message: str) -> None:
    print(f"make_reference: {message}", flush=True)


def _venv_python() -> Path:
    return VENV / "bin" / "python"


def ensure_venv(argv) -> None:
    """Re-execute inside .venv-mitsuba, creating and filling it when needed."""
    if Path(sys.prefix).resolve() == VENV.resolve():
        return
    python = _venv_python()
    if not python.exists():
        _log(f"creating virtual environment {VENV}")
        subprocess.run([sys.executable, "-m", "venv", str(VENV)], check=True)
    probe = subprocess.run([str(python), "-c", "import mitsuba, numpy"], capture_output=True)
    if probe.returncode != 0:
        if REQUIREMENTS.exists():
            _log(f"installing {REQUIREMENTS.relative_to(REPO)} into {VENV.name}")
            subprocess.run([str(python), "-m", "pip", "install", "-r", str(REQUIREMENTS)], check=True)
        else:
            _log(f"installing mitsuba numpy into {VENV.name} and pinning them in {REQUIREMENTS.name}")
            subprocess.run([str(python), "-m", "pip", "install", "mitsuba", "numpy"], check=True)
            freeze = subprocess.run([str(python), "-m", "pip", "freeze"], check=True, capture_output=True,
                                    text=True).stdout
            pins = [line for line in freeze.splitlines() if re.match(r"(mitsuba|drjit|numpy)==", line)]
            REQUIREMENTS.write_text("# Written by tools/make_reference.py: the versions it installed.\n"
                                    + "\n".join(pins) + "\n")
    os.execv(str(python), [str(python), str(Path(__file__).resolve()), *argv])


def find_libllvm() -> str | None:
    """The newest libLLVM >= 16 on this system, or None."""
    env = os.environ.get("DRJIT_LIBLLVM_PATH")
    if env:
        if Path(env).exists():
            return env
        _log(f"DRJIT_LIBLLVM_PATH={env} does not exist; ignoring it")
        del os.environ["DRJIT_LIBLLVM_PATH"]
    candidates = []
    patterns = ["/usr/lib/llvm-*/lib/libLLVM*.so*", "/usr/lib/*-linux-gnu/libLLVM*.so*", "/usr/lib64/libLLVM*.so*",
                "/usr/local/lib/libLLVM*.so*", "/usr/lib/libLLVM*.so*"]
    for pattern in patterns:
        for path in glob.glob(pattern):
            m = re.search(r"libLLVM(?:-|\.so\.)(\d+)", os.path.basename(path))
            if m and int(m.group(1)) >= MIN_LLVM:
                candidates.append((int(m.group(1)), path))
    if not candidates:
        return None
    return max(candidates)[1]


def choose_variant(requested: str):
    """Import Mitsuba with the requested variant (falling back to scalar_rgb)."""
    variant = requested
    if variant.startswith("llvm"):
        lib = find_libllvm()
        if lib is None:
            _log(f"no libLLVM >= {MIN_LLVM} found (install Debian's libllvm19 or set DRJIT_LIBLLVM_PATH); "
                 "falling back to scalar_rgb")
            variant = "scalar_rgb"
        else:
            os.environ["DRJIT_LIBLLVM_PATH"] = lib
            _log(f"DRJIT_LIBLLVM_PATH={lib}")
    import mitsuba as mi

    try:
        mi.set_variant(variant)
    except Exception as e:  # noqa: BLE001
        if variant == "scalar_rgb":
            raise
        _log(f"variant {variant} is unavailable ({e}); falling back to scalar_rgb")
        variant = "scalar_rgb"
        mi.set_variant(variant)
    return mi, variant


def write_exr(mi, path: Path, image) -> None:
    import numpy as np

    bitmap = mi.Bitmap(np.ascontiguousarray(image, dtype=np.float32), mi.Bitmap.PixelFormat.RGB)
    bitmap.write(str(path))


def main(argv) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    ap.add_argument("scene", help="vkrt scene (.toml), integrator = \"path\"")
    ap.add_argument("--out", required=True, help="output folder (created if missing)")
    ap.add_argument("--spp", type=int, default=1024, help="samples per pixel of each run (default %(default)s)")
    ap.add_argument("--runs", type=int, default=16, help="independent runs, at least 2 (default %(default)s)")
    ap.add_argument("--variant", default="llvm_ad_rgb", choices=["llvm_ad_rgb", "scalar_rgb"],
                    help="Mitsuba variant (default %(default)s)")
    ap.add_argument("--pass-spp", type=int, default=256,
                    help="largest spp per mi.render call; a run is split into passes of at most this "
                         "(bounds memory; default %(default)s)")
    ap.add_argument("--seed", type=int, default=0, help="base seed (default %(default)s)")
    args = ap.parse_args(argv)
    if args.runs < 2:
        ap.error("--runs must be at least 2 (the variance needs two runs)")
    if args.spp < 1 or args.pass_spp < 1:
        ap.error("--spp and --pass-spp must be positive")

    ensure_venv(argv)

    import numpy as np

    mi, variant = choose_variant(args.variant)
    mi.set_log_level(mi.LogLevel.Warn)
    sys.path.insert(0, str(TOOLS))
    import to_mitsuba

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    try:
        scene_dict = to_mitsuba.convert(args.scene, spp=min(args.spp, args.pass_spp))
    except to_mitsuba.ConversionError as e:
        print(f"make_reference: error: {e}", file=sys.stderr)
        return 1
    scene = mi.load_dict(scene_dict)
    load_seconds = time.perf_counter() - start
    _log(f"{args.scene}: Mitsuba {mi.__version__}, {variant}, integrator {scene_dict['integrator']['type']} "
         f"max_depth {scene_dict['integrator']['max_depth']}, {args.runs} runs x {args.spp} spp "
         f"(loaded in {load_seconds:.1f} s)")

    passes = []
    left = args.spp
    while left > 0:
        passes.append(min(left, args.pass_spp))
        left -= passes[-1]

    runs = []
    render_start = time.perf_counter()
    for k in range(args.runs):
        t0 = time.perf_counter()
        acc = None
        for p, spp in enumerate(passes):
            # Distinct seeds for every pass of every run: independent streams.
            seed = (args.seed + k * len(passes) + p) & 0xFFFFFFFF
            image = np.array(mi.render(scene, spp=spp, seed=seed), dtype=np.float64)[..., :3]
            acc = image * spp if acc is None else acc + image * spp
        run = acc / args.spp
        bad = ~np.isfinite(run)
        if bad.any():
            print(f"make_reference: error: run {k} has {int(bad.sum())} non-finite values", file=sys.stderr)
            return 1
        runs.append(run)
        _log(f"run {k + 1}/{args.runs}: {time.perf_counter() - t0:.1f} s")
    render_seconds = time.perf_counter() - render_start

    stack = np.stack(runs)
    mean = stack.mean(axis=0)
    variance = stack.var(axis=0, ddof=1) / args.runs
    write_exr(mi, out / "mean.exr", mean)
    write_exr(mi, out / "variance.exr", variance)

    rel = np.sqrt(variance.mean()) / max(mean.mean(), 1e-30)
    total = time.perf_counter() - start
    scene_path = Path(args.scene)
    digest = hashlib.sha256(scene_path.read_bytes()).hexdigest()
    try:
        shown_scene = scene_path.resolve().relative_to(REPO)
        shown_out = out.resolve().relative_to(REPO)
    except ValueError:
        shown_scene, shown_out = scene_path, out
    command = " ".join(shlex.quote(a) for a in
                       ["tools/make_reference.py", str(shown_scene), "--out", str(shown_out),
                        "--spp", str(args.spp), "--runs", str(args.runs), "--variant", args.variant]
                       + (["--seed", str(args.seed)] if args.seed else []))
    height, width = mean.shape[:2]
    (out / "README.md").write_text(f"""# Mitsuba reference: {scene_path.name}

| | |
|---|---|
| scene | `{shown_scene}` (sha256 `{digest[:16]}…`) |
| command | `{command}` |
| Mitsuba | {mi.__version__} (drjit {__import__('drjit').__version__}) |
| variant | {variant} |
| integrator | {scene_dict['integrator']['type']}, max_depth {scene_dict['integrator']['max_depth']} (vkrt max_depth + 1) |
| image | {width} x {height} |
| spp per run | {args.spp} |
| runs | {args.runs} (seeds from {args.seed}) |
| total spp | {args.spp * args.runs} |
| date | {datetime.datetime.now(datetime.timezone.utc).strftime('%Y-%m-%d %H:%M UTC')} |
| render time | {render_seconds:.0f} s ({os.cpu_count()} cores) |

- `mean.exr`: per-pixel mean of the {args.runs} runs (float32 RGB).
- `variance.exr`: per-pixel variance of that mean: sample variance across the
  runs (denominator {args.runs - 1}) divided by {args.runs}.
- sqrt(mean variance) / mean radiance = {rel:.2e}.
""")
    _log(f"wrote {out}/mean.exr, variance.exr, README.md; render {render_seconds:.1f} s, total {total:.1f} s; "
         f"relative standard error {rel:.2e}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

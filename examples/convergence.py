#!/usr/bin/env python3
"""Render a scene progressively and plot its convergence: the image's
estimated RMSE (from the per-pixel variance of independent samples) against
render time, on log-log axes beside the 1/sqrt(t) line a Monte Carlo
estimate follows.

    .venv/bin/python examples/convergence.py [SCENE] [--batches 10] [--spp-per-batch 4]
                                             [--width 320 --height 240] [--out convergence.png]

Writes the plot (matplotlib) and the image after the last batch
(convergence.exr), and prints one row per batch. Ctrl-C stops early and
plots what was rendered.
"""
import argparse
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
try:
    import vkrt
except ImportError:  # a build tree: its package
    sys.path.insert(0, str(REPO / "build" / "python"))
    import vkrt


def convergence(scene, batches, spp_per_batch, width, height, device=""):
    """(spp, render seconds, estimated RMSE) after each batch, and the last result."""
    rows, last = [], None
    for frame in vkrt.progressive(scene, batches=batches, spp_per_batch=spp_per_batch, width=width, height=height,
                                  variance=True, device=device):
        rows.append((frame.spp, frame.render_seconds, frame.error_estimate["rmse"]))
        last = frame
        print(f"{frame.spp:6d} spp  {frame.render_seconds:8.3f} s  RMSE {frame.error_estimate['rmse']:.5f}",
              flush=True)
    return rows, last


def plot(rows, title, out):
    import matplotlib
    matplotlib.use("Agg")  # files only: no display needed
    import matplotlib.pyplot as plt

    spp, seconds, rmse = zip(*rows)
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.loglog(seconds, rmse, "o-", label="estimated RMSE")
    # The Monte Carlo rate through the first point: RMSE ~ 1 / sqrt(t).
    ax.loglog(seconds, [rmse[0] * (seconds[0] / t) ** 0.5 for t in seconds], "--", label="1 / sqrt(t)")
    for s, t, e in zip(spp, seconds, rmse):
        ax.annotate(f"{s}", (t, e), textcoords="offset points", xytext=(4, 4), fontsize=7)
    ax.set_xlabel("render seconds")
    ax.set_ylabel("RMSE (estimated)")
    ax.set_title(title)
    ax.legend()
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", nargs="?", default=str(REPO / "scenes" / "default.toml"))
    parser.add_argument("--batches", type=int, default=10)
    parser.add_argument("--spp-per-batch", type=int, default=4)
    parser.add_argument("--width", type=int, default=320)
    parser.add_argument("--height", type=int, default=240)
    parser.add_argument("--device", default="")
    parser.add_argument("--out", default="convergence.png")
    args = parser.parse_args()
    scene = vkrt.Scene.load(args.scene)
    rows, last = convergence(scene, args.batches, args.spp_per_batch, args.width, args.height, args.device)
    if not rows:
        sys.exit("convergence: nothing was rendered")
    plot(rows, f"{Path(args.scene).name}: {last.spp} spp", args.out)
    last.save(Path(args.out).with_suffix(".exr"))
    print(f"wrote {args.out} and {Path(args.out).with_suffix('.exr')}")


if __name__ == "__main__":
    main()

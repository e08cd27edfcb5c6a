#!/usr/bin/env python3
"""Write the small texture images of the textured validation scene.

    tools/make_validation_textures.py [--out scenes/validation/textures]

Every image is an 8-bit RGB PNG computed here from closed-form patterns (no
third-party images, no libraries beyond Python's zlib), so
scenes/validation/textured.toml needs nothing outside the repository.
Re-running it rewrites the same bytes (the image data is stored, not
deflated, so the bytes do not depend on the zlib version).

All patterns are smooth or coarse: the scene magnifies them (each texel
covers several pixels), because vkrt picks mip levels by ray cones and
Mitsuba does not mip-map, so the two agree where vkrt reads level 0.

* floor.png (4 x 4, sRGB): each texel its own colour; red grows to the right,
  green towards the top row, blue alternates as a checker. The scene tiles it
  with scale [2, 2] and wrap "mirror", so the image and its mirror images show
  which way up and round it is read.
* sphere.png (16 x 8, sRGB): a hue circle along u (periodic, so the seam at
  u = 0 / 1 is smooth under wrap "repeat"), brighter towards the top row (the
  north pole).
* roughness.png (8 x 2, linear, for `linear = true, channel = "g"`): the green
  channel ramps the roughness from 0.12 (left) to 0.6 (right); red and blue
  hold other values, so reading the wrong channel shows.
"""
from __future__ import annotations

import argparse
import math
import struct
import zlib
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
DEFAULT_OUT = REPO / "scenes" / "validation" / "textures"


def srgb_encode(linear: float) -> float:
    """The sRGB OETF (IEC 61966-2-1), the inverse of what vkrt decodes."""
    if linear <= 0.0031308:
        return 12.92 * linear
    return 1.055 * linear ** (1 / 2.4) - 0.055


def byte(value: float) -> int:
    return max(0, min(255, round(255 * value)))


def png_bytes(rows) -> bytes:
    """An 8-bit RGB PNG of `rows` (top row first; each a list of (r, g, b) bytes)."""
    height, width = len(rows), len(rows[0])

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    raw = b"".join(b"\x00" + bytes(c for texel in row for c in texel) for row in rows)  # filter 0 per row
    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)  # 8-bit RGB, no interlace
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw, 0)) + chunk(b"IEND", b"")


def srgb_rows(width: int, height: int, linear_colour):
    """Rows of sRGB bytes of linear_colour(x, y) (texel column x, row y from the top)."""
    return [[tuple(byte(srgb_encode(c)) for c in linear_colour(x, y)) for x in range(width)] for y in range(height)]


def floor_rows():
    def colour(x, y):
        return (0.1 + 0.6 * x / 3, 0.1 + 0.5 * (3 - y) / 3, 0.5 if (x + y) % 2 == 0 else 0.12)

    return srgb_rows(4, 4, colour)


def sphere_rows():
    def colour(x, y):
        phase = 2 * math.pi * (x + 0.5) / 16
        brightness = 1.0 - 0.5 * y / 7
        return tuple(brightness * (0.4 + 0.3 * math.cos(phase - k * 2 * math.pi / 3)) for k in range(3))

    return srgb_rows(16, 8, colour)


def roughness_values(width: int = 8):
    """The roughness of each column (the green channel, linear)."""
    return [0.12 + 0.48 * x / (width - 1) for x in range(width)]


def roughness_rows():
    row = [(byte(0.9 - 0.8 * r), byte(r), byte(0.3)) for r in roughness_values()]
    return [row, list(row)]


def all_files() -> dict[str, bytes]:
    return {"floor.png": png_bytes(floor_rows()), "sphere.png": png_bytes(sphere_rows()),
            "roughness.png": png_bytes(roughness_rows())}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=DEFAULT_OUT, help="output folder (default %(default)s)")
    args = ap.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    for name, data in all_files().items():
        (args.out / name).write_bytes(data)
        print(f"wrote {args.out / name} ({len(data)} bytes)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

#!/usr/bin/env python3
"""Write the small mesh files of the mesh validation scenes.

    tools/make_validation_meshes.py [--out scenes/validation/models]

Every file is plain-text OBJ, made here from exact coordinates, so the scenes
(scenes/validation/mesh-*.toml) need nothing outside the repository except the
Stanford bunny of the shared assets. Re-running it rewrites the same bytes.

* cornell-white.obj, cornell-red.obj, cornell-green.obj: the walls of a Cornell
  box (x, z in [-1, 1], y in [0, 2], open towards +z), one file per material.
  Each wall is a quad in its own group, wound counter-clockwise seen from
  inside the room; the white walls carry vertex normals (`vn`, pointing into
  the room) so that normals = "file" reads real file normals; red and green
  have none (vkrt falls back to face normals).
* cube.obj: the unit cube [-0.5, 0.5] x [0, 1] x [-0.5, 0.5] (base at y = 0),
  six outward-facing quads without normals; the blocks are transformed copies.
* light.obj: the unit square [-0.5, 0.5]^2 in the plane y = 0, wound so that its
  counter-clockwise (emitting) side faces -y.
* uv-sphere.obj: a unit UV sphere of 12 slices and 10 stacks (216 triangles:
  triangle fans at the poles, quads between), without normals or texture
  coordinates, every vertex stored once (the seam and the poles are shared),
  so that smooth normals computed from the triangles are continuous.
"""
from __future__ import annotations

import argparse
import math
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
DEFAULT_OUT = REPO / "scenes" / "validation" / "models"
HEADER = "# Written by tools/make_validation_meshes.py; do not edit.\n"


def _num(x: float) -> str:
    """Short, exact-enough text for a coordinate (no '-0')."""
    text = f"{x:.9g}"
    return "0" if text in ("-0", "0") else text


def _vertex(p) -> str:
    return "v " + " ".join(_num(c) for c in p) + "\n"


def obj_text(groups, normals=None) -> str:
    """An OBJ of named polygon groups; `groups` is [(name, [polygon of points])].
    With `normals` ({name: normal}), each group's corners reference that normal."""
    lines = [HEADER]
    index = 1
    for g, (name, polygons) in enumerate(groups):
        lines.append(f"g {name}\n")
        for polygon in polygons:
            lines += [_vertex(p) for p in polygon]
        if normals:
            lines.append("vn " + " ".join(_num(c) for c in normals[name]) + "\n")
        for polygon in polygons:
            corners = range(index, index + len(polygon))
            if normals:
                lines.append("f " + " ".join(f"{c}//{g + 1}" for c in corners) + "\n")
            else:
                lines.append("f " + " ".join(str(c) for c in corners) + "\n")
            index += len(polygon)
    return "".join(lines)


def cornell_walls():
    """{material: [(group, [quad], inward normal)]}: each quad counter-clockwise seen from inside."""
    floor = [(-1, 0, -1), (-1, 0, 1), (1, 0, 1), (1, 0, -1)]
    ceiling = [(-1, 2, -1), (1, 2, -1), (1, 2, 1), (-1, 2, 1)]
    back = [(-1, 0, -1), (1, 0, -1), (1, 2, -1), (-1, 2, -1)]
    left = [(-1, 0, -1), (-1, 2, -1), (-1, 2, 1), (-1, 0, 1)]
    right = [(1, 0, -1), (1, 0, 1), (1, 2, 1), (1, 2, -1)]
    return {
        "white": [("floor", floor, (0, 1, 0)), ("ceiling", ceiling, (0, -1, 0)), ("back", back, (0, 0, 1))],
        "red": [("left", left, (1, 0, 0))],
        "green": [("right", right, (-1, 0, 0))],
    }


def cube():
    lo, hi = (-0.5, 0.0, -0.5), (0.5, 1.0, 0.5)

    def corner(i):
        return tuple(hi[k] if (i >> k) & 1 else lo[k] for k in range(3))

    # Corners by bit pattern (x, y, z); each face counter-clockwise seen from outside.
    faces = [(0, 4, 6, 2), (1, 3, 7, 5), (0, 1, 5, 4), (2, 6, 7, 3), (0, 2, 3, 1), (4, 5, 7, 6)]
    return [[corner(i) for i in face] for face in faces]


def light_quad():
    # cross(v1 - v0, v2 - v0) = (1, 0, 0) x (1, 0, 1) = (0, -1, 0).
    return [(-0.5, 0, -0.5), (0.5, 0, -0.5), (0.5, 0, 0.5), (-0.5, 0, 0.5)]


def uv_sphere_text(slices: int = 12, stacks: int = 10) -> str:
    """Shared vertices: north pole, (stacks - 1) rings of `slices`, south pole."""
    lines = [HEADER, "g sphere\n", _vertex((0, 1, 0))]
    for j in range(1, stacks):
        theta = math.pi * j / stacks
        for i in range(slices):
            phi = 2 * math.pi * i / slices
            lines.append(_vertex((math.sin(theta) * math.cos(phi), math.cos(theta), -math.sin(theta) * math.sin(phi))))
    lines.append(_vertex((0, -1, 0)))
    south = 2 + (stacks - 1) * slices

    def ring(j, i):  # 1-based OBJ index of ring j (1..stacks-1), slice i (mod slices)
        return 2 + (j - 1) * slices + i % slices

    # Counter-clockwise seen from outside: phi grows clockwise seen from +y
    # (z = -sin phi), so from the north pole go to slice i, then i + 1.
    for i in range(slices):
        lines.append(f"f 1 {ring(1, i)} {ring(1, i + 1)}\n")
    for j in range(1, stacks - 1):
        for i in range(slices):
            lines.append(f"f {ring(j, i)} {ring(j + 1, i)} {ring(j + 1, i + 1)} {ring(j, i + 1)}\n")
    for i in range(slices):
        lines.append(f"f {ring(stacks - 1, i)} {south} {ring(stacks - 1, i + 1)}\n")
    return "".join(lines)


def all_files() -> dict[str, str]:
    files = {}
    for material, walls in cornell_walls().items():
        groups = [(name, [quad]) for name, quad, _ in walls]
        normals = {name: n for name, _, n in walls} if material == "white" else None
        files[f"cornell-{material}.obj"] = obj_text(groups, normals)
    files["cube.obj"] = obj_text([("cube", cube())])
    files["light.obj"] = obj_text([("light", [light_quad()])])
    files["uv-sphere.obj"] = uv_sphere_text()
    return files


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=DEFAULT_OUT, help="output folder (default %(default)s)")
    args = ap.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    for name, text in all_files().items():
        (args.out / name).write_text(text, encoding="ascii")
        print(f"wrote {args.out / name} ({len(text)} bytes)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

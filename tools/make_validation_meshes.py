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
* textured-floor.obj: the square [-1, 1]^2 in y = 0 facing +y, with texture
  coordinates: u runs along +x, v along -z (away from a camera at +z), so
  uv (0, 0) is the front-left corner and the image stands upright seen from
  the front; one normal (0, 1, 0).
* textured-panel.obj: the unit square [-0.5, 0.5] x [0, 1] in z = 0 facing +z,
  u along +x, v along +y (the image upright seen from +z); normal (0, 0, 1).
* uv-sphere-textured.obj: a unit UV sphere of 24 slices and 12 stacks with
  texture coordinates u = phi / 2 pi (increasing to the right seen from
  outside), v = 1 - theta / pi (1 at the north pole) and exact unit normals
  (`vn`); the positions are shared, the seam (u = 0 and u = 1) and the pole
  triangles (u at the middle of their slice) have their own texture
  coordinates.
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


def textured_quad_text(corners, uvs, normal, group: str) -> str:
    """One quad with a texture coordinate per corner and one normal."""
    lines = [HEADER, f"g {group}\n"] + [_vertex(p) for p in corners]
    lines += ["vt " + " ".join(_num(c) for c in uv) + "\n" for uv in uvs]
    lines.append("vn " + " ".join(_num(c) for c in normal) + "\n")
    lines.append("f " + " ".join(f"{k}/{k}/1" for k in range(1, 5)) + "\n")
    return "".join(lines)


def textured_floor_text() -> str:
    # The corners of the Cornell floor, counter-clockwise seen from above.
    corners = [(-1, 0, -1), (-1, 0, 1), (1, 0, 1), (1, 0, -1)]
    uvs = [((x + 1) / 2, (1 - z) / 2) for x, _, z in corners]
    return textured_quad_text(corners, uvs, (0, 1, 0), "floor")


def textured_panel_text() -> str:
    corners = [(-0.5, 0, 0), (0.5, 0, 0), (0.5, 1, 0), (-0.5, 1, 0)]  # counter-clockwise seen from +z
    return textured_quad_text(corners, [(x + 0.5, y) for x, y, _ in corners], (0, 0, 1), "panel")


def textured_uv_sphere_text(slices: int = 24, stacks: int = 12) -> str:
    """Positions and normals: north pole, (stacks - 1) rings of `slices`, south
    pole (as uv_sphere_text). Texture coordinates: (stacks - 1) rings of
    slices + 1 (the last repeats the first at u = 1), then `slices` for each pole."""
    positions = [(0.0, 1.0, 0.0)]
    for j in range(1, stacks):
        theta = math.pi * j / stacks
        for i in range(slices):
            phi = 2 * math.pi * i / slices
            positions.append((math.sin(theta) * math.cos(phi), math.cos(theta), -math.sin(theta) * math.sin(phi)))
    positions.append((0.0, -1.0, 0.0))
    lines = [HEADER, "g sphere\n"] + [_vertex(p) for p in positions]
    lines += ["vn " + " ".join(_num(c) for c in p) + "\n" for p in positions]
    for j in range(1, stacks):
        lines += [f"vt {_num(i / slices)} {_num(1 - j / stacks)}\n" for i in range(slices + 1)]
    for v in (1, 0):
        lines += [f"vt {_num((i + 0.5) / slices)} {v}\n" for i in range(slices)]
    south = 2 + (stacks - 1) * slices
    ring_uvs = (stacks - 1) * (slices + 1)

    def ring(j, i):  # position (and normal) index of ring j, slice i (mod slices)
        return 2 + (j - 1) * slices + i % slices

    def ring_uv(j, i):  # texture coordinate of ring j, slice i in 0..slices
        return 1 + (j - 1) * (slices + 1) + i

    def corner(v, t):
        return f"{v}/{t}/{v}"

    for i in range(slices):
        lines.append(f"f {corner(1, ring_uvs + 1 + i)} {corner(ring(1, i), ring_uv(1, i))} "
                     f"{corner(ring(1, i + 1), ring_uv(1, i + 1))}\n")
    for j in range(1, stacks - 1):
        for i in range(slices):
            lines.append(f"f {corner(ring(j, i), ring_uv(j, i))} {corner(ring(j + 1, i), ring_uv(j + 1, i))} "
                         f"{corner(ring(j + 1, i + 1), ring_uv(j + 1, i + 1))} "
                         f"{corner(ring(j, i + 1), ring_uv(j, i + 1))}\n")
    for i in range(slices):
        lines.append(f"f {corner(ring(stacks - 1, i), ring_uv(stacks - 1, i))} "
                     f"{corner(south, ring_uvs + slices + 1 + i)} "
                     f"{corner(ring(stacks - 1, i + 1), ring_uv(stacks - 1, i + 1))}\n")
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
    files["textured-floor.obj"] = textured_floor_text()
    files["textured-panel.obj"] = textured_panel_text()
    files["uv-sphere-textured.obj"] = textured_uv_sphere_text()
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

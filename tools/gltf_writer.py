#!/usr/bin/env python3
"""A small glTF 2.0 writer (library and command line), Python 3.11 standard library only.

vkrt's glTF test and demo scenes are written by this tool, never downloaded.
It runs on a fresh Debian 12 or 13 with nothing but python3.

Command line:

    tools/gltf_writer.py scenes OUTDIR          # the scenes shipped in scenes/gltf/
    tools/gltf_writer.py scenes OUTDIR --glb    # ... and a .glb of each .gltf

`scenes` writes lights-camera.gltf (with lights-camera.toml and the OBJ files
of its meshes in lights-camera-parts/, the same scene written for vkrt's TOML
format), transmission.gltf, texture-transform.gltf and
texture-transform-baked.gltf (the same scene with its KHR_texture_transform
baked into the uvs, bake_texture_transforms()). Running it twice gives
identical bytes: JSON keys keep the order the code gives them, numbers are
written by repr(), and PNG data is stored in uncompressed deflate blocks
(zlib's compressed output may differ between zlib builds; stored blocks do not).

Library (see each function's docstring):

    import gltf_writer as gw
    g = gw.Gltf(description="what the file exercises")   # asset.extras.description
    red = g.add_material("red", base_color=(0.75, 0.25, 0.125, 1.0), metallic=0.0, roughness=0.5)
    cube = g.add_mesh("cube", [(gw.cube(1.0), red)])
    child = g.add_node("cube", mesh=cube, translation=(0, 0.5, 0))
    parent = g.add_node("rig", children=[child], rotation=gw.quat_axis_angle((0, 1, 0), 0.5))
    cam = g.add_node("camera", camera=g.add_camera(yfov=0.6, aspect_ratio=4 / 3),
                     translation=(0, 1, 5), rotation=gw.quat_look_at((0, 1, 5), (0, 0.5, 0)))
    g.add_node("sun", light=g.add_directional_light(intensity=2.0),
               rotation=gw.quat_look_at((0, 0, 0), (-1, -2, -1)))
    g.add_scene([parent, cam, 2])                      # node indices; becomes the default scene
    g.write("model.gltf")                              # or "model.glb"
    gw.bake_texture_transforms(g).write("baked.gltf")  # KHR_texture_transform baked into the uvs

What it writes:

- One buffer. In a .gltf it is a base64 `data:application/octet-stream` URI,
  in a .glb the BIN chunk. Each accessor has its own bufferView (4-byte
  aligned, tightly packed, so no byteStride), with target ARRAY_BUFFER (34962)
  for vertex attributes and ELEMENT_ARRAY_BUFFER (34963) for indices. Images
  are PNG bytes in a bufferView (no target) with mimeType image/png.
- Meshes: POSITION (float VEC3, with min/max from the float32 values stored),
  optional NORMAL (float VEC3) and TEXCOORD_0 (float VEC2), indices as
  UNSIGNED_SHORT (5123) below 65,536 vertices, else UNSIGNED_INT (5125);
  triangles (mode 4, glTF's default, so not written). Two meshes built from
  the same MeshData object share its accessors. The helpers (cube, quad,
  uv_sphere) always give normals and uvs, even where no texture needs them:
  vkrt's import keeps a file's uvs only when every primitive has them.
- Materials: pbrMetallicRoughness (baseColorFactor, metallicFactor,
  roughnessFactor, baseColorTexture with optional KHR_texture_transform),
  emissiveFactor with optional KHR_materials_emissive_strength,
  KHR_materials_transmission and KHR_materials_ior.
- Nodes: children, translation/rotation (quaternion x, y, z, w)/scale or a
  4x4 `matrix` (column-major, as glTF stores it), mesh, camera, light.
- Perspective cameras (yfov in radians, aspectRatio, znear, zfar).
- KHR_lights_punctual lights: point, spot (innerConeAngle < outerConeAngle,
  radians, half-angles from the axis) and directional; color and intensity
  (candela for point and spot, lux for directional). A light shines down its
  node's -Z, as a camera looks down its node's -Z with +Y up.
- extensionsUsed: every extension name found under any "extensions" member
  of the document, sorted, computed when the file is written (so none is
  ever missing); extensionsRequired is not written (each extension used has
  a fallback a viewer may fall back to).

Conventions: matrices in Python are row-major lists of 4 rows (m[row][col],
column 3 the translation); glTF's `matrix` is the column-major flattening,
`to_column_major(m)`. glTF uv has v running down the image (0 at the top
row); the mesh helpers give uvs on which images appear upright.
"""
from __future__ import annotations

import argparse
import base64
import copy
import json
import math
import struct
import sys
import zlib
from dataclasses import dataclass
from pathlib import Path
from typing import Iterable, Sequence

# glTF enumerations
FLOAT = 5126
UNSIGNED_SHORT = 5123
UNSIGNED_INT = 5125
ARRAY_BUFFER = 34962
ELEMENT_ARRAY_BUFFER = 34963
NEAREST, LINEAR, LINEAR_MIPMAP_LINEAR = 9728, 9729, 9987
REPEAT, CLAMP_TO_EDGE, MIRRORED_REPEAT = 10497, 33071, 33648

GENERATOR = "vkrt tools/gltf_writer.py"

# ---------------------------------------------------------------------------
# Numbers


def f32(x: float) -> float:
    """x rounded to the nearest float32 (as a Python float, exactly that value)."""
    return struct.unpack("<f", struct.pack("<f", x))[0]


def f32_text(x: float) -> str:
    """The shortest decimal (no exponent) that reads back as float32(x): OBJ text
    that any parser turns into the very float32 a glTF buffer holds."""
    v = f32(x) + 0.0  # -0.0 -> 0.0
    for digits in range(1, 10):
        text = f"{v:.{digits}g}"
        if f32(float(text)) == v and "e" not in text:
            return text
    text = repr(v)
    if "e" in text:
        raise ValueError(f"{x!r} needs an exponent; snap tiny coordinates to 0 first")
    return text


def clean(x: float, eps: float = 1e-12) -> float:
    """x with |x| < eps made 0.0 (and -0.0 made 0.0): sin(pi) is 0 in a mesh."""
    return 0.0 if abs(x) < eps else x + 0.0


# ---------------------------------------------------------------------------
# Vectors, quaternions and matrices (row-major 4x4: m[row][col])

Vec3 = Sequence[float]
Matrix = list  # 4 rows of 4 floats


def sub(a: Vec3, b: Vec3) -> list[float]:
    return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]


def dot(a: Vec3, b: Vec3) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a: Vec3, b: Vec3) -> list[float]:
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def normalize(a: Vec3) -> list[float]:
    length = math.sqrt(dot(a, a))
    if length == 0.0:
        raise ValueError("cannot normalize a zero vector")
    return [a[0] / length, a[1] / length, a[2] / length]


def identity() -> Matrix:
    return [[1.0 if r == c else 0.0 for c in range(4)] for r in range(4)]


def mat_mul(a: Matrix, b: Matrix) -> Matrix:
    return [[sum(a[r][k] * b[k][c] for k in range(4)) for c in range(4)] for r in range(4)]


def transform_point(m: Matrix, p: Vec3) -> list[float]:
    return [m[r][0] * p[0] + m[r][1] * p[1] + m[r][2] * p[2] + m[r][3] for r in range(3)]


def transform_vector(m: Matrix, v: Vec3) -> list[float]:
    return [m[r][0] * v[0] + m[r][1] * v[1] + m[r][2] * v[2] for r in range(3)]


def mat_inverse(m: Matrix) -> Matrix:
    """The inverse of a 4x4 matrix (Gauss-Jordan with partial pivoting)."""
    a = [list(map(float, row)) + [1.0 if r == c else 0.0 for c in range(4)] for r, row in enumerate(m)]
    for col in range(4):
        pivot = max(range(col, 4), key=lambda r: abs(a[r][col]))
        if a[pivot][col] == 0.0:
            raise ValueError("singular matrix")
        a[col], a[pivot] = a[pivot], a[col]
        p = a[col][col]
        a[col] = [x / p for x in a[col]]
        for r in range(4):
            if r != col and a[r][col] != 0.0:
                f = a[r][col]
                a[r] = [x - f * y for x, y in zip(a[r], a[col])]
    return [row[4:] for row in a]


def quat_axis_angle(axis: Vec3, angle: float) -> list[float]:
    """The unit quaternion [x, y, z, w] of a right-handed rotation by `angle` radians about `axis`."""
    n = normalize(axis)
    s = math.sin(angle / 2.0)
    return [n[0] * s, n[1] * s, n[2] * s, math.cos(angle / 2.0)]


def quat_mul(a: Sequence[float], b: Sequence[float]) -> list[float]:
    """a * b (apply b, then a), quaternions as [x, y, z, w]."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return [
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    ]


def quat_to_mat3(q: Sequence[float]) -> list[list[float]]:
    """The rotation matrix (rows) of a unit quaternion [x, y, z, w], glTF's formula."""
    x, y, z, w = q
    return [
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ]


def quat_from_mat3(m: Sequence[Sequence[float]]) -> list[float]:
    """The unit quaternion [x, y, z, w] (w >= 0) of a rotation matrix (rows)."""
    trace = m[0][0] + m[1][1] + m[2][2]
    if trace > 0.0:
        s = 2.0 * math.sqrt(trace + 1.0)
        q = [(m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s, 0.25 * s]
    elif m[0][0] > m[1][1] and m[0][0] > m[2][2]:
        s = 2.0 * math.sqrt(1.0 + m[0][0] - m[1][1] - m[2][2])
        q = [0.25 * s, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s, (m[2][1] - m[1][2]) / s]
    elif m[1][1] > m[2][2]:
        s = 2.0 * math.sqrt(1.0 + m[1][1] - m[0][0] - m[2][2])
        q = [(m[0][1] + m[1][0]) / s, 0.25 * s, (m[1][2] + m[2][1]) / s, (m[0][2] - m[2][0]) / s]
    else:
        s = 2.0 * math.sqrt(1.0 + m[2][2] - m[0][0] - m[1][1])
        q = [(m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, 0.25 * s, (m[1][0] - m[0][1]) / s]
    if q[3] < 0.0:
        q = [-c for c in q]
    length = math.sqrt(sum(c * c for c in q))
    return [c / length for c in q]


def quat_look_at(eye: Vec3, target: Vec3, up: Vec3 = (0.0, 1.0, 0.0)) -> list[float]:
    """The rotation of a node at `eye` whose -Z points at `target` and whose +Y
    is as close to `up` as it can be: how glTF cameras and lights are aimed."""
    z = normalize(sub(eye, target))  # the node looks down -Z
    x = normalize(cross(up, z))
    y = cross(z, x)
    return quat_from_mat3([[x[0], y[0], z[0]], [x[1], y[1], z[1]], [x[2], y[2], z[2]]])


def trs_matrix(translation: Vec3 | None = None, rotation: Sequence[float] | None = None,
               scale: Vec3 | None = None) -> Matrix:
    """T * R * S, glTF's local transform of a node (row-major)."""
    t = translation or (0.0, 0.0, 0.0)
    r = quat_to_mat3(rotation or (0.0, 0.0, 0.0, 1.0))
    s = scale or (1.0, 1.0, 1.0)
    m = [[r[row][col] * s[col] for col in range(3)] + [float(t[row])] for row in range(3)]
    return m + [[0.0, 0.0, 0.0, 1.0]]


def to_column_major(m: Matrix) -> list[float]:
    """glTF's `matrix` (16 numbers, column by column) of a row-major 4x4."""
    return [float(m[r][c]) + 0.0 for c in range(4) for r in range(4)]


def from_column_major(values: Sequence[float]) -> Matrix:
    """A row-major 4x4 from glTF's column-major 16 numbers."""
    return [[float(values[c * 4 + r]) for c in range(4)] for r in range(4)]


# ---------------------------------------------------------------------------
# PNG


def zlib_stored(data: bytes) -> bytes:
    """A zlib stream of `data` in stored (uncompressed) deflate blocks: the
    same bytes from every zlib build."""
    out = bytearray(b"\x78\x01")
    view = memoryview(data)
    offset = 0
    while True:
        chunk = view[offset:offset + 65535]
        offset += len(chunk)
        final = offset >= len(data)
        out += struct.pack("<BHH", 1 if final else 0, len(chunk), len(chunk) ^ 0xFFFF)
        out += chunk
        if final:
            break
    out += struct.pack(">I", zlib.adler32(data) & 0xFFFFFFFF)
    return bytes(out)


def png_bytes(width: int, height: int, pixels: Sequence[Sequence[int]], *, level: int | None = None) -> bytes:
    """An 8-bit RGB or RGBA PNG (sRGB-encoded values, as glTF base colours are).

    pixels: width*height tuples of 3 or 4 ints in 0..255, row by row from the
    top row of the image. level None stores the data uncompressed (portable,
    deterministic bytes); 0-9 passes it through zlib.compress at that level.
    """
    if width <= 0 or height <= 0 or len(pixels) != width * height:
        raise ValueError(f"expected {width}x{height} pixels, got {len(pixels)}")
    channels = len(pixels[0])
    if channels not in (3, 4) or any(len(p) != channels for p in pixels):
        raise ValueError("every pixel needs the same 3 (RGB) or 4 (RGBA) channels")
    raw = bytearray()
    for row in range(height):
        raw.append(0)  # filter: None
        for p in pixels[row * width:(row + 1) * width]:
            raw += bytes(p)

    def chunk(kind: bytes, body: bytes) -> bytes:
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF)

    colour_type = 2 if channels == 3 else 6
    header = struct.pack(">IIBBBBB", width, height, 8, colour_type, 0, 0, 0)
    data = zlib_stored(bytes(raw)) if level is None else zlib.compress(bytes(raw), level)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", data) + chunk(b"IEND", b"")


def checker_pixels(size: int, cells: int, a: Sequence[int], b: Sequence[int],
                   marks: dict[tuple[int, int], Sequence[int]] | None = None) -> list[tuple[int, ...]]:
    """size x size pixels of a `cells` x `cells` checker of colours a (top-left
    cell) and b; `marks` recolours cells {(column, row): colour}, rows from the top."""
    if size % cells:
        raise ValueError("size must be a multiple of cells")
    step = size // cells
    out = []
    for y in range(size):
        for x in range(size):
            cell = (x // step, y // step)
            colour = (marks or {}).get(cell, a if (cell[0] + cell[1]) % 2 == 0 else b)
            out.append(tuple(colour))
    return out


# ---------------------------------------------------------------------------
# Mesh data and helpers


@dataclass
class MeshData:
    """Triangles: positions (x, y, z), optional unit normals and uvs (glTF's:
    v = 0 at the image's top row), and indices, three per counter-clockwise
    (front-facing) triangle."""

    positions: list
    indices: list
    normals: list | None = None
    texcoords: list | None = None

    def __post_init__(self):
        n = len(self.positions)
        if len(self.indices) % 3 or not self.indices:
            raise ValueError("indices must be a non-empty multiple of 3")
        if any(i < 0 or i >= n for i in self.indices):
            raise ValueError("an index is out of range")
        for name in ("normals", "texcoords"):
            values = getattr(self, name)
            if values is not None and len(values) != n:
                raise ValueError(f"{name} has {len(values)} entries for {n} positions")

    def bounds(self) -> tuple[list[float], list[float]]:
        """min and max of the positions as float32 stores them."""
        stored = [[f32(c) for c in p] for p in self.positions]
        return ([min(p[i] for p in stored) for i in range(3)], [max(p[i] for p in stored) for i in range(3)])


def cube(size: float = 1.0) -> MeshData:
    """An axis-aligned cube of edge `size` centred on the origin: 24 vertices
    (each face its own normal), each face's uvs spanning [0, 1], upright seen
    from outside with +Y up on the side faces."""
    h = size / 2.0
    # face normal, u direction, v-up direction (uv v runs down the image: v = 0 at the top)
    faces = [
        ((1, 0, 0), (0, 0, -1), (0, 1, 0)),
        ((-1, 0, 0), (0, 0, 1), (0, 1, 0)),
        ((0, 1, 0), (1, 0, 0), (0, 0, -1)),
        ((0, -1, 0), (1, 0, 0), (0, 0, 1)),
        ((0, 0, 1), (1, 0, 0), (0, 1, 0)),
        ((0, 0, -1), (-1, 0, 0), (0, 1, 0)),
    ]
    positions, normals, texcoords, indices = [], [], [], []
    for n, u, v in faces:
        base = len(positions)
        for su, sv in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
            positions.append([clean(h * (n[i] + su * u[i] + sv * v[i])) for i in range(3)])
            normals.append([float(c) for c in n])
            texcoords.append([(su + 1) / 2.0, (1 - sv) / 2.0])
        indices += [base, base + 1, base + 2, base, base + 2, base + 3]
    return MeshData(positions, indices, normals, texcoords)


def quad(width: float = 1.0, height: float = 1.0, uv_repeat: Sequence[float] = (1.0, 1.0)) -> MeshData:
    """A width x height rectangle in the XY plane centred on the origin, facing
    +Z; uv (0, 0) at its top-left corner and (uv_repeat) at its bottom-right,
    so an image appears upright seen from +Z."""
    w, h = width / 2.0, height / 2.0
    ru, rv = uv_repeat
    positions = [[-w, -h, 0.0], [w, -h, 0.0], [w, h, 0.0], [-w, h, 0.0]]
    texcoords = [[0.0, rv], [ru, rv], [ru, 0.0], [0.0, 0.0]]
    normals = [[0.0, 0.0, 1.0]] * 4
    return MeshData(positions, [0, 1, 2, 0, 2, 3], [list(n) for n in normals], texcoords)


def uv_sphere_indices(segments: int, rings: int) -> list[int]:
    """Counter-clockwise triangles of a UV sphere whose vertices run ring by
    ring, segments + 1 to a ring (a seam column); no slivers at the poles."""
    indices = []
    row = segments + 1
    for ring in range(rings):
        for seg in range(segments):
            a, b = ring * row + seg, ring * row + seg + 1
            c, d = a + row, b + row
            if ring != 0:
                indices += [a, c, b]
            if ring != rings - 1:
                indices += [b, c, d]
    return indices


def uv_sphere(radius: float = 1.0, segments: int = 32, rings: int = 16) -> MeshData:
    """A UV sphere about the origin: `segments` around Y, `rings` from pole to
    pole, (segments + 1) x (rings + 1) vertices (a seam column and one vertex
    per pole per segment, so uvs never wrap); u = longitude / 2 pi from +Z
    towards +X, v = 0 at the north (+Y) pole."""
    if segments < 3 or rings < 2:
        raise ValueError("a sphere needs at least 3 segments and 2 rings")
    positions, normals, texcoords, indices = [], [], [], []
    for ring in range(rings + 1):
        theta = math.pi * ring / rings  # from +Y
        for seg in range(segments + 1):
            phi = 2.0 * math.pi * seg / segments
            n = [clean(math.sin(theta) * math.sin(phi)), clean(math.cos(theta)),
                 clean(math.sin(theta) * math.cos(phi))]
            if ring in (0, rings):
                n = [0.0, 1.0 if ring == 0 else -1.0, 0.0]
            normals.append(n)
            positions.append([clean(radius * c) for c in n])
            texcoords.append([seg / segments, ring / rings])
    indices += uv_sphere_indices(segments, rings)
    return MeshData(positions, indices, normals, texcoords)


# ---------------------------------------------------------------------------
# The document


@dataclass
class TextureRef:
    """A material's use of a texture: `texture` index, TEXCOORD set, and an
    optional KHR_texture_transform (offset [u, v], rotation radians, scale [su, sv])."""

    texture: int
    texcoord: int = 0
    offset: Sequence[float] | None = None
    rotation: float | None = None
    scale: Sequence[float] | None = None

    def to_json(self) -> dict:
        info: dict = {"index": self.texture}
        if self.texcoord:
            info["texCoord"] = self.texcoord
        transform: dict = {}
        if self.offset is not None:
            transform["offset"] = [float(c) for c in self.offset]
        if self.rotation is not None:
            transform["rotation"] = float(self.rotation)
        if self.scale is not None:
            transform["scale"] = [float(c) for c in self.scale]
        if transform:
            info["extensions"] = {"KHR_texture_transform": transform}
        return info


class Gltf:
    """A glTF 2.0 document being built. Every add_* returns the index of what it added."""

    def __init__(self, description: str | None = None, extras: dict | None = None):
        self.asset: dict = {"version": "2.0", "generator": GENERATOR}
        extras = dict(extras or {})
        if description is not None:
            extras = {"description": description, **extras}
        if extras:
            self.asset["extras"] = extras
        self.scene: int | None = None
        self.scenes: list[dict] = []
        self.nodes: list[dict] = []
        self.meshes: list[dict] = []
        self.materials: list[dict] = []
        self.textures: list[dict] = []
        self.images: list[dict] = []
        self.samplers: list[dict] = []
        self.cameras: list[dict] = []
        self.lights: list[dict] = []
        self.accessors: list[dict] = []
        self.buffer_views: list[dict] = []
        self.binary = bytearray()
        self.mesh_data: list[list[tuple[MeshData, int | None]]] = []  # per mesh, per primitive
        self._geometry: dict[int, dict] = {}  # id(MeshData) -> attributes and indices
        self._keep: list[MeshData] = []  # keeps id()s above unique

    # -- buffer ------------------------------------------------------------

    def _add_view(self, data: bytes, target: int | None) -> int:
        while len(self.binary) % 4:
            self.binary.append(0)
        view: dict = {"buffer": 0, "byteOffset": len(self.binary), "byteLength": len(data)}
        if target is not None:
            view["target"] = target
        self.binary += data
        self.buffer_views.append(view)
        return len(self.buffer_views) - 1

    def _add_accessor(self, rows: Sequence[Sequence[float]] | Sequence[int], kind: str, component: int,
                      target: int, bounds: tuple | None = None) -> int:
        width = {"SCALAR": 1, "VEC2": 2, "VEC3": 3}[kind]
        fmt = {FLOAT: "f", UNSIGNED_SHORT: "H", UNSIGNED_INT: "I"}[component]
        flat = list(rows) if width == 1 else [c for row in rows for c in row]
        if len(flat) != width * len(rows):
            raise ValueError(f"every {kind} element needs {width} components")
        data = struct.pack(f"<{len(flat)}{fmt}", *flat)
        accessor: dict = {"bufferView": self._add_view(data, target), "componentType": component,
                          "count": len(rows), "type": kind}
        if bounds is not None:
            accessor["min"], accessor["max"] = [c + 0.0 for c in bounds[0]], [c + 0.0 for c in bounds[1]]
        self.accessors.append(accessor)
        return len(self.accessors) - 1

    def _geometry_of(self, mesh: MeshData) -> dict:
        if id(mesh) in self._geometry:
            return self._geometry[id(mesh)]
        attributes = {"POSITION": self._add_accessor(mesh.positions, "VEC3", FLOAT, ARRAY_BUFFER, mesh.bounds())}
        if mesh.normals is not None:
            attributes["NORMAL"] = self._add_accessor(mesh.normals, "VEC3", FLOAT, ARRAY_BUFFER)
        if mesh.texcoords is not None:
            attributes["TEXCOORD_0"] = self._add_accessor(mesh.texcoords, "VEC2", FLOAT, ARRAY_BUFFER)
        component = UNSIGNED_SHORT if len(mesh.positions) < 65536 else UNSIGNED_INT
        indices = self._add_accessor(mesh.indices, "SCALAR", component, ELEMENT_ARRAY_BUFFER)
        self._geometry[id(mesh)] = {"attributes": attributes, "indices": indices}
        self._keep.append(mesh)
        return self._geometry[id(mesh)]

    # -- content -----------------------------------------------------------

    def add_mesh(self, name: str, primitives: Iterable[tuple[MeshData, int | None]]) -> int:
        """A mesh of triangle primitives, each (MeshData, material index or None)."""
        entries = []
        parts = list(primitives)
        for data, material in parts:
            geometry = self._geometry_of(data)
            primitive: dict = {"attributes": dict(geometry["attributes"]), "indices": geometry["indices"]}
            if material is not None:
                if not 0 <= material < len(self.materials):
                    raise ValueError(f"no material {material}")
                primitive["material"] = material
            entries.append(primitive)
        if not entries:
            raise ValueError("a mesh needs at least one primitive")
        self.meshes.append({"name": name, "primitives": entries})
        self.mesh_data.append(parts)
        return len(self.meshes) - 1

    def add_material(self, name: str, *, base_color: Sequence[float] = (1.0, 1.0, 1.0, 1.0),
                     metallic: float = 1.0, roughness: float = 1.0,
                     base_color_texture: TextureRef | None = None,
                     emissive: Sequence[float] | None = None, emissive_strength: float | None = None,
                     transmission: float | None = None, ior: float | None = None,
                     double_sided: bool = False) -> int:
        """A metallic-roughness material (glTF's defaults: white, metallic 1,
        roughness 1). emissive: emissiveFactor in [0, 1]; emissive_strength its
        KHR_materials_emissive_strength multiplier; transmission:
        KHR_materials_transmission's transmissionFactor; ior: KHR_materials_ior."""
        colour = [float(c) for c in base_color]
        if len(colour) == 3:
            colour.append(1.0)
        for value in colour + [metallic, roughness] + list(emissive or []) + [transmission or 0.0]:
            if not 0.0 <= value <= 1.0:
                raise ValueError(f"material {name}: factor {value} is outside [0, 1]")
        pbr: dict = {"baseColorFactor": colour}
        if base_color_texture is not None:
            if not 0 <= base_color_texture.texture < len(self.textures):
                raise ValueError(f"no texture {base_color_texture.texture}")
            pbr["baseColorTexture"] = base_color_texture.to_json()
        pbr["metallicFactor"] = float(metallic)
        pbr["roughnessFactor"] = float(roughness)
        material: dict = {"name": name, "pbrMetallicRoughness": pbr}
        if emissive is not None:
            material["emissiveFactor"] = [float(c) for c in emissive]
        if double_sided:
            material["doubleSided"] = True
        extensions: dict = {}
        if emissive_strength is not None:
            if emissive is None or emissive_strength < 0.0:
                raise ValueError("emissive_strength needs an emissive factor and must be >= 0")
            extensions["KHR_materials_emissive_strength"] = {"emissiveStrength": float(emissive_strength)}
        if transmission is not None:
            extensions["KHR_materials_transmission"] = {"transmissionFactor": float(transmission)}
        if ior is not None:
            if not (ior == 0.0 or ior >= 1.0):
                raise ValueError("KHR_materials_ior's ior is 0 or at least 1")
            extensions["KHR_materials_ior"] = {"ior": float(ior)}
        if extensions:
            material["extensions"] = extensions
        self.materials.append(material)
        return len(self.materials) - 1

    def add_sampler(self, *, mag_filter: int | None = LINEAR, min_filter: int | None = LINEAR_MIPMAP_LINEAR,
                    wrap_s: int = REPEAT, wrap_t: int = REPEAT) -> int:
        sampler: dict = {}
        if mag_filter is not None:
            sampler["magFilter"] = mag_filter
        if min_filter is not None:
            sampler["minFilter"] = min_filter
        sampler["wrapS"], sampler["wrapT"] = wrap_s, wrap_t
        self.samplers.append(sampler)
        return len(self.samplers) - 1

    def add_png_texture(self, name: str, png: bytes, sampler: int | None = None) -> int:
        """A texture of PNG bytes (png_bytes()), stored in the buffer."""
        if not png.startswith(b"\x89PNG\r\n\x1a\n"):
            raise ValueError("not PNG data")
        self.images.append({"name": name, "bufferView": self._add_view(png, None), "mimeType": "image/png"})
        texture: dict = {"source": len(self.images) - 1}
        if sampler is not None:
            if not 0 <= sampler < len(self.samplers):
                raise ValueError(f"no sampler {sampler}")
            texture = {"sampler": sampler, **texture}
        self.textures.append(texture)
        return len(self.textures) - 1

    def add_camera(self, yfov: float, aspect_ratio: float | None = None, znear: float = 0.05,
                   zfar: float | None = 1000.0, name: str | None = None) -> int:
        """A perspective camera: yfov (vertical, radians), aspectRatio (width / height)."""
        if not 0.0 < yfov < math.pi or znear <= 0.0 or (zfar is not None and zfar <= znear):
            raise ValueError("a perspective camera needs 0 < yfov < pi and 0 < znear < zfar")
        perspective: dict = {}
        if aspect_ratio is not None:
            perspective["aspectRatio"] = float(aspect_ratio)
        perspective["yfov"] = float(yfov)
        if zfar is not None:
            perspective["zfar"] = float(zfar)
        perspective["znear"] = float(znear)
        camera: dict = {"type": "perspective", "perspective": perspective}
        if name is not None:
            camera = {"name": name, **camera}
        self.cameras.append(camera)
        return len(self.cameras) - 1

    def _add_light(self, kind: str, name: str | None, color: Sequence[float], intensity: float,
                   extra: dict | None = None) -> int:
        if intensity < 0.0 or any(c < 0.0 or c > 1.0 for c in color):
            raise ValueError("a light needs intensity >= 0 and a colour in [0, 1]")
        light: dict = {}
        if name is not None:
            light["name"] = name
        light["type"] = kind
        light["color"] = [float(c) for c in color]
        light["intensity"] = float(intensity)
        if extra:
            light.update(extra)
        self.lights.append(light)
        return len(self.lights) - 1

    def add_point_light(self, color: Sequence[float] = (1.0, 1.0, 1.0), intensity: float = 1.0,
                        name: str | None = None) -> int:
        """KHR_lights_punctual point light; intensity in candela (vkrt: W/sr)."""
        return self._add_light("point", name, color, intensity)

    def add_spot_light(self, color: Sequence[float] = (1.0, 1.0, 1.0), intensity: float = 1.0,
                       inner_cone_angle: float = 0.0, outer_cone_angle: float = math.pi / 4,
                       name: str | None = None) -> int:
        """KHR_lights_punctual spot light down the node's -Z; cone half-angles in
        radians, 0 <= inner < outer <= pi/2; intensity in candela."""
        if not 0.0 <= inner_cone_angle < outer_cone_angle <= math.pi / 2:
            raise ValueError("a spot light needs 0 <= innerConeAngle < outerConeAngle <= pi/2")
        spot = {"innerConeAngle": float(inner_cone_angle), "outerConeAngle": float(outer_cone_angle)}
        return self._add_light("spot", name, color, intensity, {"spot": spot})

    def add_directional_light(self, color: Sequence[float] = (1.0, 1.0, 1.0), intensity: float = 1.0,
                              name: str | None = None) -> int:
        """KHR_lights_punctual directional light down the node's -Z; intensity in lux (vkrt: W/m^2)."""
        return self._add_light("directional", name, color, intensity)

    def add_node(self, name: str | None = None, *, mesh: int | None = None, camera: int | None = None,
                 light: int | None = None, children: Iterable[int] = (), translation: Vec3 | None = None,
                 rotation: Sequence[float] | None = None, scale: Vec3 | None = None,
                 matrix: Matrix | None = None) -> int:
        """A node. rotation: unit quaternion [x, y, z, w]; matrix: row-major 4x4
        (written column-major), not with translation, rotation or scale."""
        if matrix is not None and (translation is not None or rotation is not None or scale is not None):
            raise ValueError("a node has either a matrix or translation/rotation/scale")
        for index, table, what in ((mesh, self.meshes, "mesh"), (camera, self.cameras, "camera"),
                                   (light, self.lights, "light")):
            if index is not None and not 0 <= index < len(table):
                raise ValueError(f"no {what} {index}")
        node: dict = {}
        if name is not None:
            node["name"] = name
        children = list(children)
        for child in children:
            self._check_child(len(self.nodes), child)
        if children:
            node["children"] = children
        if camera is not None:
            node["camera"] = camera
        if mesh is not None:
            node["mesh"] = mesh
        if matrix is not None:
            if [float(c) for c in matrix[3]] != [0.0, 0.0, 0.0, 1.0]:
                raise ValueError("a node matrix's last row is [0, 0, 0, 1]")
            node["matrix"] = to_column_major(matrix)
        if translation is not None:
            node["translation"] = [float(c) + 0.0 for c in translation]
        if rotation is not None:
            length = math.sqrt(sum(c * c for c in rotation))
            if abs(length - 1.0) > 1e-9:
                raise ValueError(f"rotation {rotation} is not a unit quaternion")
            node["rotation"] = [float(c) + 0.0 for c in rotation]
        if scale is not None:
            node["scale"] = [float(c) + 0.0 for c in scale]
        if light is not None:
            node["extensions"] = {"KHR_lights_punctual": {"light": light}}
        self.nodes.append(node)
        return len(self.nodes) - 1

    def _check_child(self, parent: int, child: int) -> None:
        if not 0 <= child < len(self.nodes) or child == parent:
            raise ValueError(f"no node {child} to make a child of node {parent}")
        for node in self.nodes:
            if child in node.get("children", []):
                raise ValueError(f"node {child} already has a parent")

    def add_child(self, parent: int, child: int) -> None:
        """Makes node `child` (a root so far) a child of node `parent`."""
        if not 0 <= parent < len(self.nodes):
            raise ValueError(f"no node {parent}")
        self._check_child(parent, child)
        if parent in self.descendants(child):
            raise ValueError("that would make a cycle")
        self.nodes[parent].setdefault("children", []).append(child)

    def descendants(self, node: int) -> list[int]:
        out, stack = [], [node]
        while stack:
            each = stack.pop()
            out.append(each)
            stack += self.nodes[each].get("children", [])
        return out

    def add_scene(self, nodes: Iterable[int], name: str | None = None) -> int:
        """A scene of root nodes; the first scene added is the default (`scene`)."""
        roots = list(nodes)
        parents = {c for n in self.nodes for c in n.get("children", [])}
        for root in roots:
            if not 0 <= root < len(self.nodes) or root in parents:
                raise ValueError(f"node {root} is not a root node")
        scene: dict = {"name": name} if name is not None else {}
        scene["nodes"] = roots
        self.scenes.append(scene)
        if self.scene is None:
            self.scene = len(self.scenes) - 1
        return len(self.scenes) - 1

    # -- queries -----------------------------------------------------------

    def local_matrix(self, node: int) -> Matrix:
        """A node's local transform, from the values the JSON holds."""
        n = self.nodes[node]
        if "matrix" in n:
            return from_column_major(n["matrix"])
        return trs_matrix(n.get("translation"), n.get("rotation"), n.get("scale"))

    def world_matrices(self, scene: int | None = None) -> dict[int, Matrix]:
        """Every node of a scene (default: the default one) with its world matrix, in double precision."""
        index = self.scene if scene is None else scene
        out: dict[int, Matrix] = {}
        stack = [(root, identity()) for root in reversed(self.scenes[index]["nodes"])]
        while stack:
            node, parent = stack.pop()
            world = mat_mul(parent, self.local_matrix(node))
            out[node] = world
            for child in reversed(self.nodes[node].get("children", [])):
                stack.append((child, world))
        return out

    def extensions_used(self) -> list[str]:
        """Every name under an "extensions" member anywhere in the document, sorted."""
        names: set[str] = set()

        def walk(value):
            if isinstance(value, dict):
                for key, each in value.items():
                    if key == "extensions" and isinstance(each, dict):
                        names.update(each)
                    walk(each)
            elif isinstance(value, list):
                for each in value:
                    walk(each)

        walk(self._document(None))
        return sorted(names)

    # -- output ------------------------------------------------------------

    def _document(self, buffer_uri: str | None) -> dict:
        doc: dict = {"asset": self.asset}
        if self.scene is not None:
            doc["scene"] = self.scene
        if self.lights:
            doc["extensions"] = {"KHR_lights_punctual": {"lights": self.lights}}
        for key, value in (("scenes", self.scenes), ("nodes", self.nodes), ("cameras", self.cameras),
                           ("meshes", self.meshes), ("materials", self.materials),
                           ("textures", self.textures), ("images", self.images), ("samplers", self.samplers),
                           ("accessors", self.accessors), ("bufferViews", self.buffer_views)):
            if value:
                doc[key] = value
        if self.binary:
            buffer: dict = {"byteLength": len(self._padded())}
            if buffer_uri is not None:
                buffer["uri"] = buffer_uri
            doc["buffers"] = [buffer]
        return doc

    def to_json(self, *, embedded: bool = True) -> dict:
        """The document; embedded: the buffer as a base64 data: URI (a .gltf),
        else without a uri (a .glb's BIN chunk)."""
        self._check()
        uri = None
        if embedded and self.binary:
            uri = "data:application/octet-stream;base64," + base64.b64encode(bytes(self._padded())).decode("ascii")
        doc = self._document(uri)
        used = self.extensions_used()
        if not used:
            return doc
        return {"asset": doc.pop("asset"), "extensionsUsed": used, **doc}

    def _padded(self) -> bytes:
        return bytes(self.binary) + b"\0" * (-len(self.binary) % 4)

    def _check(self) -> None:
        if not self.scenes:
            raise ValueError("the document has no scene: call add_scene")

    def gltf_bytes(self) -> bytes:
        """A .gltf file: JSON text with the buffer embedded."""
        return (dumps(self.to_json(embedded=True)) + "\n").encode("ascii")

    def glb_bytes(self) -> bytes:
        """A .glb file: header, JSON chunk (space-padded), BIN chunk (zero-padded)."""
        text = dumps(self.to_json(embedded=False)).encode("ascii")
        text += b" " * (-len(text) % 4)
        chunks = struct.pack("<I4s", len(text), b"JSON") + text
        if self.binary:
            data = self._padded()
            chunks += struct.pack("<I4s", len(data), b"BIN\0") + data
        return struct.pack("<4sII", b"glTF", 2, 12 + len(chunks)) + chunks

    def write(self, path: str | Path) -> Path:
        """Writes a .gltf or a .glb, by the file's extension."""
        path = Path(path)
        suffix = path.suffix.lower()
        if suffix not in (".gltf", ".glb"):
            raise ValueError(f"{path}: expected a .gltf or .glb name")
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(self.gltf_bytes() if suffix == ".gltf" else self.glb_bytes())
        return path


def dumps(value, indent: int = 0) -> str:
    """JSON text, two-space indented, with lists of numbers or strings on one
    line; floats by repr() (json's own), so the same document gives the same bytes."""
    pad, inner = "  " * indent, "  " * (indent + 1)
    if isinstance(value, dict):
        if not value:
            return "{}"
        items = [f"{inner}{json.dumps(k)}: {dumps(v, indent + 1)}" for k, v in value.items()]
        return "{\n" + ",\n".join(items) + "\n" + pad + "}"
    if isinstance(value, list):
        if all(not isinstance(v, (dict, list)) for v in value):
            return "[" + ", ".join(json.dumps(v, allow_nan=False) for v in value) + "]"
        return "[\n" + ",\n".join(inner + dumps(v, indent + 1) for v in value) + "\n" + pad + "]"
    return json.dumps(value, allow_nan=False)


# ---------------------------------------------------------------------------
# KHR_texture_transform baked into the uvs


def texture_transform_matrix(transform: dict) -> list[list[float]]:
    """The 2x3 affine map (rows) of a KHR_texture_transform object, as the
    extension defines it: uv' = T(offset) * R(rotation) * S(scale) * uv with
    R = [[cos, sin], [-sin, cos]], so u' = cos*sx*u + sin*sy*v + ox and
    v' = -sin*sx*u + cos*sy*v + oy (double precision)."""
    ox, oy = (float(c) for c in transform.get("offset", (0.0, 0.0)))
    sx, sy = (float(c) for c in transform.get("scale", (1.0, 1.0)))
    r = float(transform.get("rotation", 0.0))
    c, s = math.cos(r), math.sin(r)
    return [[c * sx, s * sy, ox], [-s * sx, c * sy, oy]]


def apply_texture_transform(transform: dict, uv: Sequence[float]) -> list[float]:
    """uv' of one uv under a KHR_texture_transform object, in double precision."""
    m = texture_transform_matrix(transform)
    u, v = float(uv[0]), float(uv[1])
    return [m[0][0] * u + m[0][1] * v + m[0][2] + 0.0, m[1][0] * u + m[1][1] * v + m[1][2] + 0.0]


_TEXTURE_SLOTS = ("baseColorTexture", "metallicRoughnessTexture")  # under pbrMetallicRoughness
_MATERIAL_TEXTURES = ("normalTexture", "occlusionTexture", "emissiveTexture")


def _texture_infos(material: dict) -> list[dict]:
    pbr = material.get("pbrMetallicRoughness", {})
    return [pbr[k] for k in _TEXTURE_SLOTS if k in pbr] + [material[k] for k in _MATERIAL_TEXTURES if k in material]


def bake_texture_transforms(g: Gltf, description: str | None = None) -> Gltf:
    """A copy of `g` in which each KHR_texture_transform is baked into the uvs.

    Every primitive whose material has a texture under KHR_texture_transform
    gets, in place of its TEXCOORD_n values, the transformed uvs
    (apply_texture_transform of the float32 values stored, computed in double
    precision and stored as float32), and the extension is removed from the
    material. Everything else is left as it was: the accessors, bufferViews and
    byte offsets, so the buffer differs only in the baked uv bytes, and every
    other part of the JSON (extensionsUsed is recomputed on writing, so it
    loses KHR_texture_transform). description, if given, replaces
    asset.extras.description. The map is affine and uvs are interpolated
    linearly across each triangle, so baking per vertex gives the same uv at
    every point of the surface.

    Refused (ValueError): a uv accessor shared by primitives whose materials
    transform it differently (or one transforms it and another does not), a
    material with two textures on one uv set under different transforms, and a
    transform's own texCoord override.
    """
    out = copy.deepcopy(g)
    # deepcopy keeps the keys of _geometry (ids of g's MeshData): key it by the copies.
    out._geometry = {id(new): out._geometry[id(old)] for old, new in zip(g._keep, out._keep)}

    def material_transforms(index: int) -> dict[int, dict | None]:
        """uv set -> its transform (None: untransformed) for one material."""
        sets: dict[int, dict | None] = {}
        for info in _texture_infos(out.materials[index]):
            transform = info.get("extensions", {}).get("KHR_texture_transform")
            if transform is not None and "texCoord" in transform:
                raise ValueError(f"material {index}: KHR_texture_transform's texCoord override is not baked")
            uv_set = info.get("texCoord", 0)
            if uv_set in sets and sets[uv_set] != transform:
                raise ValueError(f"material {index}: two textures on TEXCOORD_{uv_set} with different transforms")
            sets[uv_set] = transform
        return sets

    # accessor -> the transform every primitive reading it through a texture wants
    wanted: dict[int, dict | None] = {}
    baked_materials: set[int] = set()
    for m, mesh in enumerate(out.meshes):
        for p, primitive in enumerate(mesh["primitives"]):
            material = primitive.get("material")
            sets = material_transforms(material) if material is not None else {}
            for uv_set in range(8):
                name = f"TEXCOORD_{uv_set}"
                if name not in primitive["attributes"]:
                    continue
                accessor = primitive["attributes"][name]
                transform = sets.get(uv_set)
                if accessor in wanted and wanted[accessor] != transform:
                    raise ValueError(f"mesh {m} primitive {p}: {name} accessor {accessor} is shared with a "
                                     "primitive that transforms it differently")
                wanted[accessor] = transform
            for uv_set, transform in sets.items():
                if transform is not None:
                    if f"TEXCOORD_{uv_set}" not in primitive["attributes"]:
                        raise ValueError(f"mesh {m} primitive {p}: no TEXCOORD_{uv_set} to bake into")
                    baked_materials.add(material)

    meshes_by_accessor = {out._geometry[id(mesh)]["attributes"].get("TEXCOORD_0"): mesh for mesh in out._keep}
    for accessor, transform in wanted.items():
        if transform is None:
            continue
        a = out.accessors[accessor]
        if a["componentType"] != FLOAT or a["type"] != "VEC2" or "byteOffset" in a:
            raise ValueError(f"accessor {accessor}: expected tightly packed float VEC2 uvs")
        view = out.buffer_views[a["bufferView"]]
        start = view["byteOffset"]
        stored = struct.unpack_from(f"<{2 * a['count']}f", out.binary, start)
        uvs = [apply_texture_transform(transform, stored[i:i + 2]) for i in range(0, len(stored), 2)]
        struct.pack_into(f"<{2 * a['count']}f", out.binary, start, *(c for uv in uvs for c in uv))
        if "min" in a:
            kept = [[f32(c) for c in uv] for uv in uvs]
            a["min"] = [min(uv[k] for uv in kept) for k in range(2)]
            a["max"] = [max(uv[k] for uv in kept) for k in range(2)]
        mesh = meshes_by_accessor.get(accessor)
        if mesh is not None:  # the MeshData (for OBJ output) holds the baked float32 values too
            mesh.texcoords = [[f32(c) for c in uv] for uv in uvs]

    for index in sorted(baked_materials):
        for info in _texture_infos(out.materials[index]):
            extensions = info.get("extensions", {})
            extensions.pop("KHR_texture_transform", None)
            if "extensions" in info and not extensions:
                del info["extensions"]
    if description is not None:
        out.asset.setdefault("extras", {})["description"] = description
    return out


# ---------------------------------------------------------------------------
# The same scene for vkrt's TOML format: camera, lights, meshes as OBJ parts


def toml_number(x: float) -> str:
    """A TOML float by repr() (exact); integers as floats too ("2.0")."""
    x = float(x) + 0.0
    if not math.isfinite(x):
        raise ValueError("TOML scenes take finite numbers only")
    return repr(x)


def toml_list(values: Iterable[float]) -> str:
    return "[" + ", ".join(toml_number(v) for v in values) + "]"


def toml_key(name: str) -> str:
    bare = name and all(c.isascii() and (c.isalnum() or c in "_-") for c in name)
    return name if bare else json.dumps(name)


def obj_text(mesh: MeshData, comment: str) -> str:
    """An OBJ of a mesh in its own (object) space: v, vt (v flipped: OBJ's v
    runs up the image), vn, and f v/vt/vn, numbers as the float32 the glTF holds."""
    lines = [f"# {line}" for line in comment.splitlines()]
    for p in mesh.positions:
        lines.append("v " + " ".join(f32_text(c) for c in p))
    if mesh.texcoords is not None:
        for u, v in mesh.texcoords:
            lines.append(f"vt {f32_text(u)} {f32_text(1.0 - f32(v))}")
    if mesh.normals is not None:
        for n in mesh.normals:
            lines.append("vn " + " ".join(f32_text(c) for c in n))
    for i in range(0, len(mesh.indices), 3):
        corners = []
        for index in mesh.indices[i:i + 3]:
            k = str(index + 1)
            corners.append(k + ("/" + k if mesh.texcoords is not None else "/" if mesh.normals is not None else "")
                           + ("/" + k if mesh.normals is not None else ""))
        lines.append("f " + " ".join(corners))
    return "\n".join(lines) + "\n"


@dataclass
class VkrtScene:
    """What gltf_to_vkrt found: the TOML text, the OBJ files (name -> text) and the world-space numbers."""

    toml: str
    objs: dict[str, str]
    camera: dict
    lights: list[dict]
    objects: list[dict]


def gltf_to_vkrt(g: Gltf, *, parts_dir: str, width: int, height: int,
                 header: str = "") -> VkrtScene:
    """The default scene of `g` written as a vkrt TOML scene: the first camera
    as [camera] (eye = the camera node's world origin, target = eye + its world
    -Z, up = its world +Y, fov = degrees(yfov)); each KHR_lights_punctual
    light as a [[lights]] entry (point: position, intensity = color x
    intensity in W/sr; spot: also direction = world -Z and the cone half-angles
    in degrees; directional: direction = world -Z, the way the light travels,
    irradiance = color x intensity in W/m^2); each mesh primitive as an OBJ
    file in object space placed by `matrix` = its node's world matrix, with
    its material as a vkrt `pbr` material (what vkrt's `material = "file"`
    makes of a glTF metallic-roughness material, src/scene/FileMaterialImport.cpp:
    base_color = baseColorFactor's rgb, metallic, roughness; emission =
    emissiveFactor x KHR_materials_emissive_strength). Every number is
    computed in double precision from the values the glTF JSON holds and
    written by repr(). Textures and transmission are refused: vkrt's pbr
    kind has no transmission, and this is for scenes without textures."""
    if width <= 0 or height <= 0:
        raise ValueError("width and height must be positive")
    worlds = g.world_matrices()
    order = list(worlds)  # depth first, in document order
    out = [header.rstrip("\n")] if header else []
    camera_nodes = [n for n in order if "camera" in g.nodes[n]]
    if not camera_nodes:
        raise ValueError("the scene has no camera node")
    cam_node = camera_nodes[0]
    cam = g.cameras[g.nodes[cam_node]["camera"]]
    if cam["type"] != "perspective":
        raise ValueError("only perspective cameras")
    aspect = cam["perspective"].get("aspectRatio")
    if aspect is not None and abs(aspect - width / height) > 1e-12:
        raise ValueError(f"width / height = {width / height!r} differs from the camera's aspectRatio {aspect!r}")
    m = worlds[cam_node]
    eye = [m[r][3] + 0.0 for r in range(3)]
    forward = normalize(transform_vector(m, (0.0, 0.0, -1.0)))
    target = [eye[i] + forward[i] + 0.0 for i in range(3)]
    up = [c + 0.0 for c in normalize(transform_vector(m, (0.0, 1.0, 0.0)))]
    fov = math.degrees(cam["perspective"]["yfov"])
    camera = {"node": cam_node, "eye": eye, "target": target, "up": up, "fov": fov, "width": width,
              "height": height}
    out += ["", f"# glTF node {cam_node} ({g.nodes[cam_node].get('name', '')}): camera "
                f"{g.nodes[cam_node]['camera']}, yfov {cam['perspective']['yfov']!r} rad", "[camera]",
            f"eye = {toml_list(eye)}", f"target = {toml_list(target)}", f"up = {toml_list(up)}",
            f"fov = {toml_number(fov)}", f"width = {width}", f"height = {height}"]

    used_materials: list[int] = []
    objects: list[dict] = []
    objs: dict[str, str] = {}
    for node in order:
        if "mesh" not in g.nodes[node]:
            continue
        mesh_index = g.nodes[node]["mesh"]
        for p, (data, material) in enumerate(g.mesh_data[mesh_index]):
            if material is None:
                raise ValueError("every primitive needs a material for the TOML scene")
            name = g.meshes[mesh_index]["name"] + (f"-{p}" if len(g.mesh_data[mesh_index]) > 1 else "")
            file = f"{parts_dir}/{name}.obj"
            objs.setdefault(file, obj_text(data, f"glTF mesh {mesh_index} ('{g.meshes[mesh_index]['name']}'), "
                                                 f"primitive {p}, in object space; written by {GENERATOR}"))
            if material not in used_materials:
                used_materials.append(material)
            objects.append({"node": node, "file": file, "material": g.materials[material]["name"],
                            "matrix": worlds[node]})

    for index in used_materials:
        mat = g.materials[index]
        pbr = mat.get("pbrMetallicRoughness", {})
        ext = mat.get("extensions", {})
        if "baseColorTexture" in pbr or "metallicRoughnessTexture" in pbr or "normalTexture" in mat \
                or "emissiveTexture" in mat or set(ext) - {"KHR_materials_emissive_strength"}:
            raise ValueError(f"material {mat['name']}: only untextured metallic-roughness materials "
                             "(and emissive strength) have a vkrt pbr equal")
        out += ["", f"# glTF material {index}", f"[materials.{toml_key(mat['name'])}]", 'type = "pbr"',
                f"base_color = {toml_list(pbr.get('baseColorFactor', [1.0, 1.0, 1.0, 1.0])[:3])}",
                f"metallic = {toml_number(pbr.get('metallicFactor', 1.0))}",
                f"roughness = {toml_number(pbr.get('roughnessFactor', 1.0))}"]
        if any(mat.get("emissiveFactor", [0.0])):
            strength = ext.get("KHR_materials_emissive_strength", {}).get("emissiveStrength", 1.0)
            out.append(f"emission = {toml_list(c * strength for c in mat['emissiveFactor'])}")

    for each in objects:
        node = each["node"]
        rows = ",\n    ".join(toml_list(row) for row in each["matrix"][:3])
        out += ["", f"# glTF node {node} ({g.nodes[node].get('name', '')}), mesh {g.nodes[node]['mesh']}: "
                    "its world matrix", "[[objects]]", 'shape = "mesh"', f'file = "{each["file"]}"',
                f"material = {json.dumps(each['material'])}",
                f"matrix = [\n    {rows},\n    [0.0, 0.0, 0.0, 1.0],\n]"]

    lights: list[dict] = []
    for node in order:
        ext = g.nodes[node].get("extensions", {}).get("KHR_lights_punctual")
        if ext is None:
            continue
        light = g.lights[ext["light"]]
        m = worlds[node]
        power = [c * light["intensity"] + 0.0 for c in light["color"]]
        entry: dict = {"node": node, "type": light["type"]}
        out += ["", f"# glTF node {node} ({g.nodes[node].get('name', '')}): light {ext['light']} "
                    f"({light['type']}, color {light['color']}, intensity {light['intensity']!r})", "[[lights]]",
                f'type = "{light["type"]}"']
        direction = [c + 0.0 for c in normalize(transform_vector(m, (0.0, 0.0, -1.0)))]
        if light["type"] in ("point", "spot"):
            entry["position"] = [m[r][3] + 0.0 for r in range(3)]
            out.append(f"position = {toml_list(entry['position'])}")
        if light["type"] in ("spot", "directional"):
            entry["direction"] = direction
            out.append(f"direction = {toml_list(direction)}")
        if light["type"] == "directional":
            entry["irradiance"] = power
            out.append(f"irradiance = {toml_list(power)}")
        else:
            entry["intensity"] = power
            out.append(f"intensity = {toml_list(power)}")
        if light["type"] == "spot":
            entry["inner_cone_angle"] = math.degrees(light["spot"].get("innerConeAngle", 0.0))
            entry["outer_cone_angle"] = math.degrees(light["spot"].get("outerConeAngle", math.pi / 4))
            out.append(f"inner_cone_angle = {toml_number(entry['inner_cone_angle'])}")
            out.append(f"outer_cone_angle = {toml_number(entry['outer_cone_angle'])}")
        lights.append(entry)
    return VkrtScene("\n".join(out) + "\n", objs, camera, lights, objects)


# ---------------------------------------------------------------------------
# The shipped scenes (scenes/gltf/, README.md there says what each exercises)

# Factors are multiples of 1/64 where they can be: float32 (glTF as assimp reads
# it) and double (vkrt's TOML) hold them exactly, so both paths agree.

LIGHTS_CAMERA_DESCRIPTION = (
    "vkrt test scene: a perspective camera (yfov 0.6 rad, aspectRatio 4/3) placed by translation and a "
    "look-at rotation; a floor quad rotated into the XZ plane; a cube mesh instanced twice (node 'cube A', "
    "child of the transformed node 'cube rig'; node 'cube B', placed by a matrix); a metallic UV sphere; "
    "a point light, a spot light (inner 0.25 < outer 0.45 rad, its node a child of the rotated node "
    "'light rig') and a directional light, each on its own node and shining down its -Z. No environment. "
    "lights-camera.toml is the same scene in vkrt's TOML format.")

TRANSMISSION_DESCRIPTION = (
    "vkrt test scene: a clear glass sphere (KHR_materials_transmission 1, KHR_materials_ior 1.5, "
    "roughness 0) and a frosted one (transmission 1, roughness 0.3, ior 1.33) over a floor with a "
    "coloured checker base-colour texture (PNG), one perspective camera, one directional light.")

TEXTURE_TRANSFORM_DESCRIPTION = (
    "vkrt test scene: a quad whose base colour is a small checker PNG (a red and a green cell mark its "
    "top-left corner) under KHR_texture_transform (scale [3, 2], rotation 0.3 rad, offset [0.25, 0.125]); "
    "an emissive quad (emissiveFactor [1, 0.5, 0.25], KHR_materials_emissive_strength 4); a floor, "
    "a perspective camera and a point light.")


TEXTURE_TRANSFORM_BAKED_DESCRIPTION = (
    "vkrt test scene: texture-transform.gltf with its KHR_texture_transform (scale [3, 2], rotation 0.3 rad, "
    "offset [0.25, 0.125]) baked into the textured quad's TEXCOORD_0 (u' = cos*sx*u + sin*sy*v + ox, "
    "v' = -sin*sx*u + cos*sy*v + oy, computed in double precision, stored as float32) and the extension "
    "removed; everything else (the checker PNG, the emissive quad with KHR_materials_emissive_strength 4, "
    "the floor, the camera and the point light) is the same, so both files render to statistically equal "
    "images.")


def lights_camera() -> tuple[Gltf, dict[str, int]]:
    """lights-camera.gltf; returns the document and its named nodes."""
    g = Gltf(description=LIGHTS_CAMERA_DESCRIPTION)
    floor_mat = g.add_material("floor", base_color=(0.75, 0.75, 0.75, 1.0), metallic=0.0, roughness=0.75)
    cube_mat = g.add_material("red", base_color=(0.75, 0.25, 0.125, 1.0), metallic=0.0, roughness=0.5)
    gold_mat = g.add_material("gold", base_color=(0.9375, 0.75, 0.375, 1.0), metallic=1.0, roughness=0.25)
    floor = g.add_mesh("floor", [(quad(8.0, 8.0), floor_mat)])
    box = g.add_mesh("cube", [(cube(1.0), cube_mat)])
    ball = g.add_mesh("sphere", [(uv_sphere(0.6, 32, 16), gold_mat)])
    nodes: dict[str, int] = {}
    nodes["floor"] = g.add_node("floor", mesh=floor, rotation=quat_axis_angle((1, 0, 0), -math.pi / 2))
    nodes["cube A"] = g.add_node("cube A", mesh=box, translation=(0.0, 0.5, 0.0))
    nodes["cube rig"] = g.add_node("cube rig", children=[nodes["cube A"]], translation=(-1.25, 0.0, -0.5),
                                   rotation=quat_axis_angle((0, 1, 0), math.radians(30)), scale=(1.25, 1.25, 1.25))
    # cube B: a matrix with a rotation about Y, a non-uniform scale and a translation.
    b = mat_mul(trs_matrix((1.5, 0.25, 0.75), quat_axis_angle((0, 1, 0), math.radians(-20))), identity())
    b = mat_mul(b, trs_matrix(scale=(0.75, 0.5, 0.75)))
    nodes["cube B"] = g.add_node("cube B", mesh=box, matrix=b)
    nodes["sphere"] = g.add_node("sphere", mesh=ball, translation=(0.25, 0.6, -1.5))
    eye = (1.0, 2.5, 6.0)
    nodes["camera"] = g.add_node("camera", camera=g.add_camera(0.6, 4.0 / 3.0, 0.05, 100.0, name="camera"),
                                 translation=eye, rotation=quat_look_at(eye, (0.0, 0.5, -0.25)))
    nodes["point"] = g.add_node("point light", light=g.add_point_light((1.0, 0.875, 0.75), 12.0, name="point"),
                                translation=(-2.5, 3.0, 2.0))
    # The spot's node is a child of a rotated rig; its local rotation aims it at the cube B / sphere area.
    rig = trs_matrix((0.5, 1.0, 0.0), quat_axis_angle((0, 1, 0), math.radians(45)))
    spot_pos_world, spot_target_world = (2.5, 4.0, 2.0), (0.75, 0.0, -0.25)
    inv = mat_inverse(rig)
    local_pos = transform_point(inv, spot_pos_world)
    local_target = transform_point(inv, spot_target_world)
    spot_light = g.add_spot_light((0.75, 0.875, 1.0), 40.0, 0.25, 0.45, name="spot")
    nodes["spot"] = g.add_node("spot light", light=spot_light, translation=local_pos,
                               rotation=quat_look_at(local_pos, local_target))
    nodes["light rig"] = g.add_node("light rig", children=[nodes["spot"]], translation=(0.5, 1.0, 0.0),
                                    rotation=quat_axis_angle((0, 1, 0), math.radians(45)))
    nodes["sun"] = g.add_node("sun", light=g.add_directional_light((1.0, 1.0, 1.0), 0.75, name="sun"),
                              rotation=quat_look_at((0.0, 0.0, 0.0), (-0.5, -2.0, -1.0)))
    g.add_scene([nodes["floor"], nodes["cube rig"], nodes["cube B"], nodes["sphere"], nodes["camera"],
                 nodes["point"], nodes["light rig"], nodes["sun"]], name="lights-camera")
    return g, nodes


def lights_camera_toml(g: Gltf) -> VkrtScene:
    header = f"""\
# lights-camera.gltf written by hand for vkrt's TOML format: the same camera,
# lights, meshes and materials, every number computed by tools/gltf_writer.py
# (in double precision, from the values the glTF JSON holds, written by
# repr()). Regenerate both with: tools/gltf_writer.py scenes scenes/gltf
#
# - camera: eye = the camera node's world origin, target = eye + its world -Z,
#   up = its world +Y, fov = degrees(yfov); 160x120 is the aspectRatio 4/3.
# - lights: glTF intensities are taken as radiometric (point and spot:
#   candela as W/sr; directional: lux as W/m^2, no 683 lm/W), times the
#   light's colour; a light shines down its node's world -Z; cone angles are
#   the glTF half-angles in degrees.
# - meshes: lights-camera-parts/*.obj hold each glTF mesh in object space
#   (the float32 values of the glTF buffer); each node that names a mesh is
#   one [[objects]] entry whose matrix is that node's world matrix.
# - materials: vkrt's pbr kind as material = "file" makes it of a glTF
#   metallic-roughness material (base_color = baseColorFactor's rgb,
#   metallic = metallicFactor, roughness = roughnessFactor).
# - no [render] table and no [background]: the defaults (the glTF has neither).
#
# {LIGHTS_CAMERA_DESCRIPTION[len("vkrt test scene: "):]}"""
    # the description as comment lines of at most ~76 characters
    lines = header.splitlines()
    last = lines.pop()
    words, line = last[2:].split(), "#"
    for word in words:
        if len(line) + 1 + len(word) > 78:
            lines.append(line)
            line = "#"
        line += " " + word
    lines.append(line)
    return gltf_to_vkrt(g, parts_dir="lights-camera-parts", width=160, height=120,
                        header="\n".join(lines))


def transmission() -> Gltf:
    g = Gltf(description=TRANSMISSION_DESCRIPTION)
    checker = checker_pixels(64, 8, (230, 140, 40), (40, 110, 150))
    sampler = g.add_sampler(mag_filter=NEAREST, min_filter=LINEAR_MIPMAP_LINEAR)
    tex = g.add_png_texture("checker", png_bytes(64, 64, checker), sampler)
    floor_mat = g.add_material("checker floor", base_color_texture=TextureRef(tex), metallic=0.0, roughness=0.75)
    glass = g.add_material("glass", base_color=(1.0, 1.0, 1.0, 1.0), metallic=0.0, roughness=0.0,
                           transmission=1.0, ior=1.5)
    frosted = g.add_material("frosted glass", base_color=(1.0, 1.0, 1.0, 1.0), metallic=0.0, roughness=0.3,
                             transmission=1.0, ior=1.33)
    sphere = uv_sphere(0.75, 40, 20)  # one geometry, two meshes (its accessors are shared)
    floor = g.add_mesh("floor", [(quad(10.0, 10.0, (5.0, 5.0)), floor_mat)])
    clear = g.add_mesh("glass sphere", [(sphere, glass)])
    rough = g.add_mesh("frosted sphere", [(sphere, frosted)])
    roots = [
        g.add_node("floor", mesh=floor, rotation=quat_axis_angle((1, 0, 0), -math.pi / 2)),
        g.add_node("glass sphere", mesh=clear, translation=(-0.9, 0.75, 0.0)),
        g.add_node("frosted sphere", mesh=rough, translation=(0.9, 0.75, 0.0)),
    ]
    eye = (0.0, 1.75, 5.0)
    roots.append(g.add_node("camera", camera=g.add_camera(0.6, 4.0 / 3.0, 0.05, 100.0, name="camera"),
                            translation=eye, rotation=quat_look_at(eye, (0.0, 0.6, 0.0))))
    roots.append(g.add_node("sun", light=g.add_directional_light((1.0, 0.96875, 0.9375), 3.0, name="sun"),
                            rotation=quat_look_at((0.0, 0.0, 0.0), (0.5, -2.0, -1.0))))
    g.add_scene(roots, name="transmission")
    return g


def texture_transform() -> Gltf:
    g = Gltf(description=TEXTURE_TRANSFORM_DESCRIPTION)
    white, grey = (235, 235, 235), (60, 60, 60)
    checker = checker_pixels(16, 4, white, grey, marks={(0, 0): (220, 30, 30), (1, 0): (30, 200, 30)})
    sampler = g.add_sampler(mag_filter=NEAREST, min_filter=LINEAR_MIPMAP_LINEAR)
    tex = g.add_png_texture("marked checker", png_bytes(16, 16, checker), sampler)
    panel_mat = g.add_material(
        "transformed checker", metallic=0.0, roughness=0.5,
        base_color_texture=TextureRef(tex, offset=(0.25, 0.125), rotation=0.3, scale=(3.0, 2.0)))
    lamp_mat = g.add_material("lamp", base_color=(0.125, 0.125, 0.125, 1.0), metallic=0.0, roughness=0.5,
                              emissive=(1.0, 0.5, 0.25), emissive_strength=4.0)
    floor_mat = g.add_material("floor", base_color=(0.5, 0.5, 0.5, 1.0), metallic=0.0, roughness=0.75)
    panel = g.add_mesh("panel", [(quad(2.0, 2.0), panel_mat)])
    lamp = g.add_mesh("lamp", [(quad(0.5, 1.5), lamp_mat)])
    floor = g.add_mesh("floor", [(quad(8.0, 8.0), floor_mat)])
    roots = [
        g.add_node("panel", mesh=panel, translation=(0.0, 1.0, 0.0)),
        g.add_node("lamp", mesh=lamp, translation=(1.75, 0.75, 0.5),
                   rotation=quat_axis_angle((0, 1, 0), math.radians(-40))),
        g.add_node("floor", mesh=floor, rotation=quat_axis_angle((1, 0, 0), -math.pi / 2)),
    ]
    eye = (0.75, 1.5, 5.5)
    roots.append(g.add_node("camera", camera=g.add_camera(0.6, 4.0 / 3.0, 0.05, 100.0, name="camera"),
                            translation=eye, rotation=quat_look_at(eye, (0.4, 0.9, 0.0))))
    roots.append(g.add_node("point light", light=g.add_point_light((1.0, 1.0, 1.0), 8.0, name="point"),
                            translation=(-1.5, 2.5, 2.5)))
    g.add_scene(roots, name="texture-transform")
    return g


def write_scenes(outdir: str | Path, glb: bool = False) -> list[Path]:
    """Writes the shipped scenes into outdir; returns the paths written."""
    outdir = Path(outdir)
    written = []
    lc, _ = lights_camera()
    tt = texture_transform()
    documents = {"lights-camera": lc, "transmission": transmission(), "texture-transform": tt,
                 "texture-transform-baked": bake_texture_transforms(tt, TEXTURE_TRANSFORM_BAKED_DESCRIPTION)}
    for stem, doc in documents.items():
        written.append(doc.write(outdir / f"{stem}.gltf"))
        if glb:
            written.append(doc.write(outdir / f"{stem}.glb"))
    vkrt = lights_camera_toml(lc)
    for name, text in vkrt.objs.items():
        path = outdir / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(text.encode("ascii"))
        written.append(path)
    path = outdir / "lights-camera.toml"
    path.write_bytes(vkrt.toml.encode("ascii"))
    written.append(path)
    return written


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description="vkrt's glTF 2.0 writer (see the module docstring).")
    sub = parser.add_subparsers(dest="command", required=True)
    scenes = sub.add_parser("scenes", help="write the scenes shipped in scenes/gltf/ into OUTDIR")
    scenes.add_argument("outdir")
    scenes.add_argument("--glb", action="store_true", help="also write a .glb of each .gltf")
    args = parser.parse_args(argv)
    if args.command == "scenes":
        for path in write_scenes(args.outdir, glb=args.glb):
            print(f"{path} ({path.stat().st_size} bytes)")
    return 0


if __name__ == "__main__":
    sys.exit(main())

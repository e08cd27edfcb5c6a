#!/usr/bin/env python3
"""Write scenes/gltf/anisotropy-spheres.gltf, a small KHR_materials_anisotropy test scene.

    tools/make_anisotropy_spheres.py [OUTPUT.gltf]

Python 3 standard library only. The scene follows the idea of the Khronos
samples AnisotropyStrengthTest and AnisotropyRotationTest on six white metal
UV spheres (baseColorFactor 0.9, metallic 1, roughness 0.35) in two rows, seen
straight on by a perspective camera and lit by one KHR_lights_punctual
directional light from the upper left behind the camera (no environment, so
each sphere shows its highlight alone):

    top row, left to right:     anisotropyStrength 0, 0.5, 1 (rotation 0)
    bottom row, left to right:  anisotropyRotation 0, pi/4, pi/2 (strength 0.8)

Every sphere has POSITION, NORMAL, TEXCOORD_0 and TANGENT. The uvs are
glTF's equirectangular mapping, u = longitude / 2 pi growing eastwards
(counter-clockwise seen from the north pole, +Y) and v = 0 at the north pole,
so the top of a texture lies at the north and the sphere shows it unmirrored.
TANGENT is the direction of increasing u (east), w = +1: the bitangent
w cross(normal, tangent) then points north, towards *decreasing* glTF v, which
is "up" in the image (glTF's normal textures have +Y up). That is the
MikkTSpace tangent frame that Blender's importer and exporter compute (they
flip v, v' = 1 - v, so north is increasing v'), so the file's tangents agree
with any renderer that derives them from the uvs.

What a renderer should show (KHR_materials_anisotropy: the direction is the
rotation counter-clockwise from the tangent towards the bitangent, and the
highlight stretches along it): on the top row the highlight grows from a round
spot into an east-west streak; on the bottom row the streak is horizontal,
then turned 45 degrees to lie from lower left to upper right, then vertical.

The output is the same bytes on every run (numbers written by repr(), JSON
keys in a fixed order), with the buffer embedded as a base64 data: URI.
"""
from __future__ import annotations

import argparse
import base64
import json
import math
import struct
from pathlib import Path

from gltf_writer import quat_from_mat3, uv_sphere_indices  # tools/gltf_writer.py, beside this script

REPO = Path(__file__).resolve().parent.parent
DEFAULT_OUTPUT = REPO / "scenes" / "gltf" / "anisotropy-spheres.gltf"

# Geometry: fine enough that the smooth normals give round highlights, coarse
# enough that the file stays well under 100 KB like the other scenes/gltf files.
RADIUS = 0.45
SEGMENTS = 40
RINGS = 24
COLUMN_SPACING = 1.1
ROW_SPACING = 1.1

# The material every sphere shares, apart from its anisotropy.
BASE_COLOR = [0.9, 0.9, 0.9, 1.0]
METALLIC = 1.0
ROUGHNESS = 0.35

# (name, anisotropyStrength, anisotropyRotation) per row, left to right.
ROWS = [
    [("strength 0", 0.0, 0.0), ("strength 0.5", 0.5, 0.0), ("strength 1", 1.0, 0.0)],
    [("rotation 0", 0.8, 0.0), ("rotation pi/4", 0.8, math.pi / 4), ("rotation pi/2", 0.8, math.pi / 2)],
]

# Camera straight on, 4:3, so a sphere's east (its tangent) is the image's right.
CAMERA_EYE = (0.0, 0.0, 5.0)
CAMERA_YFOV = 0.6
CAMERA_ASPECT = 4.0 / 3.0

# A directional light from the upper left, in front: every highlight sits just
# up and left of its sphere's centre, where east is nearly horizontal and north
# nearly vertical on the image, so the streaks' directions read directly.
LIGHT_TOWARDS = (-0.4, 0.5, 1.0)  # from the scene towards the light
LIGHT_INTENSITY = 1.0  # lux: the round highlight's core clips, the broad streaks do not

# glTF enums.
FLOAT = 5126
UNSIGNED_SHORT = 5123
ARRAY_BUFFER = 34962
ELEMENT_ARRAY_BUFFER = 34963


def clean(x: float, eps: float = 1e-12) -> float:
    """x with |x| < eps made 0.0 (and -0.0 made 0.0): sin(pi) is 0 in a mesh."""
    return 0.0 if abs(x) < eps else x + 0.0


def f32(x: float) -> float:
    """x rounded to float32, the value the buffer stores (for exact min/max)."""
    return struct.unpack("<f", struct.pack("<f", x))[0]


def normalize(v):
    """v / |v|."""
    length = math.sqrt(sum(c * c for c in v))
    return [c / length for c in v]


def cross(a, b):
    """a x b."""
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def sphere_vertex(theta: float, phi: float):
    """Unit normal, and unit tangent d/dphi (east), at polar angle theta from
    +Y and longitude phi from +Z towards +X. The tangent is taken from phi
    alone so that it stays defined at the poles, where d/dphi vanishes."""
    normal = [clean(math.sin(theta) * math.sin(phi)), clean(math.cos(theta)),
              clean(math.sin(theta) * math.cos(phi))]
    tangent = [clean(math.cos(phi)), 0.0, clean(-math.sin(phi))]
    return normal, tangent


def uv_sphere(radius: float, segments: int, rings: int) -> dict:
    """A UV sphere about the origin with glTF's attributes as lists of rows.

    (segments + 1) x (rings + 1) vertices: a seam column and one vertex per
    pole per segment, so that uvs never wrap and every pole vertex has the
    tangent of its own longitude. Triangles wind counter-clockwise seen from
    outside; the poles' degenerate halves of the quads are left out."""
    positions, normals, texcoords, tangents, indices = [], [], [], [], []
    for ring in range(rings + 1):
        theta = math.pi * ring / rings
        for seg in range(segments + 1):
            phi = 2.0 * math.pi * seg / segments
            normal, tangent = sphere_vertex(theta, phi)
            if ring in (0, rings):  # exactly the pole, whatever sin(pi) rounds to
                normal = [0.0, 1.0 if ring == 0 else -1.0, 0.0]
            positions.append([clean(radius * c) for c in normal])
            normals.append(normal)
            texcoords.append([seg / segments, ring / rings])
            # w = +1: cross(normal, east) is north, the image's up (decreasing v).
            tangents.append(tangent + [1.0])
    indices += uv_sphere_indices(segments, rings)
    return {"POSITION": positions, "NORMAL": normals, "TEXCOORD_0": texcoords,
            "TANGENT": tangents, "indices": indices}


class BufferBuilder:
    """One binary buffer with a bufferView and an accessor per array, each
    view 4-byte aligned and tightly packed (so no byteStride)."""

    def __init__(self):
        self.data = bytearray()
        self.views = []
        self.accessors = []

    def _view(self, payload: bytes, target: int) -> int:
        self.data += b"\0" * (-len(self.data) % 4)
        self.views.append({"buffer": 0, "byteOffset": len(self.data), "byteLength": len(payload),
                           "target": target})
        self.data += payload
        return len(self.views) - 1

    def add_floats(self, rows, kind: str, with_bounds: bool = False) -> int:
        """A float accessor of VEC2/VEC3/VEC4 rows; min/max when asked
        (glTF requires them for POSITION), from the stored float32 values."""
        flat = [c for r in rows for c in r]
        view = self._view(struct.pack(f"<{len(flat)}f", *flat), ARRAY_BUFFER)
        accessor = {"bufferView": view, "componentType": FLOAT, "count": len(rows), "type": kind}
        if with_bounds:
            columns = list(zip(*rows))
            accessor["min"] = [f32(min(c)) for c in columns]
            accessor["max"] = [f32(max(c)) for c in columns]
        self.accessors.append(accessor)
        return len(self.accessors) - 1

    def add_indices(self, indices) -> int:
        """An UNSIGNED_SHORT index accessor (the sphere has far fewer than 65,536 vertices)."""
        if max(indices) >= 65536:
            raise ValueError("too many vertices for 16-bit indices")
        view = self._view(struct.pack(f"<{len(indices)}H", *indices), ELEMENT_ARRAY_BUFFER)
        self.accessors.append({"bufferView": view, "componentType": UNSIGNED_SHORT,
                               "count": len(indices), "type": "SCALAR"})
        return len(self.accessors) - 1

    def data_uri(self) -> str:
        return "data:application/octet-stream;base64," + base64.b64encode(bytes(self.data)).decode("ascii")


def add_sphere_geometry(buffers: BufferBuilder) -> dict:
    """The sphere's accessors, written once and shared by every mesh: the
    spheres differ only in material, which glTF puts on the primitive."""
    sphere = uv_sphere(RADIUS, SEGMENTS, RINGS)
    return {
        "attributes": {
            "POSITION": buffers.add_floats(sphere["POSITION"], "VEC3", with_bounds=True),
            "NORMAL": buffers.add_floats(sphere["NORMAL"], "VEC3"),
            "TEXCOORD_0": buffers.add_floats(sphere["TEXCOORD_0"], "VEC2"),
            "TANGENT": buffers.add_floats(sphere["TANGENT"], "VEC4"),
        },
        "indices": buffers.add_indices(sphere["indices"]),
    }


def material(name: str, strength: float, rotation: float) -> dict:
    """The shared white metal with one anisotropy setting. Strength 0 keeps the
    extension (isotropic by its own rule) so every sphere reads the same way."""
    return {
        "name": name,
        "pbrMetallicRoughness": {"baseColorFactor": BASE_COLOR, "metallicFactor": METALLIC,
                                 "roughnessFactor": ROUGHNESS},
        "extensions": {"KHR_materials_anisotropy": {"anisotropyStrength": strength,
                                                    "anisotropyRotation": rotation}},
    }


def facing(back, up=(0.0, 1.0, 0.0)):
    """The rotation of a node whose -Z points along -back (cameras look and
    lights shine down their node's -Z) with +Y as close to `up` as it can be."""
    z = normalize(back)
    x = normalize(cross(up, z))
    y = cross(z, x)
    # The rotation whose columns are x, y, z, as rows for gltf_writer's conversion.
    return quat_from_mat3([[x[0], y[0], z[0]], [x[1], y[1], z[1]], [x[2], y[2], z[2]]])


def sphere_nodes():
    """(name, translation) of each sphere, rows top to bottom, columns left to right."""
    out = []
    for r, row in enumerate(ROWS):
        y = ROW_SPACING * ((len(ROWS) - 1) / 2.0 - r)
        for c, (name, _, _) in enumerate(row):
            x = COLUMN_SPACING * (c - (len(row) - 1) / 2.0)
            out.append((name, [clean(x), clean(y), 0.0]))
    return out


def description() -> str:
    """asset.extras.description: what the file exercises, as the other scenes/gltf files say it."""
    return ("KHR_materials_anisotropy on six white metal UV spheres (baseColorFactor 0.9, metallic 1, "
            "roughness 0.35) with POSITION, NORMAL, TEXCOORD_0 and TANGENT (east, the direction of "
            "increasing u; w = +1, so the bitangent points north, up in the texture). Top row, left to "
            "right: anisotropyStrength 0, 0.5, 1 at rotation 0. Bottom row: anisotropyRotation 0, pi/4, "
            "pi/2 at strength 0.8. The highlight stretches along the anisotropy direction: east-west on "
            "the top row; horizontal, lower-left to upper-right, vertical on the bottom row. One "
            "perspective camera straight on, one KHR_lights_punctual directional light from the upper "
            "left; no environment. Written by tools/make_anisotropy_spheres.py.")


def build() -> dict:
    """The whole glTF document."""
    buffers = BufferBuilder()
    geometry = add_sphere_geometry(buffers)
    materials, meshes, nodes = [], [], []
    settings = [s for row in ROWS for s in row]
    for (name, strength, rotation), (node_name, translation) in zip(settings, sphere_nodes()):
        materials.append(material(name, strength, rotation))
        meshes.append({"name": name, "primitives": [dict(geometry, material=len(materials) - 1)]})
        nodes.append({"name": node_name, "mesh": len(meshes) - 1, "translation": translation})
    nodes.append({"name": "camera", "camera": 0, "translation": list(CAMERA_EYE)})
    nodes.append({"name": "light", "rotation": facing(LIGHT_TOWARDS),
                  "extensions": {"KHR_lights_punctual": {"light": 0}}})
    return {
        "asset": {"version": "2.0", "generator": "vkrt tools/make_anisotropy_spheres.py",
                  "extras": {"description": description()}},
        "extensionsUsed": ["KHR_materials_anisotropy", "KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"name": "sun", "type": "directional", "color": [1.0, 1.0, 1.0], "intensity": LIGHT_INTENSITY}]}},
        "scene": 0,
        "scenes": [{"name": "anisotropy spheres", "nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "cameras": [{"name": "camera", "type": "perspective",
                     "perspective": {"yfov": CAMERA_YFOV, "aspectRatio": CAMERA_ASPECT, "znear": 0.1,
                                     "zfar": 100.0}}],
        "meshes": meshes,
        "materials": materials,
        "accessors": buffers.accessors,
        "bufferViews": buffers.views,
        "buffers": [{"byteLength": len(buffers.data), "uri": buffers.data_uri()}],
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("output", nargs="?", type=Path, default=DEFAULT_OUTPUT,
                        help="the .gltf to write [scenes/gltf/anisotropy-spheres.gltf]")
    args = parser.parse_args()
    text = json.dumps(build(), indent=1) + "\n"
    args.output.parent.mkdir(parents=True, exist_ok=True)
    args.output.write_text(text)
    print(f"wrote {args.output} ({len(text)} bytes)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

#!/usr/bin/env python3
"""Render glTF files with vkrt and with Blender's Cycles from the same camera
under the same light, and report how well the two images agree.

    tools/compare_cycles.py MODEL.gltf [MODEL.gltf ...] [options]
    tools/compare_cycles.py --models DIR --table table.md [options]

Set-up, once: tools/setup-cycles-venv.sh (creates .venv-cycles/ with bpy,
NumPy and OpenEXR). This script re-executes itself with that environment's
Python, and runs tools/cycles_render.py there in a child process per model.

Options (defaults in brackets):
    --models DIR          every folder of DIR holding glTF/*.gltf (the layout of
                          the Khronos glTF sample models), or *.gltf directly
    --width/--height      image size [320 x 240], both renderers
    --spp N               samples per pixel, both renderers [256]
    --vkrt-spp/--cycles-spp N   per renderer, overriding --spp
    --seed N              both renderers' seed [1]
    --out DIR             where the PNGs (and with --keep-exr the EXRs) go
                          [compare-cycles/ in the current folder]
    --json FILE|-         all results as one JSON object
    --table FILE          a Markdown table (model, mean rel. diff, share > 10 %,
                          verdict, notes, PNG link relative to FILE's folder)
    --exclude NAME=WHY    leave a model out of the verdict (still rendered and
                          reported); repeatable
    --keep-extensions     render the models as they are, without stripping the
                          material extensions that differ by design (below)
    --vkrt PATH           the vkrt binary [$VKRT, else build/vkrt]
    --threads N           Cycles' CPU threads [0: all]
    --max-mean-diff F / --max-share F / --tolerance F   the verdict's thresholds

What both renderers are given
-----------------------------
* The camera. The tool walks the glTF's default scene as vkrt does (depth
  first, children in order) and takes the first camera node met (perspective,
  or orthographic: a view 2 ymag x the node's Y scale tall, as vkrt renders it
  since it renders orthographic cameras); without one it computes vkrt's
  framing camera
  (src/scene/GltfScene.cpp, framingCamera): vertical fov 40 degrees, looking at
  the centre of the world bounding box of all mesh instances (each glTF mesh's
  box of its triangle primitives' POSITION min/max, its 8 corners moved by the
  instance's world matrix, EXT_mesh_gpu_instancing included) from a distance
  1.1 * radius / sin(20 degrees) along normalize(0.35, 0.3, 1.0), up +Y. It
  writes a temporary copy of the .gltf beside the original (a unique hidden
  name, so relative URIs still resolve; deleted afterwards) with that camera
  added as a new root node, renders the copy with `vkrt render --camera N`,
  and gives Cycles the same camera (position, axes, vertical fov) converted to
  Blender's Z-up world the way Blender's glTF importer converts the scene.
* The light. Without KHR_lights_punctual lights: a constant white environment
  of radiance 1 (vkrt is given a constant lat-long map of 1 with
  --environment, in place of its grey studio default; Cycles: world
  Background, white, strength 1).
  With punctual lights: a black world and the file's lights, converted to
  vkrt's radiometric reading (docs/scene-format.md: intensity taken as W/sr,
  directional as W/m^2, no 683 lm/W): Blender point and spot power = 4 pi I
  (W), sun strength = E (W/m^2), radius/angle 0 (delta lights). Spot lights
  differ by design (glTF's smoothstep-like falloff between the cones is not
  Blender's spot blend): a model with one is excluded from the verdict.
* Cycles: path tracing on the CPU, max bounces 7 for every kind (vkrt's
  max_depth 8 counts surface interactions, the longest path having 9 segments;
  Cycles' max bounces 0 is direct light only: 8 interactions = 7 bounces), no
  clamping, no glossy filter, no light threshold, no adaptive sampling, no
  denoising, a box pixel filter 1 pixel wide (vkrt's: uniform jitter in the
  pixel), every Principled BSDF switched from multiscatter GGX to GGX (glTF's
  BRDF is single-scatter), view transform Standard, 32-bit float EXR.

Material extensions that differ by design (BY_DESIGN below: iridescence,
which Blender's importer does not read) are stripped from the temporary copy
for *both* renderers, so the rest of such a model is still compared; the
row's notes say what was stripped. --keep-extensions turns that off.
Thin-walled transmission (vkrt: unrefracted, as the extension says; Cycles:
refracted) and spot lights exclude the model from the verdict instead, as
does --exclude NAME=WHY.

Metrics (luminance Y = 0.2126 R + 0.7152 G + 0.0722 B of the linear images)
-------------------------------------------------------------------------
* mean relative difference: mean(Y_vkrt) / mean(Y_cycles) - 1, over the image;
* share over tolerance: both images blurred by a 3x3 box (edges repeated),
  then the fraction of pixels with |Yb_vkrt - Yb_cycles| / max(Yb_cycles,
  floor) > tolerance (0.10), floor = 0.05 * mean(Y_cycles), so that nearly
  black pixels do not dominate.

Verdict: pass when |mean relative difference| < 3 % and share < 5 %; else
fail; "excluded" for models left out (by design or --exclude), whose metrics
are still printed. The exit status is 1 when a judged model fails or a
render fails, else 0.

The PNG of each model is vkrt | Cycles | difference: the two renders
tone-mapped by the same operator (clamp to [0, 1], sRGB curve: the white
environment is white), and a heat map of the blurred signed relative
difference (blue: vkrt darker, red: vkrt brighter, full colour at +-25 %).
"""
from __future__ import annotations

import argparse
import base64
import json
import math
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import time
import uuid
import zlib
from pathlib import Path

TOOLS = Path(__file__).resolve().parent
REPO = TOOLS.parent
VENV = REPO / ".venv-cycles"


def ensure_venv() -> None:
    """Re-execute with .venv-cycles' Python (bpy, NumPy, OpenEXR) unless this is it."""
    if Path(sys.prefix).resolve() == VENV.resolve():
        return
    python = VENV / "bin" / "python"
    if not python.exists():
        if any(a in ("-h", "--help") for a in sys.argv[1:]):
            print(__doc__)
            sys.exit(0)
        print(f"compare_cycles: error: {VENV} does not exist: run tools/setup-cycles-venv.sh first", file=sys.stderr)
        sys.exit(2)
    os.execv(str(python), [str(python), str(Path(__file__).resolve())] + sys.argv[1:])


if __name__ == "__main__":
    ensure_venv()

import numpy as np  # noqa: E402

CYCLES_SCRIPT = TOOLS / "cycles_render.py"

# Thresholds of the verdict (documented in the module docstring).
MAX_MEAN_DIFF = 0.03
MAX_SHARE = 0.05
TOLERANCE = 0.10
FLOOR_FRACTION = 0.05

# vkrt's glTF defaults (src/scene/GltfScene.cpp).
FRAMING_FOV_Y = 40.0
FRAMING_DIRECTION = (0.35, 0.3, 1.0)
VKRT_MAX_DEPTH = 8
CYCLES_BOUNCES = VKRT_MAX_DEPTH - 1

# Material extensions whose Cycles rendering differs from vkrt's by design:
# stripped from the temporary copy (both renderers) unless --keep-extensions.
# (vkrt renders sheen, clearcoat and specular as their specifications say, and
# they are compared: Principled's sheen is a different lobe, its coat a true
# layer, yet the Khronos test models agree within the tool's rule.)
BY_DESIGN = {
    "KHR_materials_iridescence": "iridescence: Blender's glTF importer does not read it (Cycles would render "
                                 "the material without its film)",
}
# Features that exclude a model from the verdict (the model is rendered as it is).
EXCLUDING = {}
THIN_WALLED = ("thin-walled transmission: vkrt passes light unrefracted, as KHR_materials_transmission says "
               "without KHR_materials_volume; Cycles' Principled BSDF always refracts")


def has_thin_walled_transmission(gltf: dict) -> bool:
    """Whether some material transmits without a volume (KHR_materials_volume
    absent or of thicknessFactor 0): thin-walled, unrefracted in vkrt."""
    for m in gltf.get("materials", []):
        ext = m.get("extensions", {})
        if ext.get("KHR_materials_transmission", {}).get("transmissionFactor", 0.0) > 0.0 and \
                not ext.get("KHR_materials_volume", {}).get("thicknessFactor", 0.0) > 0.0:
            return True
    return False

# ----------------------------------------------------------------------------
# Metrics (pure NumPy: tests/tools/test_compare_cycles.py)
# ----------------------------------------------------------------------------


def luminance(rgb: np.ndarray) -> np.ndarray:
    """Rec. 709 luminance of a linear (H, W, 3) image (or (H, W) as it is)."""
    rgb = np.asarray(rgb, dtype=np.float64)
    if rgb.ndim == 2:
        return rgb
    return 0.2126 * rgb[..., 0] + 0.7152 * rgb[..., 1] + 0.0722 * rgb[..., 2]


def box_blur3(image: np.ndarray) -> np.ndarray:
    """3x3 box blur of an (H, W) array, edges repeated."""
    image = np.asarray(image, dtype=np.float64)
    padded = np.pad(image, 1, mode="edge")
    h, w = image.shape
    total = np.zeros_like(image)
    for dy in range(3):
        for dx in range(3):
            total += padded[dy:dy + h, dx:dx + w]
    return total / 9.0


def mean_relative_difference(y_vkrt: np.ndarray, y_cycles: np.ndarray) -> float:
    """mean(vkrt) / mean(Cycles) - 1 of two luminance images."""
    mean_cycles = float(np.mean(y_cycles))
    if mean_cycles <= 0.0:
        return 0.0 if float(np.mean(y_vkrt)) <= 0.0 else math.inf
    return float(np.mean(y_vkrt)) / mean_cycles - 1.0


def relative_difference_map(y_vkrt: np.ndarray, y_cycles: np.ndarray,
                            floor_fraction: float = FLOOR_FRACTION) -> np.ndarray:
    """Signed (blur(vkrt) - blur(Cycles)) / max(blur(Cycles), floor) per pixel,
    floor = floor_fraction * mean(Cycles luminance) (at least 1e-12)."""
    bv = box_blur3(y_vkrt)
    bc = box_blur3(y_cycles)
    floor = max(floor_fraction * float(np.mean(y_cycles)), 1e-12)
    return (bv - bc) / np.maximum(bc, floor)


def share_over(y_vkrt: np.ndarray, y_cycles: np.ndarray, tolerance: float = TOLERANCE,
               floor_fraction: float = FLOOR_FRACTION) -> float:
    """Fraction of pixels whose blurred luminance differs by more than tolerance."""
    rel = relative_difference_map(y_vkrt, y_cycles, floor_fraction)
    return float(np.mean(np.abs(rel) > tolerance))


def compare_images(vkrt_rgb: np.ndarray, cycles_rgb: np.ndarray, tolerance: float = TOLERANCE) -> dict:
    """The two metrics of two linear RGB (or luminance) images of one size."""
    if np.shape(vkrt_rgb) != np.shape(cycles_rgb):
        raise ValueError(f"image sizes differ: {np.shape(vkrt_rgb)} and {np.shape(cycles_rgb)}")
    yv, yc = luminance(vkrt_rgb), luminance(cycles_rgb)
    return {
        "mean_rel_diff": mean_relative_difference(yv, yc),
        "share_over": share_over(yv, yc, tolerance),
        "mean_luminance_vkrt": float(np.mean(yv)),
        "mean_luminance_cycles": float(np.mean(yc)),
    }


def verdict(metrics: dict, max_mean_diff: float = MAX_MEAN_DIFF, max_share: float = MAX_SHARE) -> str:
    """'pass' when |mean rel. diff| < max_mean_diff and share < max_share, else 'fail'."""
    ok = abs(metrics["mean_rel_diff"]) < max_mean_diff and metrics["share_over"] < max_share
    return "pass" if ok else "fail"


# ----------------------------------------------------------------------------
# glTF: walking the scene as vkrt does, the framing camera, the temporary copy
# ----------------------------------------------------------------------------


def _normalize(v):
    v = np.asarray(v, dtype=np.float64)
    n = np.linalg.norm(v)
    return v / n if n > 0 else None


def quat_to_matrix(q) -> np.ndarray:
    x, y, z, w = (float(c) for c in q)
    n = math.sqrt(x * x + y * y + z * z + w * w)
    if n == 0:
        return np.eye(3)
    x, y, z, w = x / n, y / n, z / n, w / n
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def trs_matrix(translation=(0, 0, 0), rotation=(0, 0, 0, 1), scale=(1, 1, 1)) -> np.ndarray:
    m = np.eye(4)
    m[:3, :3] = quat_to_matrix(rotation) @ np.diag([float(s) for s in scale])
    m[:3, 3] = [float(t) for t in translation]
    return m


def local_matrix(node: dict) -> np.ndarray:
    if "matrix" in node:
        return np.array(node["matrix"], dtype=np.float64).reshape(4, 4).T  # glTF is column-major
    return trs_matrix(node.get("translation", (0, 0, 0)), node.get("rotation", (0, 0, 0, 1)),
                      node.get("scale", (1, 1, 1)))


_COMPONENTS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}
_TYPES = {5120: ("b", 127.0), 5121: ("B", 255.0), 5122: ("h", 32767.0), 5123: ("H", 65535.0),
          5125: ("I", None), 5126: ("f", None)}


def read_accessor(gltf: dict, folder: Path, index: int) -> np.ndarray:
    """An accessor's values as float64 (count, components); normalized integers
    scaled as glTF says. No sparse substitution (not needed for the bounds and
    instancing data read here)."""
    acc = gltf["accessors"][index]
    n = _COMPONENTS[acc["type"]]
    count = acc["count"]
    fmt, norm = _TYPES[acc["componentType"]]
    if "bufferView" not in acc:
        return np.zeros((count, n))
    view = gltf["bufferViews"][acc["bufferView"]]
    buffer = gltf["buffers"][view["buffer"]]
    uri = buffer["uri"]
    if uri.startswith("data:"):
        data = base64.b64decode(uri.split(",", 1)[1])
    else:
        from urllib.parse import unquote
        data = (folder / unquote(uri)).read_bytes()
    item = np.dtype("<" + fmt)
    stride = view.get("byteStride") or item.itemsize * n
    start = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
    out = np.empty((count, n))
    for i in range(count):
        out[i] = np.frombuffer(data, dtype=item, count=n, offset=start + i * stride)
    if norm and acc.get("normalized"):
        out = np.maximum(out / norm, -1.0)
    return out


def walk_scene(gltf: dict, folder: Path | None = None):
    """vkrt's walk (src/mesh/GltfReader.cpp, walkNodes): the default scene's
    roots (or, without scenes, every node that is no child), depth first,
    children in order. Returns (instances [(mesh, world 4x4)], cameras
    [(camera index, node index, world)], lights [(light index, world)])."""
    nodes = gltf.get("nodes", [])
    scenes = gltf.get("scenes", [])
    if scenes:
        roots = list(scenes[gltf.get("scene", 0)].get("nodes", []))
    else:
        children = {c for n in nodes for c in n.get("children", [])}
        roots = [i for i in range(len(nodes)) if i not in children]
    instances, cameras, lights = [], [], []
    stack = [(r, np.eye(4)) for r in reversed(roots)]
    while stack:
        index, parent = stack.pop()
        node = nodes[index]
        world = parent @ local_matrix(node)
        if "mesh" in node:
            for instance in _instance_matrices(gltf, node, folder):
                placed = world @ instance
                det = np.linalg.det(placed[:3, :3])
                if abs(det) > 0 and math.isfinite(det):
                    instances.append((node["mesh"], placed))
        if "camera" in node:
            cameras.append((node["camera"], index, world))
        light = node.get("extensions", {}).get("KHR_lights_punctual", {})
        if "light" in light:
            lights.append((light["light"], world))
        for child in reversed(node.get("children", [])):
            stack.append((child, world))
    return instances, cameras, lights


def _instance_matrices(gltf: dict, node: dict, folder: Path | None):
    attributes = node.get("extensions", {}).get("EXT_mesh_gpu_instancing", {}).get("attributes")
    if not attributes or folder is None:
        return [np.eye(4)]
    t = read_accessor(gltf, folder, attributes["TRANSLATION"]) if "TRANSLATION" in attributes else None
    r = read_accessor(gltf, folder, attributes["ROTATION"]) if "ROTATION" in attributes else None
    s = read_accessor(gltf, folder, attributes["SCALE"]) if "SCALE" in attributes else None
    count = max(len(a) for a in (t, r, s) if a is not None) if any(a is not None for a in (t, r, s)) else 0
    if count == 0:
        return [np.eye(4)]
    return [trs_matrix(t[i] if t is not None else (0, 0, 0), r[i] if r is not None else (0, 0, 0, 1),
                       s[i] if s is not None else (1, 1, 1)) for i in range(count)]


def mesh_bounds(gltf: dict, mesh_index: int, folder: Path | None = None):
    """Local (lower, upper) of a mesh's triangle primitives (modes 4-6), from
    the POSITION accessors' min/max (read from the data when absent)."""
    lower, upper = np.full(3, np.inf), np.full(3, -np.inf)
    for primitive in gltf["meshes"][mesh_index]["primitives"]:
        if primitive.get("mode", 4) < 4 or "POSITION" not in primitive.get("attributes", {}):
            continue
        acc = gltf["accessors"][primitive["attributes"]["POSITION"]]
        if "min" in acc and "max" in acc:
            lo, hi = np.array(acc["min"], float), np.array(acc["max"], float)
        elif folder is not None:
            data = read_accessor(gltf, folder, primitive["attributes"]["POSITION"])
            lo, hi = data.min(axis=0), data.max(axis=0)
        else:
            continue
        lower, upper = np.minimum(lower, lo), np.maximum(upper, hi)
    return lower, upper


def world_bounds(gltf: dict, instances, folder: Path | None = None):
    """Union of each instance's local box with its 8 corners transformed (vkrt's boundsOf(Mesh))."""
    lower, upper = np.full(3, np.inf), np.full(3, -np.inf)
    cache = {}
    for mesh, world in instances:
        if mesh not in cache:
            cache[mesh] = mesh_bounds(gltf, mesh, folder)
        lo, hi = cache[mesh]
        if not np.all(lo <= hi):
            continue
        for corner in range(8):
            p = np.array([hi[0] if corner & 1 else lo[0], hi[1] if corner & 2 else lo[1],
                          hi[2] if corner & 4 else lo[2], 1.0])
            q = (world @ p)[:3]
            lower, upper = np.minimum(lower, q), np.maximum(upper, q)
    return lower, upper


def framing_camera(lower, upper) -> dict:
    """vkrt's framingCamera: eye, target, up, vertical fov in degrees."""
    lower, upper = np.asarray(lower, float), np.asarray(upper, float)
    empty = not np.all(lower <= upper)
    centre = np.zeros(3) if empty else 0.5 * (lower + upper)
    radius = 1.0 if empty else max(0.5 * float(np.linalg.norm(upper - lower)), 1e-6)
    distance = 1.1 * radius / math.sin(math.radians(FRAMING_FOV_Y / 2.0))
    eye = centre + distance * _normalize(FRAMING_DIRECTION)
    return {"eye": eye.tolist(), "target": centre.tolist(), "up": [0.0, 1.0, 0.0], "fov_y": FRAMING_FOV_Y}


def camera_frame(camera: dict):
    """Orthonormal (right, up, back) of a camera {eye, target, up}, as a look-at builds it."""
    forward = _normalize(np.subtract(camera["target"], camera["eye"]))
    right = _normalize(np.cross(forward, camera["up"]))
    up = np.cross(right, forward)
    return right, up, -forward


def camera_node_matrix(camera: dict) -> list:
    """The glTF node matrix (column-major, 16 numbers) placing a camera {eye,
    target, up}: the camera looks down its local -Z with +Y up."""
    right, up, back = camera_frame(camera)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = right, up, back, camera["eye"]
    return [float(v) for v in m.T.reshape(-1)]


def choose_camera(gltf: dict, folder: Path | None = None):
    """The camera both renderers use: the file's first perspective camera met
    walking the scene (vkrt's default), else vkrt's framing camera. Returns
    (camera {eye, target, up, fov_y}, where it came from)."""
    instances, cameras, _ = walk_scene(gltf, folder)
    if cameras:
        index, node, world = cameras[0]
        definition = gltf["cameras"][index]
        eye = world[:3, 3]
        forward = _normalize(world[:3, :3] @ np.array([0.0, 0.0, -1.0]))
        up = _normalize(world[:3, :3] @ np.array([0.0, 1.0, 0.0]))
        if forward is not None and up is not None:
            lower, upper = world_bounds(gltf, instances, folder)
            centre = 0.5 * (lower + upper) if np.all(lower <= upper) else eye + forward
            ahead = max(float(np.dot(centre - eye, forward)), 1e-3)
            camera = {"eye": eye.tolist(), "target": (eye + ahead * forward).tolist(), "up": up.tolist()}
            if definition.get("type") == "orthographic":
                # vkrt (GltfScene.cpp, cameraFrom): a view 2 ymag tall, times the node's Y scale;
                # the width follows the image's aspect.
                scale_y = float(np.linalg.norm(world[:3, :3] @ np.array([0.0, 1.0, 0.0])))
                camera["ortho_height"] = 2.0 * abs(float(definition["orthographic"]["ymag"])) * scale_y
                return camera, f"the file's orthographic camera {index} (node {node})"
            camera["fov_y"] = math.degrees(definition["perspective"]["yfov"])
            return camera, f"the file's camera {index} (node {node})"
    lower, upper = world_bounds(gltf, instances, folder)
    return framing_camera(lower, upper), "vkrt's framing camera (the file has no camera)"


def punctual_lights(gltf: dict, folder: Path | None = None) -> list:
    """The scene's KHR_lights_punctual lights in world space, as vkrt reads them."""
    definitions = gltf.get("extensions", {}).get("KHR_lights_punctual", {}).get("lights", [])
    out = []
    for index, world in walk_scene(gltf, folder)[2]:
        d = definitions[index]
        colour = np.array(d.get("color", (1, 1, 1)), float) * float(d.get("intensity", 1.0))
        direction = _normalize(world[:3, :3] @ np.array([0.0, 0.0, -1.0]))
        light = {"type": d["type"], "position": world[:3, 3].tolist(), "power": colour.tolist(),
                 "direction": direction.tolist() if direction is not None else [0.0, 0.0, -1.0]}
        if d["type"] == "spot":
            spot = d.get("spot", {})
            light["inner"] = float(spot.get("innerConeAngle", 0.0))
            light["outer"] = float(spot.get("outerConeAngle", math.pi / 4))
        out.append(light)
    return out


def has_emission(gltf: dict) -> bool:
    for m in gltf.get("materials", []):
        strength = m.get("extensions", {}).get("KHR_materials_emissive_strength", {}).get("emissiveStrength", 1.0)
        if any(float(c) * strength != 0.0 for c in m.get("emissiveFactor", (0, 0, 0))):
            return True
    return False


def strip_by_design(gltf: dict) -> list:
    """Removes BY_DESIGN extensions from gltf (in place); returns what was
    removed, as notes. Alpha modes stay: both renderers honour them."""
    removed = set()
    for material in gltf.get("materials", []):
        ext = material.get("extensions", {})
        for name in list(ext):
            if name in BY_DESIGN:
                del ext[name]
                removed.add(name)
        if not ext and "extensions" in material:
            del material["extensions"]
    for key in ("extensionsUsed", "extensionsRequired"):
        if key in gltf:
            gltf[key] = [e for e in gltf[key] if e not in BY_DESIGN]
            if not gltf[key]:
                del gltf[key]
    return sorted(removed)


def make_default_material_explicit(gltf: dict) -> bool:
    """Gives primitives without a material an explicit glTF default material
    (in place; base colour 1, metallic 1, roughness 1, as glTF 2.0 says and vkrt
    renders): Blender's importer leaves them without one, which Cycles renders
    as its own grey diffuse surface. Returns whether any primitive had none."""
    bare = [p for m in gltf.get("meshes", []) for p in m.get("primitives", []) if "material" not in p]
    if not bare:
        return False
    materials = gltf.setdefault("materials", [])
    materials.append({"name": "compare_cycles_default"})
    for primitive in bare:
        primitive["material"] = len(materials) - 1
    return True


def add_camera(gltf: dict, camera: dict, aspect: float) -> int:
    """Adds `camera` as a new root node of the default scene (in place);
    returns the new camera's index (for vkrt's --camera)."""
    cameras = gltf.setdefault("cameras", [])
    if "ortho_height" in camera:
        half = camera["ortho_height"] / 2.0
        cameras.append({"type": "orthographic", "name": "compare_cycles",
                        "orthographic": {"xmag": half * aspect, "ymag": half, "znear": 0.0, "zfar": 1e30}})
    else:
        cameras.append({"type": "perspective", "name": "compare_cycles",
                        "perspective": {"yfov": math.radians(camera["fov_y"]), "aspectRatio": aspect,
                                        "znear": 1e-3}})
    nodes = gltf.setdefault("nodes", [])
    nodes.append({"name": "compare_cycles_camera", "camera": len(cameras) - 1,
                  "matrix": camera_node_matrix(camera)})
    scenes = gltf.get("scenes")
    if scenes:
        scenes[gltf.get("scene", 0)].setdefault("nodes", []).append(len(nodes) - 1)
    return len(cameras) - 1


def write_temporary_copy(source: Path, gltf: dict) -> Path:
    """Writes gltf beside source under a unique hidden name (relative URIs keep working)."""
    path = source.parent / f".{source.stem}.compare-cycles-{os.getpid()}-{uuid.uuid4().hex[:8]}.gltf"
    path.write_text(json.dumps(gltf))
    return path


# ----------------------------------------------------------------------------
# Images
# ----------------------------------------------------------------------------


def read_exr(path: Path) -> np.ndarray:
    import OpenEXR
    with OpenEXR.File(str(path), separate_channels=True) as f:
        channels = f.channels()
        names = list(channels)
        pick = []
        for c in "RGB":
            name = c if c in channels else next((n for n in names if n.endswith("." + c) and "variance" not in n), None)
            if name is None:
                raise ValueError(f"{path}: no {c} channel (has {', '.join(names)})")
            pick.append(channels[name].pixels.astype(np.float64))
    return np.stack(pick, axis=-1)


def write_white_exr(path: Path) -> None:
    import OpenEXR
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    with OpenEXR.File(header, {"RGB": np.ones((16, 32, 3), np.float32)}) as f:
        f.write(str(path))


def tonemap(rgb: np.ndarray) -> np.ndarray:
    """The PNGs' operator, the same for both renders: clamp to [0, 1], sRGB curve, 8 bits."""
    x = np.clip(np.nan_to_num(np.asarray(rgb, float)), 0.0, 1.0)
    srgb = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)
    return np.round(srgb * 255.0).astype(np.uint8)


def heat_map(rel: np.ndarray, scale: float = 0.25) -> np.ndarray:
    """Signed relative difference to colour: white 0, red vkrt brighter, blue darker, full at +-scale."""
    t = np.clip(rel / scale, -1.0, 1.0)
    out = np.ones(rel.shape + (3,))
    pos, neg = np.clip(t, 0, 1), np.clip(-t, 0, 1)
    out[..., 1] -= pos + neg
    out[..., 2] -= pos
    out[..., 0] -= neg
    return np.round(np.clip(out, 0, 1) * 255).astype(np.uint8)


def write_png(path: Path, rgb8: np.ndarray) -> None:
    h, w, _ = rgb8.shape
    raw = b"".join(b"\x00" + rgb8[y].tobytes() for y in range(h))

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
                     + chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))


def side_by_side(vkrt_rgb, cycles_rgb, rel) -> np.ndarray:
    h, w = rel.shape
    gap = np.full((h, 4, 3), 64, np.uint8)
    return np.concatenate([tonemap(vkrt_rgb), gap, tonemap(cycles_rgb), gap, heat_map(rel)], axis=1)


# ----------------------------------------------------------------------------
# Running the renderers
# ----------------------------------------------------------------------------


def log(message: str) -> None:
    print(f"compare_cycles: {message}", file=sys.stderr, flush=True)


def find_vkrt(explicit: str | None) -> Path:
    candidate = Path(explicit or os.environ.get("VKRT") or REPO / "build" / "vkrt")
    for attempt in range(6):  # a rebuild may be replacing it
        if candidate.is_file() and os.access(candidate, os.X_OK):
            return candidate
        if attempt < 5:
            log(f"{candidate} is missing; waiting for a rebuild ({attempt + 1}/5)")
            time.sleep(20)
    log(f"error: no vkrt binary at {candidate} (build it, or pass --vkrt / set $VKRT)")
    sys.exit(2)


class Unsupported(Exception):
    """vkrt refuses the file (an extensionsRequired it does not implement)."""


def run_vkrt(vkrt: Path, copy: Path, source: Path, camera_index: int, args, out_exr: Path,
             environment: Path | None) -> dict:
    json_path = out_exr.with_suffix(".json")
    command = [str(vkrt), "render", str(copy), "--camera", str(camera_index), "--spp", str(args.vkrt_spp),
               "--width", str(args.width), "--height", str(args.height), "--seed", str(args.seed),
               "-o", str(out_exr), "--json", str(json_path)]
    if environment is not None:
        command += ["--environment", str(environment)]
    for attempt in range(3):
        started = time.perf_counter()
        done = subprocess.run(command, capture_output=True, text=True)
        seconds = time.perf_counter() - started
        if done.returncode == 0 or vkrt.exists():
            break
        time.sleep(30)  # the binary vanished mid-run: a rebuild
    if done.returncode != 0:
        message = done.stderr.strip().replace(str(copy), source.name).replace(copy.name, source.name)
        if done.returncode == 2 and "vkrt does not implement" in message:
            raise Unsupported(message.splitlines()[-1][:300])
        raise RuntimeError(f"vkrt exited {done.returncode}: {message[-2000:]}")
    facts = json.loads(json_path.read_text()) if json_path.exists() else {}
    warnings = [line.split("warning:", 1)[1].strip() for line in done.stderr.splitlines() if "warning:" in line]
    # Name the model's own file, not the temporary copy, and drop the file prefix.
    warnings = [w.replace(str(copy), copy.name).replace(copy.name, source.name) for w in warnings]
    warnings = [w[len(source.name) + 2:] if w.startswith(source.name + ": ") else w for w in warnings]
    return {"seconds": seconds, "warnings": warnings, "facts": facts}


def run_cycles(copy: Path, camera: dict, lights: list, white_world: bool, args, out_exr: Path) -> dict:
    spec = {"gltf": str(copy), "output": str(out_exr), "width": args.width, "height": args.height,
            "spp": args.cycles_spp, "seed": args.seed, "bounces": CYCLES_BOUNCES, "threads": args.threads,
            "camera": camera, "lights": lights, "white_world": white_world}
    spec_path = out_exr.with_suffix(".spec.json")
    spec_path.write_text(json.dumps(spec))
    started = time.perf_counter()
    done = subprocess.run([sys.executable, str(CYCLES_SCRIPT), str(spec_path)], capture_output=True, text=True)
    seconds = time.perf_counter() - started
    if done.returncode != 0 or not out_exr.exists():
        raise RuntimeError(f"Cycles exited {done.returncode}: {(done.stdout + done.stderr).strip()[-2000:]}")
    facts = {}
    for line in done.stdout.splitlines():
        if line.startswith("CYCLES_RENDER_RESULT "):
            facts = json.loads(line.split(" ", 1)[1])
    return {"seconds": seconds, "facts": facts}


def model_files(directory: Path) -> list[tuple[str, Path]]:
    """(name, .gltf) for every sub-folder holding glTF/*.gltf (else *.gltf), and *.gltf in DIR itself."""
    found = []
    for sub in sorted(p for p in directory.iterdir() if p.is_dir()):
        files = sorted((sub / "glTF").glob("*.gltf")) or sorted(sub.glob("*.gltf"))
        files = [f for f in files if not f.name.startswith(".")]
        if files:
            found.append((sub.name, files[0]))
    for f in sorted(directory.glob("*.gltf")):
        if not f.name.startswith("."):
            found.append((f.stem, f))
    return found


def compare_model(name: str, source: Path, args, vkrt: Path, work: Path) -> dict:
    row = {"model": name, "file": str(source), "notes": []}
    gltf = json.loads(source.read_text())
    folder = source.parent
    if not args.keep_extensions:
        stripped = strip_by_design(gltf)
        if stripped:
            row["notes"].append("stripped for both: " + ", ".join(stripped))
    if make_default_material_explicit(gltf):
        row["notes"].append("glTF's default material made explicit for Blender")
    used = set(gltf.get("extensionsUsed", []))
    exclusions = [why for ext, why in EXCLUDING.items() if ext in used]
    if has_thin_walled_transmission(gltf):
        exclusions.append(THIN_WALLED)
    camera, origin = choose_camera(gltf, folder)
    row["camera"] = dict(camera, origin=origin)
    lights = punctual_lights(gltf, folder)
    if any(light["type"] == "spot" for light in lights):
        exclusions.append("spot light: glTF's cone falloff is not Blender's spot blend")
    if name in args.exclude:
        exclusions.append(args.exclude[name])
    white_world = not lights
    environment = None
    if white_world:
        # vkrt's own default for a file without lights is its grey studio
        # gradient; the comparison lights both renderers alike, white.
        environment = work / "white.exr"
        if not environment.exists():
            write_white_exr(environment)
    camera_index = add_camera(gltf, camera, args.width / args.height)
    copy = write_temporary_copy(source, gltf)
    vkrt_exr, cycles_exr = work / f"{name}.vkrt.exr", work / f"{name}.cycles.exr"
    try:
        row["vkrt"] = run_vkrt(vkrt, copy, source, camera_index, args, vkrt_exr, environment)
        row["cycles"] = run_cycles(copy, camera, lights, white_world, args, cycles_exr)
    finally:
        copy.unlink(missing_ok=True)
    warned = list(dict.fromkeys(row["vkrt"]["warnings"]))
    if warned:
        row["notes"].append(f"vkrt warned ({len(warned)}): " + "; ".join(warned))
    vkrt_rgb, cycles_rgb = read_exr(vkrt_exr), read_exr(cycles_exr)
    row.update(compare_images(vkrt_rgb, cycles_rgb, args.tolerance))
    if exclusions:
        row["verdict"] = "excluded"
        row["notes"].insert(0, "excluded: " + "; ".join(exclusions))
    else:
        row["verdict"] = verdict(row, args.max_mean_diff, args.max_share)
    rel = relative_difference_map(luminance(vkrt_rgb), luminance(cycles_rgb))
    png = args.out / f"{name}.png"
    write_png(png, side_by_side(vkrt_rgb, cycles_rgb, rel))
    row["png"] = str(png)
    if args.keep_exr:
        for src in (vkrt_exr, cycles_exr):
            shutil.copy2(src, args.out / src.name)
    return row


def _short(note: str, limit: int = 160) -> str:
    return note if len(note) <= limit else note[:limit - 1] + "…"


def markdown_table(rows: list, table_path: Path, args) -> str:
    lines = [
        f"vkrt against Cycles: {args.width}x{args.height}, vkrt {args.vkrt_spp} spp, Cycles {args.cycles_spp} spp, "
        f"seed {args.seed}. Pass: |mean rel. diff| < {args.max_mean_diff:.0%} and share of pixels over "
        f"{args.tolerance:.0%} < {args.max_share:.0%} (tools/compare_cycles.py).",
        "",
        "| model | mean rel. diff | share > {:.0%} | verdict | notes | image |".format(args.tolerance),
        "| --- | ---: | ---: | --- | --- | --- |",
    ]
    for r in rows:
        if "error" in r:
            text = r["error"].replace("vkrt: error: ", "").replace(r["file"], Path(r["file"]).name)
            lines.append(f"| {r['model']} | | | {r['verdict']} | {text.splitlines()[0][:200]} | |")
            continue
        link = os.path.relpath(Path(r["png"]).resolve(), table_path.resolve().parent)
        notes = "; ".join(_short(n) for n in r["notes"]).replace("|", "\\|")
        lines.append(f"| {r['model']} | {r['mean_rel_diff']:+.1%} | {r['share_over']:.1%} | {r['verdict']} | "
                     f"{notes} | [png]({link}) |")
    judged = [r for r in rows if r.get("verdict") in ("pass", "fail")]
    lines += ["", f"{sum(r['verdict'] == 'pass' for r in judged)} of {len(judged)} judged models pass; "
              f"{sum(r.get('verdict') == 'excluded' for r in rows)} excluded; "
              f"{sum(r.get('verdict') == 'unsupported' for r in rows)} refused by vkrt; "
              f"{sum(r.get('verdict') == 'error' for r in rows)} errors."]
    return "\n".join(lines) + "\n"


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("files", nargs="*", type=Path, help=".gltf files")
    p.add_argument("--models", type=Path, help="a folder of model folders (each with glTF/*.gltf)")
    p.add_argument("--width", type=int, default=320)
    p.add_argument("--height", type=int, default=240)
    p.add_argument("--spp", type=int, default=256)
    p.add_argument("--vkrt-spp", type=int)
    p.add_argument("--cycles-spp", type=int)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--out", type=Path, default=Path("compare-cycles"))
    p.add_argument("--json", dest="json_out")
    p.add_argument("--table", type=Path)
    p.add_argument("--exclude", action="append", default=[], metavar="NAME=WHY")
    p.add_argument("--only", help="comma-separated model names to run from --models")
    p.add_argument("--keep-extensions", action="store_true")
    p.add_argument("--keep-exr", action="store_true", help="also keep both EXRs in --out")
    p.add_argument("--vkrt")
    p.add_argument("--threads", type=int, default=0)
    p.add_argument("--max-mean-diff", type=float, default=MAX_MEAN_DIFF)
    p.add_argument("--max-share", type=float, default=MAX_SHARE)
    p.add_argument("--tolerance", type=float, default=TOLERANCE)
    args = p.parse_args(argv)
    args.vkrt_spp = args.vkrt_spp or args.spp
    args.cycles_spp = args.cycles_spp or args.spp
    exclude = {}
    for item in args.exclude:
        name, _, why = item.partition("=")
        exclude[name] = why or "excluded on the command line"
    args.exclude = exclude
    if not args.files and not args.models:
        p.error("give .gltf files or --models DIR")
    return args


def summary_of(rows: list, args, vkrt: Path) -> dict:
    return {"settings": {"width": args.width, "height": args.height, "vkrt_spp": args.vkrt_spp,
                            "cycles_spp": args.cycles_spp, "seed": args.seed, "cycles_bounces": CYCLES_BOUNCES,
                            "vkrt_max_depth": VKRT_MAX_DEPTH, "tolerance": args.tolerance,
                            "floor_fraction": FLOOR_FRACTION, "max_mean_diff": args.max_mean_diff,
                            "max_share": args.max_share, "vkrt": str(vkrt)},
               "models": rows}


def write_outputs(rows: list, args, vkrt: Path) -> None:
    """Writes --json (when a file) and --table for the rows so far."""
    if args.json_out and args.json_out != "-":
        Path(args.json_out).write_text(json.dumps(summary_of(rows, args, vkrt), indent=1, default=float) + "\n")
    if args.table:
        args.table.write_text(markdown_table(rows, args.table, args))


def main(argv=None) -> int:
    # SIGTERM runs the finally blocks too, so that no temporary copy is left beside a model.
    import signal
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))
    args = parse_args(sys.argv[1:] if argv is None else argv)
    vkrt = find_vkrt(args.vkrt)
    models = [(f.stem, f.resolve()) for f in args.files]
    if args.models:
        models += [(n, f.resolve()) for n, f in model_files(args.models)]
    if args.only:
        wanted = set(args.only.split(","))
        models = [(n, f) for n, f in models if n in wanted]
    for path in (f for _, f in models):
        if path.suffix.lower() != ".gltf":
            log(f"error: {path}: only .gltf (JSON) files are supported")
            return 2
    args.out.mkdir(parents=True, exist_ok=True)
    rows = []
    with tempfile.TemporaryDirectory(prefix="compare-cycles-") as tmp:
        work = Path(tmp)
        for name, path in models:
            try:
                row = compare_model(name, path, args, vkrt, work)
                print(f"{name:32s} mean {row['mean_rel_diff']:+7.2%}  over {args.tolerance:.0%}: "
                      f"{row['share_over']:6.2%}  {row['verdict']:8s}  (vkrt {row['vkrt']['seconds']:.1f} s, "
                      f"Cycles {row['cycles']['seconds']:.1f} s)  {'; '.join(row['notes'])}", flush=True)
            except Unsupported as error:
                row = {"model": name, "file": str(path), "verdict": "unsupported", "error": str(error)}
                print(f"{name:32s} unsupported by vkrt: {error}", flush=True)
            except Exception as error:  # one model's failure must not stop the others
                row = {"model": name, "file": str(path), "verdict": "error", "error": str(error)}
                print(f"{name:32s} error: {error}", flush=True)
            rows.append(row)
            write_outputs(rows, args, vkrt)  # after each model, so an interrupted run leaves its rows
    write_outputs(rows, args, vkrt)
    if args.json_out == "-":
        print(json.dumps(summary_of(rows, args, vkrt), indent=1, default=float))
    failed = any(r.get("verdict") in ("fail", "error") for r in rows)  # "unsupported" is reported, not failed
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""Convert a vkrt scene (TOML, docs/scene-format.md) to a Mitsuba 3 scene.

    tools/to_mitsuba.py SCENE.toml -o scene.xml     # XML plus a scene_files/ folder
    tools/to_mitsuba.py SCENE.toml --print-dict     # the Python dict, for inspection

As a module (Mitsuba must be importable; a variant is chosen if none is set):

    import to_mitsuba
    scene_dict = to_mitsuba.convert("scene.toml")
    scene = mitsuba.load_dict(scene_dict)

The conversion follows the semantics of vkrt's path integrator
(`[render] integrator = "path"`); see scenes/validation/README.md:

* camera: `perspective`, vertical `fov`, `look_at(eye, target, up)`, `hdrfilm`
  with a one-pixel `box` reconstruction filter (each sample lands in its own
  pixel, as in vkrt);
* `max_depth`: Mitsuba's max_depth = vkrt's max_depth + 1 (vkrt counts surface
  interactions, Mitsuba counts path segments);
* lambert -> `diffuse`; mirror (fresnel = "none") -> `conductor`, material
  "none"; dielectric (exact Fresnel) -> `dielectric` with int_ior = ior and
  ext_ior = 1; absorption κ -> a `homogeneous` interior medium with
  sigma_t = κ and albedo 0, rendered with `volpath`; conductor -> `conductor`
  (roughness 0) or `roughconductor` (ggx, alpha = roughness², visible-normal
  sampling) with RGB eta and k; rough_dielectric -> `roughdielectric`;
  plastic -> `plastic` / `roughplastic` (nonlinear = false). vkrt shades both sides of
  every surface, so diffuse and conductor BSDFs are wrapped in `twosided`;
* point light -> `point` (intensity, W/sr); triangle light -> a one-triangle
  mesh with an `area` emitter and a black diffuse BSDF; a two-sided light is two
  such triangles with opposite windings, the back one displaced by 1e-5 of the
  light's size behind the front one so that each side of the light hits the
  triangle that emits towards it;
* background colour -> `constant`; cubemap -> an equirectangular `envmap`
  resampled from the six faces with Vulkan's seamless bilinear cube lookup;
* sphere -> `sphere`; box -> `cube` with a scale+translate to_world; triangle ->
  a one-triangle PLY mesh; infinite plane -> a large `rectangle` (an
  approximation: see --plane-half-size).
* mesh (OBJ, PLY) -> `obj` / `ply` reading the same file, to_world = the
  object's matrix (or T * R * S); normals = "face", or "file" for a file
  without vertex normals -> face_normals = true (Mitsuba would compute smooth
  normals where vkrt uses face normals); normals = "smooth" -> a PLY written
  with vkrt's area-weighted vertex normals (Mitsuba's own are angle-weighted);
  emission -> an `area` emitter on the mesh, which keeps its material. glTF
  (Mitsuba has no loader) and two-sided emissive meshes are refused.

* textures (`albedo = { texture = "wood.png", scale = [su, sv], linear = false,
  wrap = "repeat" }` for lambert albedo, mirror reflectance, conductor tint,
  plastic diffuse; `roughness = { ..., channel = "r" }` for conductor and
  rough_dielectric) -> `bitmap` textures, bilinear, one `wrap_mode`, `raw`
  for linear data (linear = true, or EXR), `to_uv` for the uv scale. The
  meshes get flip_tex_coords = true (Mitsuba's PLY loader does not flip v by
  default, its OBJ loader does), so that uv (0, 0) is the image's bottom-left
  corner as in vkrt. A colour texture is the scene's own image file. A
  roughness texture becomes a one-channel float EXR of GGX alpha =
  roughness², made from the chosen channel and resampled 7x with vkrt's
  filter (Mitsuba can neither select a channel nor square a texture); it is
  written into the folder next to the XML (<stem>_files/<bsdf>_..._alpha.exr,
  or the temporary folder of --print-dict and convert()). Only meshes with
  texture coordinates on every face corner can carry textured materials.

What has no Mitsuba equivalent (phong, glossy, pbr, anisotropic conductors, Schlick Fresnel, the Whitted
integrator, normal maps, plastic roughness textures, different wrap modes for u and v, textured materials on
spheres, boxes, planes and triangles, whose uvs are vkrt's own) is refused with an error naming the scene
file, table and key.
"""
from __future__ import annotations

import argparse
import atexit
import math
import os
import shutil
import sys
import tempfile
import tomllib
from pathlib import Path

DEFAULT_PLANE_HALF_SIZE = 1e4
ABSORPTION_FLOOR = 1e-7  # see the dielectric case in convert()
MIN_GGX_ALPHA = 1e-4  # shaders/shared/SceneTypes.h: the narrowest GGX lobe vkrt renders
# vkrt's named metals (src/material/Metals.cpp), RGB eta and k; tests/tools/test_to_mitsuba.py checks that the tables agree.
METALS: dict = {
    "none": ([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]),
    "Ag": ([0.1553, 0.1167, 0.1384], [4.8283, 3.1222, 2.1470]),
    "Al": ([1.6575, 0.8804, 0.5212], [9.2239, 6.2695, 4.8370]),
    "Au": ([0.1431, 0.3750, 1.4425], [3.9832, 2.3857, 1.6032]),
    "Cr": ([4.3697, 2.9167, 1.6547], [5.2064, 4.2314, 3.7549]),
    "Cu": ([0.2004, 0.9240, 1.1022], [3.9129, 2.4528, 2.1422]),
    "Hg": ([2.3989, 1.4400, 0.9096], [6.3276, 4.3719, 3.4218]),
    "Ir": ([3.0864, 2.0822, 1.6179], [5.5922, 4.0672, 3.2673]),
    "Li": ([0.2658, 0.1956, 0.2209], [3.5402, 2.3111, 1.6686]),
    "Mo": ([4.4837, 3.5255, 2.7761], [4.1111, 3.4209, 3.1506]),
    "Rh": ([2.5858, 1.8602, 1.5544], [6.7823, 4.7030, 3.9761]),
    "W": ([4.3707, 3.3003, 2.9983], [3.5007, 2.6049, 2.2732]),
}
FACE_KEYS = ("px", "nx", "py", "ny", "pz", "nz")  # Vulkan face order


class ConversionError(Exception):
    """A scene that cannot be converted; the message names file, table and key."""


# ----------------------------------------------------------------------------
# Small helpers
# ----------------------------------------------------------------------------

def _note(message: str) -> None:
    print(f"to_mitsuba: note: {message}", file=sys.stderr)


class _Reader:
    """Type-checked access to the TOML data with error messages in vkrt's style."""

    def __init__(self, path: Path):
        self.path = path

    def fail(self, where: str, message: str):
        raise ConversionError(f"{self.path}: {where}: {message}")

    def table(self, data, where):
        if not isinstance(data, dict):
            self.fail(where, "expected a table")
        return data

    def check_keys(self, data: dict, where: str, allowed):
        for key in data:
            if key not in allowed:
                self.fail(f"{where}.{key}" if where else key,
                          f"unknown key '{key}' (expected one of: {', '.join(allowed)})")

    def number(self, data: dict, key: str, where: str, default=None):
        if key not in data:
            if default is None:
                self.fail(where, f"missing required key '{key}'")
            return float(default)
        v = data[key]
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            self.fail(f"{where}.{key}", f"expected a finite number, got {v!r}")
        return float(v)

    def integer(self, data: dict, key: str, where: str, default=None):
        if key not in data:
            if default is None:
                self.fail(where, f"missing required key '{key}'")
            return int(default)
        v = data[key]
        if isinstance(v, bool) or not isinstance(v, int):
            self.fail(f"{where}.{key}", f"expected an integer, got {v!r}")
        return v

    def string(self, data: dict, key: str, where: str, default=None):
        if key not in data:
            if default is None:
                self.fail(where, f"missing required key '{key}'")
            return default
        v = data[key]
        if not isinstance(v, str):
            self.fail(f"{where}.{key}", f"expected a string, got {v!r}")
        return v

    def boolean(self, data: dict, key: str, where: str, default: bool):
        v = data.get(key, default)
        if not isinstance(v, bool):
            self.fail(f"{where}.{key}", f"expected true or false, got {v!r}")
        return v

    def vector(self, data: dict, key: str, where: str, default=None):
        if key not in data:
            if default is None:
                self.fail(where, f"missing required key '{key}'")
            return [float(x) for x in default]
        return self._vec3(data[key], f"{where}.{key}")

    def _vec3(self, v, where):
        if not isinstance(v, list) or len(v) != 3:
            self.fail(where, f"expected [x, y, z], got {v!r}")
        out = []
        for i, x in enumerate(v):
            if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x):
                self.fail(f"{where}[{i}]", f"expected a finite number, got {x!r}")
            out.append(float(x))
        return out

    def color(self, data: dict, key: str, where: str, default=None, lo=0.0, hi=None):
        if key not in data:
            if default is None:
                self.fail(where, f"missing required key '{key}'")
            c = [float(default)] * 3
        else:
            v = data[key]
            if isinstance(v, (int, float)) and not isinstance(v, bool):
                if not math.isfinite(v):
                    self.fail(f"{where}.{key}", f"expected a finite number, got {v!r}")
                c = [float(v)] * 3
            else:
                c = self._vec3(v, f"{where}.{key}")
        for i, x in enumerate(c):
            if x < lo or (hi is not None and x > hi):
                rng = f"[{lo:g}, {hi:g}]" if hi is not None else f">= {lo:g}"
                self.fail(f"{where}.{key}", f"every channel must be {rng}, got {c}")
        return c

    def triangle(self, data: dict, key: str, where: str):
        if key not in data:
            self.fail(where, f"missing required key '{key}'")
        v = data[key]
        if not isinstance(v, list) or len(v) != 3:
            self.fail(f"{where}.{key}", f"expected three points, got {v!r}")
        return [self._vec3(p, f"{where}.{key}[{i}]") for i, p in enumerate(v)]


def _quote(name: str) -> str:
    bare = name and all(c.isalnum() or c in "_-" for c in name)
    return name if bare else '"' + name.replace('"', '\\"') + '"'


def _sub(a, b):
    return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]


def _cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _norm(a):
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


def _rgb(c):
    return {"type": "rgb", "value": [float(x) for x in c]}


def _mitsuba():
    import mitsuba as mi  # noqa: PLC0415 (deferred so --help works without Mitsuba)

    if mi.variant() is None:
        mi.set_variant("scalar_rgb")
    return mi


# ----------------------------------------------------------------------------
# Cubemap -> equirectangular environment map
# ----------------------------------------------------------------------------

def _face_direction(face, sc, tc):
    """Unnormalised direction of face coordinates sc, tc in [-1, 1] (CubeFaces.h)."""
    import numpy as np

    one = np.ones_like(sc)
    if face == 0:
        return np.stack([one, -tc, -sc], -1)
    if face == 1:
        return np.stack([-one, -tc, sc], -1)
    if face == 2:
        return np.stack([sc, one, tc], -1)
    if face == 3:
        return np.stack([sc, -one, -tc], -1)
    if face == 4:
        return np.stack([sc, -tc, one], -1)
    return np.stack([-sc, -tc, -one], -1)


def _select_face(d):
    """Vulkan cube face selection: face index and s, t in [0, 1] for directions d[..., 3]."""
    import numpy as np

    x, y, z = d[..., 0], d[..., 1], d[..., 2]
    ax, ay, az = np.abs(x), np.abs(y), np.abs(z)
    face = np.where((ax >= ay) & (ax >= az), np.where(x >= 0, 0, 1),
                    np.where(ay >= az, np.where(y >= 0, 2, 3), np.where(z >= 0, 4, 5)))
    ma = np.choose(face, [ax, ax, ay, ay, az, az])
    sc = np.choose(face, [-z, z, x, x, x, -x])
    tc = np.choose(face, [-y, -y, z, -z, -y, -y])
    ma = np.maximum(ma, 1e-300)
    return face, 0.5 * (sc / ma + 1.0), 0.5 * (tc / ma + 1.0)


def _padded_faces(faces):
    """Faces with a one-texel border taken from the adjacent faces (Vulkan's cube
    map edge handling); a border corner is the mean of the three texels that meet
    there. Shape (6, n + 2, n + 2, 3)."""
    import numpy as np

    n = faces.shape[1]
    padded = np.zeros((6, n + 2, n + 2, 3), dtype=np.float64)
    padded[:, 1:-1, 1:-1] = faces
    idx = np.arange(-1, n + 1)
    jj, ii = np.meshgrid(idx, idx, indexing="ij")  # jj: row (t), ii: column (s)
    border = (ii < 0) | (ii >= n) | (jj < 0) | (jj >= n)
    corner = ((ii < 0) | (ii >= n)) & ((jj < 0) | (jj >= n))
    edge = border & ~corner
    for f in range(6):
        sc = 2.0 * (ii[edge] + 0.5) / n - 1.0
        tc = 2.0 * (jj[edge] + 0.5) / n - 1.0
        g, s, t = _select_face(_face_direction(f, sc, tc))
        si = np.clip(np.floor(s * n).astype(int), 0, n - 1)
        ti = np.clip(np.floor(t * n).astype(int), 0, n - 1)
        padded[f][edge] = faces[g, ti, si]
        for cj, ci, dj, di in ((0, 0, 1, 1), (0, n + 1, 1, -1), (n + 1, 0, -1, 1), (n + 1, n + 1, -1, -1)):
            padded[f, cj, ci] = (padded[f, cj + dj, ci + di] + padded[f, cj, ci + di] + padded[f, cj + dj, ci]) / 3.0
    return padded


def cube_lookup(faces, d, padded=None):
    """Bilinear, seamless lookup of the cubemap (6, n, n, 3) in directions d[..., 3],
    as Vulkan's textureLod(samplerCube, d, 0) with linear filtering does.
    `padded` is _padded_faces(faces), when the caller has it already."""
    import numpy as np

    n = faces.shape[1]
    if padded is None:
        padded = _padded_faces(faces)
    face, s, t = _select_face(d)
    x = s * n - 0.5 + 1.0  # padded texel coordinates
    y = t * n - 0.5 + 1.0
    x0 = np.clip(np.floor(x).astype(int), 0, n)
    y0 = np.clip(np.floor(y).astype(int), 0, n)
    ax = (x - x0)[..., None]
    ay = (y - y0)[..., None]
    v00 = padded[face, y0, x0]
    v01 = padded[face, y0, x0 + 1]
    v10 = padded[face, y0 + 1, x0]
    v11 = padded[face, y0 + 1, x0 + 1]
    return (1 - ay) * ((1 - ax) * v00 + ax * v01) + ay * ((1 - ax) * v10 + ax * v11)


def envmap_column_offset(mi) -> float:
    """Where Mitsuba's envmap puts column i: u = (i + offset) / width. Mitsuba
    3.7+ centres columns (offset 0.5); older versions put column i at u = i /
    width. Probed on a tiny map rather than assumed."""
    import numpy as np

    w, h = 8, 5
    data = np.zeros((h, w, 3), dtype=np.float32)
    data[:, 2] = 1.0  # column 2 only
    emitter = mi.load_dict({"type": "envmap", "bitmap": mi.Bitmap(data)})
    for offset in (0.5, 0.0):
        u = (2 + offset) / w
        phi, theta = 2 * math.pi * u, 0.5 * math.pi
        d = [math.sin(phi) * math.sin(theta), math.cos(theta), -math.cos(phi) * math.sin(theta)]
        si = mi.SurfaceInteraction3f()
        si.wi = mi.Vector3f(-d[0], -d[1], -d[2])
        value = np.array(emitter.eval(si)).ravel()
        if abs(float(value[0]) - 1.0) < 1e-4:
            return offset
    raise ConversionError("cannot determine the column convention of this Mitsuba's envmap plugin")


def equirect_from_cubemap(faces, width: int, column_offset: float):
    """Equirectangular image (height = width / 2 + 1) in Mitsuba's envmap layout:
    column i at u = (i + column_offset) / width, row j at v = j / (height - 1)
    (row 0 is the +y pole), direction (sin φ sin θ, cos θ, -cos φ sin θ) with
    φ = 2πu, θ = πv."""
    import numpy as np

    height = width // 2 + 1
    padded = _padded_faces(faces)
    out = np.empty((height, width, 3), dtype=np.float32)
    phi = 2 * np.pi * (np.arange(width) + column_offset) / width
    rows = max(1, (1 << 20) // width)  # bounded memory: about a million texels at a time
    for j0 in range(0, height, rows):
        theta = np.pi * np.arange(j0, min(height, j0 + rows))[:, None] / (height - 1)
        d = np.stack(np.broadcast_arrays(np.sin(phi) * np.sin(theta), np.cos(theta) + 0 * phi,
                                         -np.cos(phi) * np.sin(theta)), -1)
        out[j0:j0 + d.shape[0]] = cube_lookup(faces, d, padded)
    return out


def load_cubemap_faces(reader: _Reader, paths):
    """The six faces as float64 (6, n, n, 3) linear RGB, checked as vkrt checks them."""
    import numpy as np

    mi = _mitsuba()
    faces = []
    for key, path in zip(FACE_KEYS, paths):
        where = f"background.cubemap.{key}"
        try:
            bmp = mi.Bitmap(str(path))
        except Exception as e:  # noqa: BLE001 (Mitsuba raises RuntimeError and friends)
            reader.fail(where, f"cannot read '{path}': {e}")
        # PNG is sRGB-encoded; convert() with srgb_gamma=False linearises it.
        bmp = bmp.convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, False)
        a = np.array(bmp, dtype=np.float64).reshape(bmp.height(), bmp.width(), 3)
        if a.shape[0] != a.shape[1] or a.shape[0] == 0:
            reader.fail(where, f"{path}: a cube face must be square, got {a.shape[1]}x{a.shape[0]}")
        if faces and a.shape != faces[0].shape:
            reader.fail(where, f"{path}: all faces must have the same size ({faces[0].shape[0]} for px), "
                               f"got {a.shape[0]}")
        if not np.all(np.isfinite(a)) or np.any(a < 0):
            reader.fail(where, f"{path}: contains a negative or non-finite value")
        faces.append(a)
    return np.stack(faces)


# ----------------------------------------------------------------------------
# Geometry files
# ----------------------------------------------------------------------------

def _write_ply(path: Path, vertices):
    with open(path, "w", encoding="ascii") as f:
        f.write("ply\nformat ascii 1.0\ncomment written by vkrt tools/to_mitsuba.py\n")
        f.write(f"element vertex {len(vertices)}\nproperty float x\nproperty float y\nproperty float z\n")
        f.write(f"element face {len(vertices) // 3}\nproperty list uchar int vertex_indices\nend_header\n")
        for v in vertices:
            f.write(f"{v[0]!r} {v[1]!r} {v[2]!r}\n")
        for i in range(0, len(vertices), 3):
            f.write(f"3 {i} {i + 1} {i + 2}\n")


def _matrix_transform(mi, m):
    return mi.ScalarTransform4f(mi.ScalarMatrix4f(m))


# ----------------------------------------------------------------------------
# Textures (a parameter given as { texture = "file.png", ... })
# ----------------------------------------------------------------------------

TEXTURE_WRAPS = ("repeat", "clamp", "mirror")
TEXTURE_CHANNELS = ("r", "g", "b", "a")
COLOR_TEXTURE_KEYS = ["texture", "scale", "linear", "wrap"]
SCALAR_TEXTURE_KEYS = COLOR_TEXTURE_KEYS + ["channel"]
TEXTURE_EXTENSIONS = (".png", ".jpg", ".jpeg", ".exr")


class _Texture:
    """A texture table of the scene: the texel is the parameter's value. It
    stands in the scene dict until convert() has Mitsuba and turns it into a
    `bitmap` (_bitmap_texture). `alpha`: the texel is a GGX roughness, whose
    alpha = roughness² Mitsuba needs as a one-channel image."""

    def __init__(self, file: Path, scale, linear: bool, wrap: str, channel: int, where: str, alpha: bool):
        self.file = file  # where: "scene.toml: materials.x.key"
        self.scale = scale
        self.linear = linear
        self.wrap = wrap
        self.channel = channel
        self.where = where
        self.alpha = alpha

    @property
    def is_linear(self) -> bool:
        """vkrt decodes PNG and JPEG as sRGB unless linear = true; EXR is linear."""
        return self.linear or self.file.suffix.lower() == ".exr"


def is_texture_table(data: dict, key: str) -> bool:
    return isinstance(data.get(key), dict)


def _read_wrap(r: _Reader, value, where: str) -> str:
    """`wrap`: a mode, or [u, v] modes; Mitsuba's bitmap has one mode for both axes."""
    modes = value if isinstance(value, list) else [value]
    if len(modes) not in (1, 2) or not all(isinstance(m, str) for m in modes):
        r.fail(where, f"expected a wrap mode or a pair [u, v] of them, got {value!r}")
    for i, m in enumerate(modes):
        if m not in TEXTURE_WRAPS:
            r.fail(where if len(modes) == 1 else f"{where}[{i}]",
                   f"unknown wrap mode '{m}' (expected one of: {', '.join(TEXTURE_WRAPS)})")
    if len(set(modes)) != 1:
        r.fail(where, f"wrap = {value!r} has no Mitsuba equivalent: Mitsuba's bitmap texture has one "
                      "wrap_mode for both axes (use the same mode for u and v)")
    return modes[0]


def _read_uv_scale(r: _Reader, value, where: str):
    """`scale`: one number or [su, sv], finite and non-zero (negative mirrors)."""
    items = value if isinstance(value, list) else [value, value]
    if len(items) != 2:
        r.fail(where, f"expected a number or a pair [su, sv], got {value!r}")
    for x in items:
        if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x) or x == 0:
            r.fail(where, f"expected finite, non-zero numbers, got {value!r}")
    return [float(items[0]), float(items[1])]


def read_texture(r: _Reader, data: dict, key: str, where: str, scene_dir: Path, *, scalar: bool,
                 alpha: bool = False) -> _Texture:
    """The texture table data[key] (docs/scene-format.md, "Textures"), checked
    as vkrt checks it: `channel` only for scalar parameters."""
    tw = f"{where}.{key}"
    t = data[key]
    r.check_keys(t, tw, SCALAR_TEXTURE_KEYS if scalar else COLOR_TEXTURE_KEYS)
    file = Path(r.string(t, "texture", tw))
    if not file.is_absolute():
        file = scene_dir / file
    if file.suffix.lower() not in TEXTURE_EXTENSIONS:
        r.fail(f"{tw}.texture", f"'{file}': expected a .png, .jpg, .jpeg or .exr file")
    if not file.is_file():
        r.fail(f"{tw}.texture", f"'{file}' does not exist or is not a regular file")
    scale = _read_uv_scale(r, t["scale"], f"{tw}.scale") if "scale" in t else [1.0, 1.0]
    wrap = _read_wrap(r, t["wrap"], f"{tw}.wrap") if "wrap" in t else "repeat"
    channel = r.string(t, "channel", tw, "r")
    if channel not in TEXTURE_CHANNELS:
        r.fail(f"{tw}.channel", f"unknown channel '{channel}' (expected one of: {', '.join(TEXTURE_CHANNELS)})")
    return _Texture(file, scale, r.boolean(t, "linear", tw, False), wrap, TEXTURE_CHANNELS.index(channel),
                    f"{r.path}: {tw}", alpha)


def uv_transform_matrix(scale):
    """Mitsuba's bitmap `to_uv` (3 x 3) for vkrt's uv scale [su, sv], on meshes
    loaded with flip_tex_coords = true (Mitsuba's uv = (u, 1 - v) of the
    file's (u, v); its bitmap puts uv.y = 0 at the image's top row). vkrt
    reads the image at (su u, sv v) with v up from the bottom row, i.e. at
    Mitsuba image coordinates (su u, 1 - sv v) = (su u', (1 - sv) + sv v') for
    u' = u, v' = 1 - v."""
    su, sv = scale
    return [[su, 0.0, 0.0], [0.0, sv, 1.0 - sv], [0.0, 0.0, 1.0]]


ALPHA_UPSAMPLING = 7  # odd: see _alpha_texture_file
ALPHA_MAX_SIDE = 2048


def wrap_texel_index(i, n: int, wrap: str):
    """Texel index i (numpy ints) of a side of n texels after vkrt's wrap mode
    (shaders/lib/texture.glsl: repeat has period n, mirror period 2n with the
    edge texels doubled, clamp continues the edge texel)."""
    import numpy as np

    if wrap == "repeat":
        return np.mod(i, n)
    if wrap == "mirror":
        j = np.mod(i, 2 * n)
        return np.where(j < n, j, 2 * n - 1 - j)
    return np.clip(i, 0, n - 1)


def upsample_bilinear(image, factor: int, wrap: str):
    """vkrt's bilinear lookup of `image` (h x w, row 0 at the top) at the texel
    centres of an image `factor` times larger on each side, which spans the
    same uv square: fine texel j of side k n has its centre at coarse texel
    coordinate (j + 0.5) / k - 0.5."""
    import numpy as np

    for axis in (0, 1):
        n = image.shape[axis]
        x = (np.arange(factor * n) + 0.5) / factor - 0.5
        i0 = np.floor(x).astype(np.int64)
        f = (x - i0).reshape((-1, 1) if axis == 0 else (1, -1))
        lo = np.take(image, wrap_texel_index(i0, n, wrap), axis)
        hi = np.take(image, wrap_texel_index(i0 + 1, n, wrap), axis)
        image = lo * (1 - f) + hi * f
    return image


def _alpha_texture_file(mi, tex: _Texture, out: Path) -> int:
    """Write a one-channel float EXR of GGX alpha = max(roughness², MIN_GGX_ALPHA)
    for the chosen channel (Mitsuba's bitmap cannot select a channel, and its
    alpha is not the roughness); return the upsampling factor. The texel is
    decoded as vkrt decodes it: sRGB colour channels linearised unless linear,
    the alpha channel as stored.

    vkrt interpolates the roughness and squares it, Mitsuba interpolates alpha:
    at texel resolution the two differ between texel centres by up to
    (Δr)²/4 for neighbouring roughnesses r and r + Δr. The image is therefore
    first resampled with vkrt's bilinear filter and wrap mode to k = 7 times
    its size (less where a side would exceed 2048), which cuts that bound to
    about (Δr)²/(4 k²): the squares are exact at the fine texel centres, and k
    is odd so that every coarse texel centre (where vkrt's interpolated
    roughness has a kink) is a fine one."""
    import numpy as np

    try:
        bmp = mi.Bitmap(str(tex.file))
    except Exception as e:  # noqa: BLE001 (Mitsuba raises RuntimeError and friends)
        raise ConversionError(f"{tex.where}.texture: cannot read '{tex.file}': {e}") from e
    if tex.is_linear:
        bmp.set_srgb_gamma(False)  # the stored values are the texels
    rgba = bmp.convert(mi.Bitmap.PixelFormat.RGBA, mi.Struct.Type.Float32, False)
    texel = np.array(rgba, dtype=np.float64).reshape(rgba.height(), rgba.width(), 4)[..., tex.channel]
    factor = max(1, min(ALPHA_UPSAMPLING, ALPHA_MAX_SIDE // max(texel.shape)))
    factor -= 1 - factor % 2  # odd
    roughness = upsample_bilinear(texel, factor, tex.wrap)
    alpha = np.maximum(roughness * roughness, MIN_GGX_ALPHA).astype(np.float32)
    mi.Bitmap(alpha[..., None], mi.Bitmap.PixelFormat.Y).write(str(out))
    return factor


def _bitmap_texture(mi, tex: _Texture, files_dir: Path, name: str) -> dict:
    """The `bitmap` texture for `tex`: the scene's own image for a colour, a
    one-channel alpha EXR written to files_dir/<name>.exr for a roughness."""
    if tex.alpha:
        file = files_dir / f"{name}.exr"
        factor = _alpha_texture_file(mi, tex, file)
        _note(f"{tex.where}: roughness texture written as GGX alpha = roughness² to {file} "
              f"({factor}x the resolution of {tex.file.name}, resampled bilinearly as vkrt filters it)")
        raw = True
    else:
        file, raw = tex.file, tex.is_linear
    bitmap = {"type": "bitmap", "filename": str(Path(file).resolve()), "raw": raw, "filter_type": "bilinear",
              "wrap_mode": tex.wrap}
    if tex.scale != [1.0, 1.0]:
        bitmap["to_uv"] = mi.ScalarTransform3f(mi.ScalarMatrix3f(uv_transform_matrix(tex.scale)))
    return bitmap


def _resolve_textures(mi, value, files_dir: Path, name: str):
    """`value` with every _Texture in it replaced by its bitmap dict (names from the path of keys)."""
    if isinstance(value, _Texture):
        return _bitmap_texture(mi, value, files_dir, name)
    if isinstance(value, dict):
        return {k: _resolve_textures(mi, v, files_dir, f"{name}_{k}") for k, v in value.items()}
    return value


# ----------------------------------------------------------------------------
# Mesh files (shape = "mesh")
# ----------------------------------------------------------------------------

MESH_KEYS = ["shape", "material", "file", "scale", "rotate", "translate", "matrix", "normals", "emission",
             "two_sided"]
NORMAL_MODES = ("file", "smooth", "face")
MESH_EXTENSIONS = (".obj", ".ply", ".gltf", ".glb")


class _MeshFileError(Exception):
    """A mesh file this converter cannot read; the caller adds the scene context."""


class _MeshFile:
    """What the converter needs of a mesh file: object-space positions (float64,
    N x 3), triangles (M x 3 vertex indices, polygons fanned from their first
    corner as Mitsuba's and assimp's loaders do), whether the file gives
    every triangle corner a vertex normal, and the texture coordinates if
    every corner has one: `uvs` (K x 2, the file's values) and `corner_uvs`
    (M x 3 indices into `uvs`), else both None."""

    def __init__(self, positions, triangles, has_normals: bool, uvs=None, corner_uvs=None):
        self.positions = positions
        self.triangles = triangles
        self.has_normals = has_normals
        self.uvs = uvs
        self.corner_uvs = corner_uvs

    @property
    def has_uvs(self) -> bool:
        return self.uvs is not None


def _fan(polygon):
    return [(polygon[0], polygon[k], polygon[k + 1]) for k in range(1, len(polygon) - 1)]


def _read_obj(path: Path) -> _MeshFile:
    import numpy as np

    positions, triangles, uvs, corner_uvs = [], [], [], []
    corners = with_normal = with_uv = 0
    with open(path, encoding="utf-8", errors="replace") as f:
        for line_no, line in enumerate(f, 1):
            parts = line.split()
            if not parts:
                continue
            if parts[0] == "v":
                try:
                    positions.append([float(x) for x in parts[1:4]])
                except ValueError as e:
                    raise _MeshFileError(f"{path}:{line_no}: bad vertex: {e}") from e
                if len(positions[-1]) != 3:
                    raise _MeshFileError(f"{path}:{line_no}: a vertex needs three coordinates")
            elif parts[0] == "vt":
                try:
                    uvs.append([float(x) for x in parts[1:3]])
                except ValueError as e:
                    raise _MeshFileError(f"{path}:{line_no}: bad texture coordinate: {e}") from e
                if len(uvs[-1]) != 2:
                    raise _MeshFileError(f"{path}:{line_no}: a texture coordinate needs u and v")
            elif parts[0] == "f":
                polygon, polygon_uvs = [], []
                for corner in parts[1:]:
                    fields = corner.split("/")
                    try:
                        index = int(fields[0])
                        uv = int(fields[1]) if len(fields) >= 2 and fields[1] != "" else None
                    except ValueError as e:
                        raise _MeshFileError(f"{path}:{line_no}: bad face corner '{corner}'") from e
                    index = index - 1 if index > 0 else len(positions) + index
                    if not 0 <= index < len(positions):
                        raise _MeshFileError(f"{path}:{line_no}: vertex index {fields[0]} out of range")
                    if uv is not None:
                        uv = uv - 1 if uv > 0 else len(uvs) + uv
                        if not 0 <= uv < len(uvs):
                            raise _MeshFileError(f"{path}:{line_no}: texture coordinate index {fields[1]} "
                                                 "out of range")
                        with_uv += 1
                    polygon.append(index)
                    polygon_uvs.append(uv if uv is not None else -1)
                    corners += 1
                    with_normal += len(fields) >= 3 and fields[2] != ""
                triangles += _fan(polygon)
                corner_uvs += _fan(polygon_uvs)
    if with_normal not in (0, corners):
        # assimp and Mitsuba fill the missing normals differently.
        raise _MeshFileError(f"{path}: only {with_normal} of {corners} face corners have a normal index "
                             "(give all or none normals)")
    # vkrt takes uvs only when every corner has one (MeshLoader.cpp); so do we.
    all_uvs = corners > 0 and with_uv == corners
    return _MeshFile(np.array(positions, float).reshape(-1, 3), np.array(triangles, np.int64).reshape(-1, 3),
                     corners > 0 and with_normal == corners,
                     np.array(uvs, float).reshape(-1, 2) if all_uvs else None,
                     np.array(corner_uvs, np.int64).reshape(-1, 3) if all_uvs else None)


# vkrt's PlyReader.cpp: the first of these names present is u (resp. v).
_PLY_U_NAMES = ("u", "s", "texture_u", "texture_s")
_PLY_V_NAMES = ("v", "t", "texture_v", "texture_t")


_PLY_TYPES = {"char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2", "int16": "i2",
              "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
              "float": "f4", "float32": "f4", "double": "f8", "float64": "f8"}


def _read_ply_header(f, path: Path):
    if f.readline().strip() != b"ply":
        raise _MeshFileError(f"{path}: not a PLY file (no 'ply' magic)")
    fmt, elements = None, []
    while True:
        line = f.readline()
        if not line:
            raise _MeshFileError(f"{path}: PLY header has no end_header")
        parts = line.decode("ascii", "replace").split()
        if not parts or parts[0] in ("comment", "obj_info"):
            continue
        if parts[0] == "end_header":
            return fmt, elements
        if parts[0] == "format":
            fmt = parts[1]
        elif parts[0] == "element":
            elements.append((parts[1], int(parts[2]), []))
        elif parts[0] == "property" and elements:
            if parts[1] == "list":
                elements[-1][2].append((parts[4], _PLY_TYPES[parts[2]], _PLY_TYPES[parts[3]]))
            else:
                elements[-1][2].append((parts[2], None, _PLY_TYPES[parts[1]]))


def _read_ply(path: Path) -> _MeshFile:
    """ASCII and binary PLY (either byte order): vertex x, y, z (nx, ny, nz) and
    face vertex_indices (or vertex_index) lists."""
    import numpy as np

    with open(path, "rb") as f:
        try:
            fmt, elements = _read_ply_header(f, path)
        except (KeyError, IndexError, ValueError) as e:
            raise _MeshFileError(f"{path}: bad PLY header ({e})") from e
        if fmt not in ("ascii", "binary_little_endian", "binary_big_endian"):
            raise _MeshFileError(f"{path}: unknown PLY format '{fmt}'")
        body = f.read()
    order = "<" if fmt == "binary_little_endian" else ">"
    tokens = body.split() if fmt == "ascii" else None
    pos = 0
    data = {}
    for name, count, props in elements:
        scalar_only = all(lt is None for _, lt, _ in props)
        if tokens is not None:
            rows = []
            for _ in range(count):
                row = {}
                for pname, lt, vt in props:
                    if lt is None:
                        row[pname] = float(tokens[pos])
                        pos += 1
                    else:
                        n = int(tokens[pos])
                        row[pname] = [int(t) for t in tokens[pos + 1:pos + 1 + n]]
                        pos += 1 + n
                rows.append(row)
            data[name] = rows
        elif scalar_only:
            dtype = np.dtype([(p, order + vt) for p, _, vt in props])
            data[name] = np.frombuffer(body, dtype, count, pos)
            pos += dtype.itemsize * count
        else:
            data[name] = rows = []
            for _ in range(count):
                row = {}
                for pname, lt, vt in props:
                    if lt is None:
                        row[pname] = np.frombuffer(body, order + vt, 1, pos)[0]
                        pos += np.dtype(vt).itemsize
                    else:
                        n = int(np.frombuffer(body, order + lt, 1, pos)[0])
                        pos += np.dtype(lt).itemsize
                        row[pname] = np.frombuffer(body, order + vt, n, pos).tolist()
                        pos += np.dtype(vt).itemsize * n
                rows.append(row)
    vertices = data.get("vertex")
    if vertices is None or len(vertices) == 0:
        raise _MeshFileError(f"{path}: no vertex element")
    if isinstance(vertices, list):
        positions = np.array([[v["x"], v["y"], v["z"]] for v in vertices], float)
    else:
        positions = np.stack([vertices[k].astype(float) for k in "xyz"], -1)
    vertex_props = [p for p, _, _ in next(e for e in elements if e[0] == "vertex")[2]]
    triangles = []
    for face in data.get("face", []):
        polygon = face.get("vertex_indices", face.get("vertex_index"))
        if polygon is None:
            raise _MeshFileError(f"{path}: face element without vertex_indices")
        triangles += _fan(list(polygon))
    triangles = np.array(triangles, np.int64).reshape(-1, 3)
    if triangles.size and (triangles.min() < 0 or triangles.max() >= len(positions)):
        raise _MeshFileError(f"{path}: vertex index out of range")
    u_name = next((k for k in _PLY_U_NAMES if k in vertex_props), None)
    v_name = next((k for k in _PLY_V_NAMES if k in vertex_props), None)
    uvs = None
    if u_name and v_name:
        if isinstance(vertices, list):
            uvs = np.array([[v[u_name], v[v_name]] for v in vertices], float)
        else:
            uvs = np.stack([vertices[u_name].astype(float), vertices[v_name].astype(float)], -1)
    return _MeshFile(positions, triangles, all(k in vertex_props for k in ("nx", "ny", "nz")),
                     uvs, triangles if uvs is not None else None)


def read_mesh_file(path: Path) -> _MeshFile:
    """The geometry of an OBJ or PLY file (glTF is not read: see convert())."""
    try:
        mesh = _read_obj(path) if path.suffix.lower() == ".obj" else _read_ply(path)
    except (OSError, ValueError, IndexError, KeyError) as e:
        raise _MeshFileError(f"{path}: cannot read: {e}") from e
    if len(mesh.triangles) == 0:
        raise _MeshFileError(f"{path}: no triangles")
    import numpy as np

    if not np.all(np.isfinite(mesh.positions)):
        raise _MeshFileError(f"{path}: a vertex coordinate is NaN or infinite")
    return mesh


def area_weighted_normals(positions, triangles):
    """vkrt's normals = "smooth" (computeSmoothNormals in MeshData.h): each vertex
    gets the normalised sum of its triangles' cross(v1 - v0, v2 - v0), i.e. of
    their unit normals weighted by area. Vertices are shared by index only.
    A vertex whose triangles are all degenerate gets (0, 0, 0).
    (Mitsuba's own recomputed normals weight by corner angle instead.)"""
    import numpy as np

    p = positions[triangles]
    face = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    normals = np.zeros_like(positions)
    for corner in range(3):
        np.add.at(normals, triangles[:, corner], face)
    length = np.linalg.norm(normals, axis=1, keepdims=True)
    return np.where(length > 0, normals / np.maximum(length, 1e-300), 0.0)


def write_ply_with_normals(path: Path, positions, normals, triangles, uvs=None, corner_uvs=None) -> None:
    """Binary little-endian PLY with float32 positions and vertex normals, and
    texture coordinates u, v (the file's values, unflipped) when `uvs` and
    `corner_uvs` are given: a vertex is then split wherever its corners have
    different uvs (a uv seam), each copy keeping the vertex's normal."""
    import numpy as np

    props = ["x", "y", "z", "nx", "ny", "nz"]
    columns = [positions, normals]
    if uvs is not None:
        pairs = np.stack([triangles.ravel(), corner_uvs.ravel()], -1)
        unique, inverse = np.unique(pairs, axis=0, return_inverse=True)
        columns = [positions[unique[:, 0]], normals[unique[:, 0]], uvs[unique[:, 1]]]
        triangles = inverse.reshape(-1, 3)
        props += ["u", "v"]
    vertex = np.concatenate(columns, 1).astype("<f4")
    header = ("ply\nformat binary_little_endian 1.0\ncomment written by vkrt tools/to_mitsuba.py\n"
              f"element vertex {len(vertex)}\n"
              + "".join(f"property float {k}\n" for k in props)
              + f"element face {len(triangles)}\nproperty list uchar int vertex_indices\nend_header\n")
    faces = np.zeros(len(triangles), dtype=[("n", "u1"), ("i", "<i4", 3)])
    faces["n"] = 3
    faces["i"] = triangles
    with open(path, "wb") as f:
        f.write(header.encode("ascii"))
        f.write(vertex.tobytes())
        f.write(faces.tobytes())


def _rotation_matrix(axis, degrees):
    """Right-handed rotation by `degrees` about `axis` (Rodrigues' formula)."""
    n = _norm(axis)
    x, y, z = (a / n for a in axis)
    c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
    k = 1 - c
    return [[c + x * x * k, x * y * k - z * s, x * z * k + y * s],
            [y * x * k + z * s, c + y * y * k, y * z * k - x * s],
            [z * x * k - y * s, z * y * k + x * s, c + z * z * k]]


def _matmul4(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(4)) for j in range(4)] for i in range(4)]


def _det3(m):
    return (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))


def mesh_transform(r: _Reader, o: dict, where: str):
    """The object's 4 x 4 object-to-world matrix: `matrix`, or T * R * S."""
    if "matrix" in o:
        for key in ("scale", "rotate", "translate"):
            if key in o:
                r.fail(f"{where}.{key}", "cannot be combined with matrix (matrix gives the whole transform)")
        rows = o["matrix"]
        if not isinstance(rows, list) or len(rows) != 4:
            r.fail(f"{where}.matrix", f"expected 4 rows of 4 numbers, got {rows!r}")
        m = []
        for i, row in enumerate(rows):
            if not isinstance(row, list) or len(row) != 4:
                r.fail(f"{where}.matrix[{i}]", f"expected a row of 4 numbers, got {row!r}")
            for j, x in enumerate(row):
                if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x):
                    r.fail(f"{where}.matrix[{i}][{j}]", f"expected a finite number, got {x!r}")
            m.append([float(x) for x in row])
        if m[3] != [0.0, 0.0, 0.0, 1.0]:
            r.fail(f"{where}.matrix[3]", f"the last row must be [0, 0, 0, 1] (an affine transform), got {m[3]}")
        if _det3(m) == 0:
            r.fail(f"{where}.matrix", "is singular (it flattens the mesh)")
        return m
    s = [1.0, 1.0, 1.0]
    if "scale" in o:
        v = o["scale"]
        uniform = isinstance(v, (int, float)) and not isinstance(v, bool)
        s = [r.number(o, "scale", where)] * 3 if uniform else r.vector(o, "scale", where)
        if any(x == 0 for x in s):
            r.fail(f"{where}.scale", f"every component must be non-zero, got {s}")
    rot = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    if "rotate" in o:
        rw = f"{where}.rotate"
        rt = r.table(o["rotate"], rw)
        r.check_keys(rt, rw, ["axis", "angle"])
        axis = r.vector(rt, "axis", rw)
        if _norm(axis) == 0:
            r.fail(f"{rw}.axis", "must be non-zero")
        rot = _rotation_matrix(axis, r.number(rt, "angle", rw))
    t = r.vector(o, "translate", where, [0, 0, 0])
    return [[rot[i][j] * s[j] for j in range(3)] + [t[i]] for i in range(3)] + [[0.0, 0.0, 0.0, 1.0]]


# ----------------------------------------------------------------------------
# Conversion
# ----------------------------------------------------------------------------

def convert(path, *, files_dir=None, plane_half_size: float = DEFAULT_PLANE_HALF_SIZE,
            envmap_width: int | None = None, allow_whitted: bool = False, spp: int = 64) -> dict:
    """Convert the vkrt scene at `path` to a Mitsuba 3 scene dict.

    Triangles are written as PLY files and a cubemap as an equirectangular EXR
    into `files_dir` (a temporary folder removed at exit when None); the dict
    refers to them by absolute path.
    """
    path = Path(path)
    r = _Reader(path)
    try:
        with open(path, "rb") as f:
            data = tomllib.load(f)
    except OSError as e:
        raise ConversionError(f"cannot read scene file '{path}': {e.strerror}") from e
    except tomllib.TOMLDecodeError as e:
        raise ConversionError(f"{path}: invalid TOML: {e}") from e

    r.check_keys(data, "", ["render", "camera", "materials", "objects", "lights", "background"])

    # [render]
    render = r.table(data.get("render", {}), "render")
    r.check_keys(render, "render", ["integrator", "max_depth"])
    integrator = r.string(render, "integrator", "render", "whitted")
    if integrator not in ("whitted", "path"):
        r.fail("render.integrator", f"unknown integrator '{integrator}' (expected whitted or path)")
    if integrator == "whitted" and not allow_whitted:
        r.fail("render.integrator" if "integrator" in render else "render",
               "the Whitted integrator has no Mitsuba equivalent; set integrator = \"path\" "
               "(or pass --allow-whitted to convert the scene as if it were a path-traced one)")
    max_depth = r.integer(render, "max_depth", "render", 5)
    if not 1 <= max_depth <= 64:
        r.fail("render.max_depth", f"must be in [1, 64], got {max_depth}")

    # [camera]
    if "camera" not in data:
        r.fail("camera", "missing required table")
    cam = r.table(data["camera"], "camera")
    r.check_keys(cam, "camera", ["eye", "target", "up", "fov", "width", "height"])
    eye = r.vector(cam, "eye", "camera")
    target = r.vector(cam, "target", "camera")
    up = r.vector(cam, "up", "camera", [0, 1, 0])
    fov = r.number(cam, "fov", "camera")
    width = r.integer(cam, "width", "camera", 640)
    height = r.integer(cam, "height", "camera", 480)
    if not 0 < fov < 180:
        r.fail("camera.fov", f"must be strictly between 0 and 180, got {fov:g}")
    forward = _sub(target, eye)
    if _norm(forward) == 0:
        r.fail("camera.target", "must differ from eye")
    if _norm(_cross(forward, up)) < 1e-6 * _norm(forward) * _norm(up):
        r.fail("camera.up", "must not be parallel to target - eye")

    # [materials]
    materials = r.table(data.get("materials", {}), "materials")
    for name, m in materials.items():
        where = f"materials.{_quote(name)}"
        r.table(m, where)
        r.string(m, "type", where)

    # Objects first, so that only materials in use must be convertible.
    objects = data.get("objects", [])
    if not isinstance(objects, list):
        r.fail("objects", "expected an array of tables")
    used = {}
    for i, o in enumerate(objects):
        where = f"objects[{i}]"
        r.table(o, where)
        name = r.string(o, "material", where)
        if name not in materials:
            r.fail(f"{where}.material", f"unknown material '{name}'")
        used.setdefault(name, where)

    scene: dict = {"type": "scene"}
    bsdf_ids: dict[str, str] = {}
    media_ids: dict[str, str] = {}
    textured: dict[str, list[str]] = {}  # material -> its keys given as textures
    needs_volpath = False

    def color_param(m, key, where, default, name):
        """An rgb value, or a _Texture for a texture table (its texel replaces the constant)."""
        if is_texture_table(m, key):
            textured.setdefault(name, []).append(key)
            return read_texture(r, m, key, where, path.parent, scalar=False)
        return _rgb(r.color(m, key, where, default, 0.0, 1.0))

    def roughness_param(m, where, default, name):
        """The roughness as a number, or a _Texture whose texel is the roughness."""
        if is_texture_table(m, "roughness"):
            textured.setdefault(name, []).append("roughness")
            return read_texture(r, m, "roughness", where, path.parent, scalar=True, alpha=True)
        return r.number(m, "roughness", where, default)

    def ggx(roughness):
        """Mitsuba's microfacet keys for a roughness (number or texture) > 0."""
        alpha = roughness if isinstance(roughness, _Texture) else max(roughness * roughness, MIN_GGX_ALPHA)
        return {"distribution": "ggx", "sample_visible": True, "alpha": alpha}

    def is_rough(roughness):
        return isinstance(roughness, _Texture) or roughness > 0
    for index, (name, m) in enumerate(materials.items()):
        where = f"materials.{_quote(name)}"
        mtype = m["type"]
        if name not in used:
            _note(f"{path}: {where}: not used by any object; skipped")
            continue
        bsdf_id = f"mat{index}"
        if "normal_map" in m:
            r.fail(f"{where}.normal_map", "normal maps are not converted: Mitsuba's normalmap BSDF builds its "
                                          "tangent frame from each triangle's dp/du, vkrt from its own vertex "
                                          "tangents, and the two treat shading normals that face away from "
                                          "the light differently (remove normal_map for a Mitsuba reference)")
        if mtype == "lambert":
            r.check_keys(m, where, ["type", "albedo"])
            albedo = color_param(m, "albedo", where, 0.8, name)
            bsdf = {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": albedo}}
        elif mtype == "mirror":
            r.check_keys(m, where, ["type", "reflectance", "fresnel", "ior"])
            fresnel = r.string(m, "fresnel", where, "none")
            if fresnel != "none":
                r.fail(f"{where}.fresnel", f"mirror with fresnel = \"{fresnel}\" has no Mitsuba equivalent "
                                           "(only fresnel = \"none\" converts, to a conductor with material = \"none\")")
            refl = color_param(m, "reflectance", where, 1.0, name)
            bsdf = {"type": "twosided", "bsdf": {"type": "conductor", "material": "none",
                                                 "specular_reflectance": refl}}
        elif mtype in ("dielectric", "rough_dielectric"):
            r.check_keys(m, where, ["type", "ior", "absorption", "fresnel"] +
                         (["roughness"] if mtype == "rough_dielectric" else []))
            fresnel = r.string(m, "fresnel", where, "exact")
            if fresnel != "exact":
                r.fail(f"{where}.fresnel", f"dielectric with fresnel = \"{fresnel}\" has no Mitsuba equivalent "
                                           "(Mitsuba's dielectric uses the exact Fresnel equations; "
                                           "use fresnel = \"exact\" or omit the key)")
            ior = r.number(m, "ior", where, 1.5)
            if not 1 <= ior <= 1e30:
                r.fail(f"{where}.ior", f"must be in [1, 1e30], got {ior:g}")
            absorption = r.color(m, "absorption", where, 0.0, 0.0)
            bsdf = {"type": "dielectric", "int_ior": ior, "ext_ior": 1.0}
            roughness = roughness_param(m, where, math.sqrt(0.1), name) if mtype == "rough_dielectric" else 0.0
            if is_rough(roughness):
                bsdf.update({"type": "roughdielectric", **ggx(roughness)})
            if any(k > 0 for k in absorption):
                media_ids[name] = f"medium{index}"
                # volpath turns a channel with sigma_t = 0 and albedo 0 into NaN
                # (0/0 in its albedo ratio); a floor of 1e-7 per unit length
                # changes the transmittance by less than 1e-6 over 10 units.
                # An RGB sigma_t is read as a reflectance (each channel <= 1),
                # so pass κ / max(κ) and scale = max(κ).
                sigma_t = [max(k, ABSORPTION_FLOOR) for k in absorption]
                scale = max(sigma_t)
                scene[media_ids[name]] = {"type": "homogeneous", "id": media_ids[name], "albedo": 0.0,
                                          "sigma_t": _rgb([k / scale for k in sigma_t]), "scale": scale}
                needs_volpath = True
        elif mtype == "conductor":
            r.check_keys(m, where, ["type", "roughness", "anisotropy", "metal", "eta", "k", "tint"])
            roughness = roughness_param(m, where, 0.0, name)
            if r.number(m, "anisotropy", where, 0.0) != 0.0:
                r.fail(f"{where}.anisotropy", "anisotropic conductors do not convert: vkrt orients the "
                                              "anisotropy by a frame around the normal, Mitsuba by dp/du")
            if "metal" in m:
                eta, k = METALS.get(r.string(m, "metal", where), (None, None))
                if eta is None:
                    r.fail(f"{where}.metal", f"unknown metal '{m['metal']}' (known: {', '.join(sorted(METALS))})")
            elif "eta" in m or "k" in m:
                eta = r.color(m, "eta", where, None, 0.0)
                k = r.color(m, "k", where, None, 0.0)
            else:  # vkrt's default, Mitsuba's material "none"
                eta, k = [0.0] * 3, [1.0] * 3
            tint = color_param(m, "tint", where, 1.0, name)
            inner = {"type": "conductor", "eta": _rgb(eta), "k": _rgb(k), "specular_reflectance": tint}
            if is_rough(roughness):
                inner.update({"type": "roughconductor", **ggx(roughness)})
            bsdf = {"type": "twosided", "bsdf": inner}
        elif mtype == "plastic":
            r.check_keys(m, where, ["type", "diffuse", "roughness", "ior"])
            if is_texture_table(m, "roughness"):
                r.fail(f"{where}.roughness", "a plastic's roughness cannot be a texture (vkrt refuses it too: "
                                             "its coating's energy table, like Mitsuba's roughplastic's, is "
                                             "computed for one roughness)")
            roughness = r.number(m, "roughness", where, 0.0)
            inner = {"type": "plastic", "int_ior": r.number(m, "ior", where, 1.49), "ext_ior": 1.0,
                     "diffuse_reflectance": color_param(m, "diffuse", where, 0.5, name), "nonlinear": False}
            if roughness > 0:
                inner.update({"type": "roughplastic", **ggx(roughness)})
            bsdf = {"type": "twosided", "bsdf": inner}
        elif mtype == "pbr":
            r.fail(f"{where}.type", "material type 'pbr' (glTF metallic-roughness) has no Mitsuba equivalent: "
                                    "Mitsuba's principled BSDF is another model")
        elif mtype in ("phong", "glossy"):
            r.fail(f"{where}.type", f"material type '{mtype}' has no Mitsuba equivalent "
                                    f"(used by {used[name]}); only lambert, mirror (fresnel = \"none\") and "
                                    "dielectric (exact Fresnel) convert")
        else:
            r.fail(f"{where}.type", f"unknown material type '{mtype}'")
        bsdf["id"] = bsdf_id
        scene[bsdf_id] = bsdf
        bsdf_ids[name] = bsdf_id

    # Only meshes have texture coordinates Mitsuba shares with vkrt.
    for i, o in enumerate(objects):
        shape, mat = o.get("shape"), o["material"]
        if mat in textured and shape != "mesh":
            r.fail(f"objects[{i}].shape", f"material '{mat}' has textures ({', '.join(textured[mat])}), but a "
                                          f"{shape} has no texture coordinates that Mitsuba shares with vkrt "
                                          "(vkrt's parametrisation of spheres, boxes, planes and triangles is "
                                          "its own); use a mesh with uvs for a Mitsuba reference")

    # Everything above is plain Python: scenes that cannot be converted are
    # refused without Mitsuba.
    mi = _mitsuba()
    if files_dir is None:
        files_dir = Path(tempfile.mkdtemp(prefix="vkrt-mitsuba-"))
        atexit.register(shutil.rmtree, files_dir, True)
    files_dir = Path(files_dir)
    files_dir.mkdir(parents=True, exist_ok=True)
    for bsdf_id in bsdf_ids.values():
        scene[bsdf_id] = _resolve_textures(mi, scene[bsdf_id], files_dir, bsdf_id)

    def ref(i):
        return {"type": "ref", "id": i}

    # Bounds of finite geometry, for the camera's far clip.
    extent_points = [eye, target]

    black_id = None

    def black_bsdf():
        nonlocal black_id
        if black_id is None:
            black_id = "black"
            scene[black_id] = {"type": "diffuse", "id": black_id, "reflectance": _rgb([0, 0, 0])}
        return ref(black_id)

    mesh_count = 0

    def mesh(tris, key_prefix):
        nonlocal mesh_count
        file = files_dir / f"{key_prefix}.ply"
        _write_ply(file, [v for t in tris for v in t])
        mesh_count += 1
        return {"type": "ply", "filename": str(file.resolve()), "face_normals": True}

    def mesh_object(o, where, texture_keys):
        """A `shape = "mesh"` object as an obj/ply shape (material and medium are added by the caller).
        `texture_keys`: the material's textured keys (empty for none)."""
        import numpy as np

        r.check_keys(o, where, MESH_KEYS)
        file = Path(r.string(o, "file", where))
        if not file.is_absolute():
            file = path.parent / file
        suffix = file.suffix.lower()
        if suffix not in MESH_EXTENSIONS:
            r.fail(f"{where}.file", f"'{file}': expected a .obj, .ply, .gltf or .glb file")
        if not file.is_file():
            r.fail(f"{where}.file", f"'{file}' does not exist or is not a regular file")
        if suffix in (".gltf", ".glb"):
            r.fail(f"{where}.file", f"'{file}': Mitsuba 3 has no glTF loader and this converter does not "
                                    "translate glTF; export the mesh as OBJ or PLY for a Mitsuba reference")
        normals = r.string(o, "normals", where, "file")
        if normals not in NORMAL_MODES:
            r.fail(f"{where}.normals", f"unknown normals mode '{normals}' (expected file, smooth or face)")
        m4 = mesh_transform(r, o, where)
        emission = r.color(o, "emission", where, 0.0, 0.0) if "emission" in o else None
        two_sided = r.boolean(o, "two_sided", where, False)
        if two_sided and emission is None:
            r.fail(f"{where}.two_sided", "only applies to an emissive mesh (set emission too)")
        if two_sided:
            r.fail(f"{where}.two_sided", "a two-sided emissive mesh has no Mitsuba equivalent (its area "
                                         "emitter emits on the front side only); use two_sided = false")
        try:
            geometry = read_mesh_file(file)
        except _MeshFileError as e:
            r.fail(f"{where}.file", str(e))
        if texture_keys and not geometry.has_uvs:
            r.fail(f"{where}.file", f"'{file}' has no texture coordinates (on every face corner), but its "
                                    f"material '{o['material']}' has textures ({', '.join(texture_keys)})")
        shape_dict = {"type": suffix[1:], "filename": str(file.resolve())}
        if normals == "smooth":
            # Mitsuba's recomputed vertex normals are angle-weighted and it
            # prefers the file's own; vkrt's are area-weighted from the
            # triangles alone: write them into a PLY of our own.
            smooth = files_dir / f"{where.replace('[', '').replace(']', '')}_smooth.ply"
            uvs = (geometry.uvs, geometry.corner_uvs) if texture_keys else (None, None)
            write_ply_with_normals(smooth, geometry.positions,
                                   area_weighted_normals(geometry.positions, geometry.triangles),
                                   geometry.triangles, *uvs)
            shape_dict = {"type": "ply", "filename": str(smooth.resolve())}
        elif normals == "face" or not geometry.has_normals:
            # vkrt: no file normals means face normals; Mitsuba would compute smooth ones.
            shape_dict["face_normals"] = True
        if texture_keys:
            # Mitsuba's OBJ loader flips v by default, its PLY loader does not;
            # flipped, its bitmaps show the image as vkrt does (uv_transform_matrix).
            shape_dict["flip_tex_coords"] = True
        shape_dict["to_world"] = _matrix_transform(mi, m4)
        if emission is not None and any(c > 0 for c in emission):
            shape_dict["emitter"] = {"type": "area", "radiance": _rgb(emission)}
            if not shape_dict.get("face_normals"):
                _note(f"{path}: {where}: Mitsuba's area emitter picks its emitting side by the shading "
                      "normal, vkrt by the winding; they agree where the two normals are on the same side")
        world = geometry.positions @ np.array(m4)[:3, :3].T + np.array(m4)[:3, 3]
        return shape_dict, [world.min(0).tolist(), world.max(0).tolist()]

    plane_count = 0
    for i, o in enumerate(objects):
        where = f"objects[{i}]"
        shape = r.string(o, "shape", where)
        mat = o["material"]
        shape_dict = None
        if shape == "sphere":
            r.check_keys(o, where, ["shape", "material", "center", "radius"])
            c = r.vector(o, "center", where)
            rad = r.number(o, "radius", where)
            if rad <= 0:
                r.fail(f"{where}.radius", f"must be > 0, got {rad:g}")
            shape_dict = {"type": "sphere", "center": c, "radius": rad}
            extent_points += [[c[k] + s * rad for k in range(3)] for s in (-1, 1)]
        elif shape == "box":
            r.check_keys(o, where, ["shape", "material", "min", "max"])
            lo = r.vector(o, "min", where)
            hi = r.vector(o, "max", where)
            if not all(hi[k] > lo[k] for k in range(3)):
                r.fail(f"{where}.max", "must be greater than min in every component")
            c = [(lo[k] + hi[k]) / 2 for k in range(3)]
            h = [(hi[k] - lo[k]) / 2 for k in range(3)]
            m4 = [[h[0], 0, 0, c[0]], [0, h[1], 0, c[1]], [0, 0, h[2], c[2]], [0, 0, 0, 1]]
            shape_dict = {"type": "cube", "to_world": _matrix_transform(mi, m4)}
            extent_points += [lo, hi]
        elif shape == "triangle":
            r.check_keys(o, where, ["shape", "material", "vertices"])
            v = r.triangle(o, "vertices", where)
            if _norm(_cross(_sub(v[1], v[0]), _sub(v[2], v[0]))) == 0:
                _note(f"{path}: {where}: degenerate triangle (zero area) skipped; it covers nothing")
                continue
            shape_dict = mesh([v], f"object{i}")
            extent_points += v
        elif shape == "mesh":
            shape_dict, points = mesh_object(o, where, textured.get(mat, []))
            extent_points += points
        elif shape == "plane":
            r.check_keys(o, where, ["shape", "material", "point", "normal"])
            p = r.vector(o, "point", where)
            n = r.vector(o, "normal", where)
            ln = _norm(n)
            if ln == 0:
                r.fail(f"{where}.normal", "must be non-zero")
            n = [x / ln for x in n]
            # Orthonormal basis (t, b, n) (Duff et al. 2017).
            sign = 1.0 if n[2] >= 0 else -1.0
            a = -1.0 / (sign + n[2])
            b = n[0] * n[1] * a
            t = [1.0 + sign * n[0] * n[0] * a, sign * b, -sign * n[0]]
            bt = [b, sign + n[1] * n[1] * a, -n[1]]
            hs = plane_half_size
            m4 = [[t[0] * hs, bt[0] * hs, n[0], p[0]], [t[1] * hs, bt[1] * hs, n[1], p[1]],
                  [t[2] * hs, bt[2] * hs, n[2], p[2]], [0, 0, 0, 1]]
            shape_dict = {"type": "rectangle", "to_world": _matrix_transform(mi, m4)}
            extent_points += [[p[k] + s * hs * (t[k] + bt[k]) for k in range(3)] for s in (-1, 1)]
            plane_count += 1
        else:
            r.fail(f"{where}.shape", f"unknown shape '{shape}' (expected sphere, box, triangle, plane or mesh)")
        shape_dict["bsdf"] = ref(bsdf_ids[mat])
        if mat in media_ids:
            shape_dict["interior"] = ref(media_ids[mat])
        scene[f"object{i}"] = shape_dict
    if plane_count:
        _note(f"{path}: {plane_count} infinite plane(s) approximated by square(s) of half-size "
              f"{plane_half_size:g} (--plane-half-size)")

    # [[lights]]
    lights = data.get("lights", [])
    if not isinstance(lights, list):
        r.fail("lights", "expected an array of tables")
    for i, light in enumerate(lights):
        where = f"lights[{i}]"
        r.table(light, where)
        ltype = r.string(light, "type", where)
        if ltype == "point":
            r.check_keys(light, where, ["type", "position", "intensity"])
            pos = r.vector(light, "position", where)
            intensity = r.color(light, "intensity", where, None, 0.0)
            scene[f"light{i}"] = {"type": "point", "position": pos, "intensity": _rgb(intensity)}
            extent_points.append(pos)
        elif ltype == "triangle":
            r.check_keys(light, where, ["type", "vertices", "radiance", "two_sided"])
            v = r.triangle(light, "vertices", where)
            radiance = r.color(light, "radiance", where, None, 0.0)
            two_sided = r.boolean(light, "two_sided", where, False)
            nrm = _cross(_sub(v[1], v[0]), _sub(v[2], v[0]))
            if _norm(nrm) == 0:
                _note(f"{path}: {where}: zero-area light skipped (vkrt drops it too)")
                continue
            extent_points += v
            emitter = {"type": "area", "radiance": _rgb(radiance)}
            front = mesh([v], f"light{i}")
            front.update({"bsdf": black_bsdf(), "emitter": emitter})
            scene[f"light{i}"] = front
            if two_sided:
                # The reverse-wound twin emits on the other side. It sits a hair
                # behind the front triangle so that rays from either side meet
                # the triangle facing them first (coincident triangles would be
                # hit in arbitrary order).
                size = max(_norm(_sub(v[1], v[0])), _norm(_sub(v[2], v[1])), _norm(_sub(v[0], v[2])))
                unit = [x / _norm(nrm) for x in nrm]
                eps = 1e-5 * size
                back = [[p[k] - eps * unit[k] for k in range(3)] for p in (v[0], v[2], v[1])]
                back_dict = mesh([back], f"light{i}_back")
                back_dict.update({"bsdf": black_bsdf(), "emitter": dict(emitter)})
                scene[f"light{i}_back"] = back_dict
        else:
            r.fail(f"{where}.type", f"unknown light type '{ltype}' (expected point or triangle)")

    # [background]
    bg = r.table(data.get("background", {}), "background")
    r.check_keys(bg, "background", ["color", "cubemap"])
    if "cubemap" in bg:
        if "color" in bg:
            r.fail("background.cubemap", "cannot be combined with background.color")
        cm = r.table(bg["cubemap"], "background.cubemap")
        r.check_keys(cm, "background.cubemap", list(FACE_KEYS))
        face_paths = []
        for key in FACE_KEYS:
            p = Path(r.string(cm, key, "background.cubemap"))
            if not p.is_absolute():
                p = path.parent / p
            if not p.is_file():
                r.fail(f"background.cubemap.{key}", f"'{p}' does not exist or is not a regular file")
            if p.suffix.lower() not in (".exr", ".png"):
                r.fail(f"background.cubemap.{key}", f"'{p}': expected a .exr or .png file")
            face_paths.append(p)
        faces = load_cubemap_faces(r, face_paths)
        n = faces.shape[1]
        # Mitsuba interpolates the equirectangular map bilinearly once more;
        # 128 columns per face texel keep that second interpolation within
        # ~1e-4 of the cube's own bilinear filter even at sharp edges.
        w = envmap_width or min(8192, max(1024, 128 * n))
        equirect = equirect_from_cubemap(faces, w, envmap_column_offset(mi))
        env_file = files_dir / "environment.exr"
        mi.Bitmap(equirect, mi.Bitmap.PixelFormat.RGB).write(str(env_file))
        scene["environment"] = {"type": "envmap", "filename": str(env_file.resolve())}
    else:
        color = r.color(bg, "color", "background", 0.0, 0.0)
        if any(c > 0 for c in color):
            scene["environment"] = {"type": "constant", "radiance": _rgb(color)}

    # Camera last: the far clip must reach all geometry.
    far = 1e4
    for p in extent_points:
        far = max(far, 2.0 * _norm(_sub(p, eye)))
    scene["integrator"] = {"type": "volpath" if needs_volpath else "path", "max_depth": max_depth + 1}
    scene["sensor"] = {
        "type": "perspective",
        "fov": fov,
        "fov_axis": "y",
        "near_clip": 1e-3,
        "far_clip": far,
        "to_world": mi.ScalarTransform4f().look_at(origin=eye, target=target, up=up),
        "film": {"type": "hdrfilm", "width": width, "height": height, "rfilter": {"type": "box"},
                 "pixel_format": "rgb", "component_format": "float32"},
        "sampler": {"type": "independent", "sample_count": spp},
    }
    return scene


_PLUGIN_TAGS = {
    "twosided": "bsdf", "diffuse": "bsdf", "conductor": "bsdf", "dielectric": "bsdf",
    "roughconductor": "bsdf", "roughdielectric": "bsdf", "plastic": "bsdf", "roughplastic": "bsdf",
    "bitmap": "texture", "sphere": "shape", "cube": "shape", "rectangle": "shape", "ply": "shape", "obj": "shape",
    "area": "emitter", "point": "emitter", "constant": "emitter", "envmap": "emitter",
    "homogeneous": "medium", "perspective": "sensor", "hdrfilm": "film", "independent": "sampler",
    "box": "rfilter", "path": "integrator", "volpath": "integrator",
}


def _xml_number(x) -> str:
    return repr(float(x))


def _xml_element(name, value, indent: str, base: Path) -> list[str]:
    """One property or nested plugin as XML lines."""
    from xml.sax.saxutils import quoteattr

    q = quoteattr
    if isinstance(value, dict):
        kind = value.get("type")
        if kind == "ref":
            return [f"{indent}<ref name={q(name)} id={q(value['id'])}/>"]
        if kind == "rgb":
            return [f"{indent}<rgb name={q(name)} value=\"{' '.join(_xml_number(v) for v in value['value'])}\"/>"]
        tag = _PLUGIN_TAGS[kind]
        attrs = f"type={q(kind)}"
        if "id" in value:
            attrs += f" id={q(value['id'])}"
        elif name is not None:
            attrs += f" name={q(name)}"
        lines = [f"{indent}<{tag} {attrs}>"]
        for k, v in value.items():
            if k not in ("type", "id"):
                lines += _xml_element(k, v, indent + "    ", base)
        lines.append(f"{indent}</{tag}>")
        return lines
    if isinstance(value, bool):
        return [f"{indent}<boolean name={q(name)} value=\"{'true' if value else 'false'}\"/>"]
    if isinstance(value, int):
        return [f"{indent}<integer name={q(name)} value=\"{value}\"/>"]
    if isinstance(value, float):
        return [f"{indent}<float name={q(name)} value=\"{_xml_number(value)}\"/>"]
    if isinstance(value, str):
        if name == "filename":
            value = os.path.relpath(value, base)
        return [f"{indent}<string name={q(name)} value={q(value)}/>"]
    if isinstance(value, list) and len(value) == 3:
        x, y, z = (_xml_number(v) for v in value)
        return [f"{indent}<point name={q(name)} x=\"{x}\" y=\"{y}\" z=\"{z}\"/>"]
    if hasattr(value, "matrix"):  # ScalarTransform4f or 3f: write the full matrix, row-major
        import numpy as np

        m = np.array(value.matrix, dtype=np.float64)
        if m.size == 9:
            # A 2D (uv) transform. Mitsuba's XML reads 9 values as the linear part of a 4 x 4 matrix
            # and drops the translation (checked), but takes rows/columns 0, 1 and 3 of a 4 x 4.
            m3 = m.reshape(3, 3)
            m = np.eye(4)
            m[np.ix_([0, 1, 3], [0, 1, 3])] = m3
        m = m.reshape(4, 4)
        values = " ".join(_xml_number(v) for v in m.ravel())
        return [f"{indent}<transform name={q(name)}>", f"{indent}    <matrix value=\"{values}\"/>",
                f"{indent}</transform>"]
    raise TypeError(f"cannot write {name} = {value!r} as Mitsuba XML")


def write_xml(scene: dict, xml_path: Path) -> None:
    """Write the dict as Mitsuba 3 XML; file references become paths relative to
    the XML file, transforms full matrices."""
    import mitsuba as mi

    xml_path = Path(xml_path)
    base = xml_path.parent.resolve()
    lines = [f"<!-- Converted from a vkrt scene by tools/to_mitsuba.py -->",
             f"<scene version=\"{mi.__version__}\">"]
    for k, v in scene.items():
        if k != "type":
            lines += _xml_element(k, v, "    ", base)
    lines.append("</scene>")
    xml_path.write_text("\n".join(lines) + "\n", encoding="utf-8")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene", help="vkrt scene (.toml)")
    out = ap.add_mutually_exclusive_group(required=True)
    out.add_argument("-o", "--output", help="Mitsuba XML file to write; meshes, the environment map and "
                                            "roughness (alpha) textures go into a folder next to it named "
                                            "after it (<stem>_files/)")
    out.add_argument("--print-dict", action="store_true",
                     help="print the Mitsuba scene dict (its PLY and EXR files live in a temporary folder "
                          "that is removed on exit)")
    ap.add_argument("--plane-half-size", type=float, default=DEFAULT_PLANE_HALF_SIZE,
                    help="half-size of the squares that stand in for infinite planes (default %(default)g)")
    ap.add_argument("--envmap-width", type=int, default=None,
                    help="width of the equirectangular environment map made from a cubemap "
                         "(default: 128 x face size, clamped to [1024, 8192])")
    ap.add_argument("--allow-whitted", action="store_true",
                    help="convert a Whitted scene as if it used integrator = \"path\"")
    ap.add_argument("--variant", default="scalar_rgb", help="Mitsuba variant (default %(default)s)")
    args = ap.parse_args(argv)
    try:
        import mitsuba as mi
    except ImportError:
        print("to_mitsuba: error: cannot import mitsuba; run it in the environment made by "
              "tools/make_reference.py (.venv-mitsuba) or `pip install -r tools/requirements-mitsuba.txt`",
              file=sys.stderr)
        return 2
    mi.set_variant(args.variant)
    try:
        if args.output:
            xml = Path(args.output)
            files = xml.parent / f"{xml.stem}_files"
            scene = convert(args.scene, files_dir=files, plane_half_size=args.plane_half_size,
                            envmap_width=args.envmap_width, allow_whitted=args.allow_whitted)
            write_xml(scene, xml)
            print(f"wrote {xml} (+ {files}/)")
        else:
            import pprint
            scene = convert(args.scene, plane_half_size=args.plane_half_size,
                            envmap_width=args.envmap_width, allow_whitted=args.allow_whitted)
            pprint.pprint(scene, sort_dicts=False, width=110)
    except ConversionError as e:
        print(f"to_mitsuba: error: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())

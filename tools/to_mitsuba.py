#!/usr/bin/env python3
"""Convert a vkrt scene (TOML, docs/scene-format.md) to a Mitsuba 3 scene.

    tools/to_mitsuba.py SCENE.toml -o scene.xml     # XML plus a scene_files/ folder
    tools/to_mitsuba.py SCENE.toml --print-dict     # the Python dict, for inspection
    tools/to_mitsuba.py SCENE.toml -o scene.xml --vkrt build/vkrt   # which vkrt reads the scene

As a module (Mitsuba must be importable; a variant is chosen if none is set):

    import to_mitsuba
    scene_dict = to_mitsuba.convert("scene.toml")
    scene = mitsuba.load_dict(scene_dict)

The scene is read by vkrt itself: `vkrt info SCENE --scene-json -` prints the
scene it parsed and validated, every default filled in and every path
absolute (docs/scene-json.md), and this converter translates that JSON. So a
scene vkrt refuses is refused with vkrt's own message, and what is converted
is what vkrt renders. The vkrt binary is `--vkrt`, else $VKRT, else
build/vkrt of this repository.

The conversion follows the semantics of vkrt's path integrator
(`[render] integrator = "path"`); see scenes/validation/README.md:

* camera: `perspective`, vertical `fov`, `look_at(eye, target, up)`, `hdrfilm`
  with a one-pixel `box` reconstruction filter (each sample lands in its own
  pixel, as in vkrt); a camera with aperture_radius > 0 -> `thinlens` with
  the same aperture_radius and focus_distance (both measure as Mitsuba's: a
  disc across the viewing direction, the distance to the plane in focus along it);
* `max_depth`: Mitsuba's max_depth = vkrt's max_depth + 1 (vkrt counts surface
  interactions, Mitsuba counts path segments);
* lambert -> `diffuse`; mirror (fresnel = "none") -> `conductor`, material
  "none"; dielectric (exact Fresnel) -> `dielectric` with int_ior = ior and
  ext_ior = 1; absorption κ -> a `homogeneous` interior medium with
  sigma_t = κ and albedo 0, rendered with `volpath`; conductor -> `conductor`
  (roughness 0) or `roughconductor` (ggx, alpha = roughness², visible-normal
  sampling) with vkrt's RGB eta and k (a named metal's numbers as vkrt holds
  them); rough_dielectric -> `roughdielectric`;
  plastic -> `plastic` / `roughplastic` (nonlinear = false). vkrt shades both sides of
  every surface, so diffuse and conductor BSDFs are wrapped in `twosided`;
* point light -> `point` (intensity, W/sr); directional light with angle 0 ->
  `directional` (the direction light travels, irradiance); spot light with
  inner_cone_angle = outer_cone_angle -> `spot` with beam_width =
  cutoff_angle = the cone angle (a hard cone in both), to_world along its
  direction; triangle light -> a one-triangle mesh with an `area` emitter and
  a black diffuse BSDF; a two-sided light is two such triangles with opposite
  windings, the back one displaced by 1e-5 of the light's size behind the
  front one so that each side of the light hits the triangle that emits
  towards it;
* background colour -> `constant`; cubemap -> an equirectangular `envmap`
  resampled from the six faces with Vulkan's seamless bilinear cube lookup;
  lat-long environment -> `envmap` of the same file (vkrt's lat-long
  convention is Mitsuba's), to_world = its rotation, a grey scale as `scale`,
  a coloured one applied to the image (written as an EXR: Mitsuba's scale is
  one number);
* sphere -> `sphere`; box -> `cube` with a scale+translate to_world; triangle ->
  a one-triangle PLY mesh; infinite plane -> a large `rectangle` (an
  approximation: see --plane-half-size).
* mesh (OBJ, PLY) -> `obj` / `ply` reading the same file (the path vkrt
  resolved), to_world = the object-to-world matrix vkrt built; normals =
  "face", or "file" for a file without vertex normals (vkrt says which) ->
  face_normals = true (Mitsuba would compute smooth normals where vkrt uses
  face normals); normals = "smooth" -> a PLY written with vkrt's
  area-weighted vertex normals, vertices at the same position sharing one
  (Mitsuba's own are angle-weighted), from the geometry Mitsuba's loader
  reads; emission -> an `area` emitter on the mesh, which keeps its
  material. glTF (Mitsuba has no loader) and two-sided emissive meshes are
  refused.

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

* pbr glass (transmission = 1, thin_walled = false, metallic = 0, every other glTF layer at its default)
  -> roughdielectric of its ior and roughness, with its absorbing medium (glTF's Schlick Fresnel and
  height-correlated G against Mitsuba's exact Fresnel and separable G: a note says so).

What has no Mitsuba equivalent (phong, glossy, other pbr materials, anisotropic conductors, Schlick Fresnel, the Whitted
integrator, directional lights with an angle (sun discs), spot lights with a soft edge (glTF's falloff
between the inner and outer cone; Mitsuba's is linear in the angle), normal maps, plastic roughness
textures, different wrap modes for u and v, textured materials on spheres, boxes, planes and triangles,
whose uvs are vkrt's own, 16-bit PNG textures, whose `linear` flag the export does not carry) is refused
with an error naming the scene file and the table and key, or the object's position in the file.
"""
from __future__ import annotations

import argparse
import atexit
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
DEFAULT_PLANE_HALF_SIZE = 1e4
ABSORPTION_FLOOR = 1e-7  # see the dielectric case in convert()
MIN_GGX_ALPHA = 1e-4  # shaders/shared/SceneTypes.h: the narrowest GGX lobe vkrt renders
SCENE_JSON_VERSION = 1  # docs/scene-json.md
FACE_KEYS = ("px", "nx", "py", "ny", "pz", "nz")  # Vulkan face order


class ConversionError(Exception):
    """A scene that cannot be converted; the message names file, table and key."""


# ----------------------------------------------------------------------------
# Small helpers
# ----------------------------------------------------------------------------

def _note(message: str) -> None:
    print(f"to_mitsuba: note: {message}", file=sys.stderr)


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
# The scene as vkrt parsed it
# ----------------------------------------------------------------------------

def default_vkrt() -> str:
    """$VKRT, else this repository's build/vkrt."""
    return os.environ.get("VKRT", str(REPO / "build" / "vkrt"))


def read_scene_json(path: Path, vkrt: str | None = None) -> dict:
    """`vkrt info SCENE --scene-json -`: the validated scene (docs/scene-json.md).
    vkrt's refusal becomes a ConversionError with vkrt's message; its warnings become notes."""
    vkrt = vkrt or default_vkrt()
    try:
        done = subprocess.run([vkrt, "info", str(path), "--scene-json", "-"], capture_output=True, text=True)
    except OSError as e:
        raise ConversionError(f"cannot run vkrt '{vkrt}' to read {path}: {e.strerror} "
                              "(build it, or pass --vkrt / set VKRT)") from e
    if done.returncode != 0:
        message = done.stderr.strip().removeprefix("vkrt: error: ")
        raise ConversionError(message or f"{vkrt} info {path} exited with status {done.returncode}")
    try:
        scene = json.loads(done.stdout)
    except json.JSONDecodeError as e:
        raise ConversionError(f"{vkrt} info {path} --scene-json: not JSON ({e})") from e
    if scene.get("format") != "vkrt-scene" or scene.get("version") != SCENE_JSON_VERSION:
        raise ConversionError(f"{vkrt}: scene JSON format {scene.get('format')!r} version {scene.get('version')!r}; "
                              f"this converter reads vkrt-scene version {SCENE_JSON_VERSION}")
    for warning in scene["warnings"]:
        _note(f"vkrt: {warning}")
    return scene


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


def load_cubemap_faces(path, face_paths):
    """The six faces as float64 (6, n, n, 3) linear RGB, checked as vkrt checks them
    when it loads them (vkrt's parser has checked that each is a .png or .exr file)."""
    import numpy as np

    mi = _mitsuba()
    faces = []
    for key, face in zip(FACE_KEYS, face_paths):
        where = f"background.cubemap.{key}"
        try:
            bmp = mi.Bitmap(str(face))
        except Exception as e:  # noqa: BLE001 (Mitsuba raises RuntimeError and friends)
            _fail(path, where, f"cannot read '{face}': {e}")
        # PNG is sRGB-encoded; convert() with srgb_gamma=False linearises it.
        bmp = bmp.convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, False)
        a = np.array(bmp, dtype=np.float64).reshape(bmp.height(), bmp.width(), 3)
        if a.shape[0] != a.shape[1] or a.shape[0] == 0:
            _fail(path, where, f"{face}: a cube face must be square, got {a.shape[1]}x{a.shape[0]}")
        if faces and a.shape != faces[0].shape:
            _fail(path, where, f"{face}: all faces must have the same size ({faces[0].shape[0]} for px), "
                               f"got {a.shape[0]}")
        if not np.all(np.isfinite(a)) or np.any(a < 0):
            _fail(path, where, f"{face}: contains a negative or non-finite value")
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

TEXTURE_CHANNELS = ("r", "g", "b", "a")


class _Texture:
    """A texture table of the scene: the texel is the parameter's value. It
    stands in the scene dict until convert() has Mitsuba and turns it into a
    `bitmap` (_bitmap_texture). `alpha`: the texel is a GGX roughness, whose
    alpha = roughness² Mitsuba needs as a one-channel image."""

    def __init__(self, file: Path, scale, linear: bool, wrap: str, channel: int, where: str, alpha: bool,
                 offset=(0.0, 0.0), rotation: float = 0.0):
        self.file = file  # where: "scene.toml: materials.x.key"
        self.scale = scale
        self.offset = [float(x) for x in offset]  # glTF KHR_texture_transform (vkrt's scene export)
        self.rotation = float(rotation)
        self.linear = linear
        self.wrap = wrap
        self.channel = channel
        self.where = where
        self.alpha = alpha

    @property
    def is_linear(self) -> bool:
        """vkrt decodes PNG and JPEG as sRGB unless linear = true; EXR is linear."""
        return self.linear or self.file.suffix.lower() == ".exr"


def exported_texture(slot: dict, records: list, where: str, *, alpha: bool = False) -> _Texture:
    """The _Texture of an exported texture slot (docs/scene-json.md): its file,
    and from its record the wrap modes and whether the data is linear."""
    record = records[slot["record"]]
    if slot["file"] is None:
        raise ConversionError(f"{where}: the texture '{slot['name']}' is not a file (it is inside a mesh file)")
    wrap_u, wrap_v = record["wrap"]
    if wrap_u != wrap_v:
        raise ConversionError(f"{where}.wrap: wrap = [\"{wrap_u}\", \"{wrap_v}\"] has no Mitsuba equivalent: "
                              "Mitsuba's bitmap texture has one wrap_mode for both axes (use the same mode for u "
                              "and v)")
    file = Path(slot["file"])
    if record["encoding"] == "rgba16f" and file.suffix.lower() != ".exr":
        # vkrt decodes 16-bit data into half floats, sRGB or not as `linear` says, and the export keeps only the result.
        raise ConversionError(f"{where}.texture: '{file}' is a 16-bit image, whose `linear` flag vkrt's scene export "
                              "does not carry; use an 8-bit PNG or an EXR for a Mitsuba reference")
    return _Texture(file, [float(x) for x in slot["scale"]], record["encoding"] == "rgba8_linear", wrap_u,
                    TEXTURE_CHANNELS.index(slot["channel"]), where, alpha, slot.get("offset", (0.0, 0.0)),
                    slot.get("rotation", 0.0))


def uv_transform_matrix(scale, offset=(0.0, 0.0), rotation: float = 0.0):
    """Mitsuba's bitmap `to_uv` (3 x 3) for vkrt's uv transform, on meshes
    loaded with flip_tex_coords = true (Mitsuba's uv = (u, 1 - v) of the
    file's (u, v); its bitmap puts uv.y = 0 at the image's top row). vkrt
    reads the image at (a, b) = R (su u, sv v) + (ou, ov), R = [c s; -s c]
    (glTF KHR_texture_transform's rotation), with b up from the bottom row,
    i.e. at Mitsuba image coordinates (a, 1 - b); with u = u', v = 1 - v' that
    is the affine map below (for c = 1, s = 0, o = 0: (su u', (1 - sv) + sv v'))."""
    su, sv = scale
    ou, ov = offset
    c, s = math.cos(rotation), math.sin(rotation)
    return [[c * su, -s * sv, s * sv + ou], [s * su, c * sv, 1.0 - c * sv - ov], [0.0, 0.0, 1.0]]


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
    if tex.scale != [1.0, 1.0] or tex.offset != [0.0, 0.0] or tex.rotation != 0.0:
        bitmap["to_uv"] = mi.ScalarTransform3f(
            mi.ScalarMatrix3f(uv_transform_matrix(tex.scale, tex.offset, tex.rotation)))
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

MITSUBA_MESH_TYPES = {".obj": "obj", ".ply": "ply"}


def area_weighted_normals(positions, triangles):
    """vkrt's normals = "smooth" (computeSmoothNormals in MeshData.h): each vertex
    gets the normalised sum of cross(v1 - v0, v2 - v0) of the triangles that use
    it or another vertex at exactly the same position (loaders split a surface's
    vertices at uv seams and normal creases), i.e. of their unit normals
    weighted by area. A vertex whose triangles are all degenerate gets (0, 0, 0).
    (Mitsuba's own recomputed normals weight by corner angle instead.)"""
    import numpy as np

    _, weld = np.unique(positions, axis=0, return_inverse=True)
    weld = weld.ravel()
    p = positions[triangles]
    face = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    sums = np.zeros((weld.max() + 1, 3))
    for corner in range(3):
        np.add.at(sums, weld[triangles[:, corner]], face)
    normals = sums[weld]
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


def write_smooth_mesh(mi, file: Path, out: Path, with_uvs: bool) -> None:
    """The mesh file as Mitsuba's own loader reads it (uvs as in the file,
    unflipped), with vkrt's smooth normals, written as a PLY to `out`."""
    import numpy as np

    mesh = mi.load_dict({"type": MITSUBA_MESH_TYPES[file.suffix.lower()], "filename": str(file),
                         "flip_tex_coords": False, "face_normals": True})
    positions = np.array(mesh.vertex_positions_buffer(), np.float64).reshape(-1, 3)
    triangles = np.array(mesh.faces_buffer(), np.int64).reshape(-1, 3)
    uvs = None
    if with_uvs and mesh.has_vertex_texcoords():
        uvs = np.array(mesh.vertex_texcoords_buffer(), np.float64).reshape(-1, 2)
    write_ply_with_normals(out, positions, area_weighted_normals(positions, triangles), triangles, uvs,
                           triangles if uvs is not None else None)


# ----------------------------------------------------------------------------
# Conversion
# ----------------------------------------------------------------------------

def _fail(path, where: str, message: str):
    raise ConversionError(f"{path}: {where}: {message}")


def _shape_where(kind: str, k: int) -> str:
    """An object's path in the export, which has one array per kind (docs/scene-json.md)."""
    return f"shapes.{kind}[{k}]"


def _origin(path, record: dict) -> str:
    """Where messages about a record point: its table in the scene file where
    vkrt keeps that (meshes: "scene.toml:12:1"), else the scene file."""
    return record.get("where", str(path))


def _used_materials(shapes: dict) -> dict[int, str]:
    """Material index -> the first object using it."""
    used = {}
    for kind, records in shapes.items():
        for k, o in enumerate(records):
            for index in [o["material"]] + o.get("file_materials", []):
                used.setdefault(index, f"{_shape_where(kind, k)} at {_origin(None, o)}" if "where" in o
                                else _shape_where(kind, k))
    return used


# A pbr material Mitsuba can render: glass that transmits everything into a
# volume, every other layer at its default (glTF's values).
PBR_GLASS = {"transmission": 1.0, "thin_walled": False, "metallic": 0.0, "base_color": [1.0, 1.0, 1.0],
             "emission": [0.0, 0.0, 0.0], "specular": 1.0, "specular_color": [1.0, 1.0, 1.0],
             "sheen_color": [0.0, 0.0, 0.0], "clearcoat": 0.0, "iridescence": 0.0, "anisotropy": 0.0}


def pbr_glass_refusal(m: dict):
    """None when the exported pbr material `m` converts to Mitsuba's rough
    dielectric, else (key, why) for the first key that keeps it from it."""
    why = ("pbr converts only as volumetric glass (transmission = 1, thin_walled = false, metallic = 0, "
           "base_color = 1, no emission, sheen, clearcoat, iridescence, anisotropy or specular change): Mitsuba's "
           "principled BSDF is Disney's model, not glTF's, and its other BSDFs have no fresnel_mix, sheen or thin "
           "film, nor glTF's anisotropy mapping and tangent frame")
    for key, value in PBR_GLASS.items():
        if key in m.get("textures", {}):
            return key, f"{key} is a texture; {why}"
        if m.get(key, value) != value:
            return key, f"{key} = {json.dumps(m.get(key))}; {why}"
    return None


def convert(path, *, files_dir=None, plane_half_size: float = DEFAULT_PLANE_HALF_SIZE,
            envmap_width: int | None = None, allow_whitted: bool = False, spp: int = 64,
            vkrt: str | None = None) -> dict:
    """Convert the vkrt scene at `path` to a Mitsuba 3 scene dict.

    vkrt (`vkrt`, default: default_vkrt()) reads and validates the scene.
    Triangles are written as PLY files and a cubemap (or a lat-long map with a
    coloured scale) as an equirectangular EXR into `files_dir` (a temporary
    folder removed at exit when None); the dict refers to them by absolute path.
    """
    path = Path(path)
    exported = read_scene_json(path, vkrt)

    integrator = exported["render"]["integrator"]
    if integrator == "whitted" and not allow_whitted:
        _fail(path, "render.integrator", "the Whitted integrator has no Mitsuba equivalent; set integrator = \"path\" "
                                         "(or pass --allow-whitted to convert the scene as if it were a path-traced one)")
    max_depth = exported["render"]["max_depth"]
    cam = exported["camera"]
    eye, target, up = cam["eye"], cam["target"], cam["up"]
    shapes, lights = exported["shapes"], exported["lights"]
    records = exported["textures"]

    scene: dict = {"type": "scene"}
    bsdf_ids: dict[int, str] = {}
    media_ids: dict[int, str] = {}
    textured: dict[int, list[str]] = {}  # material -> its keys given as textures
    needs_volpath = False
    used = _used_materials(shapes)

    def color_param(m, key, where, index):
        """An rgb value, or a _Texture for a textured parameter (its texel replaces the constant)."""
        if key in m["textures"]:
            textured.setdefault(index, []).append(key)
            return exported_texture(m["textures"][key], records, f"{path}: {where}.{key}")
        return _rgb(m[key])

    def roughness_param(m, where, index):
        """The roughness as a number, or a _Texture whose texel is the roughness."""
        if "roughness" in m["textures"]:
            textured.setdefault(index, []).append("roughness")
            return exported_texture(m["textures"]["roughness"], records, f"{path}: {where}.roughness", alpha=True)
        return m["roughness"]

    def ggx(roughness):
        """Mitsuba's microfacet keys for a roughness (number or texture) > 0."""
        alpha = roughness if isinstance(roughness, _Texture) else max(roughness * roughness, MIN_GGX_ALPHA)
        return {"distribution": "ggx", "sample_visible": True, "alpha": alpha}

    def is_rough(roughness):
        return isinstance(roughness, _Texture) or roughness > 0

    def glass(index, m, roughness):
        """Mitsuba's (rough) dielectric of m's ior, with a purely absorbing
        interior medium where m absorbs."""
        nonlocal needs_volpath
        bsdf = {"type": "dielectric", "int_ior": m["ior"], "ext_ior": 1.0}
        if is_rough(roughness):
            bsdf.update({"type": "roughdielectric", **ggx(roughness)})
        absorption = m["absorption"]
        if any(k > 0 for k in absorption):
            media_ids[index] = f"medium{index}"
            # volpath turns a channel with sigma_t = 0 and albedo 0 into NaN
            # (0/0 in its albedo ratio); a floor of 1e-7 per unit length
            # changes the transmittance by less than 1e-6 over 10 units.
            # An RGB sigma_t is read as a reflectance (each channel <= 1),
            # so pass κ / max(κ) and scale = max(κ).
            sigma_t = [max(k, ABSORPTION_FLOOR) for k in absorption]
            scale = max(sigma_t)
            scene[media_ids[index]] = {"type": "homogeneous", "id": media_ids[index], "albedo": 0.0,
                                       "sigma_t": _rgb([k / scale for k in sigma_t]), "scale": scale}
            needs_volpath = True
        return bsdf

    def fresnel_of(m):
        """The Fresnel term; under --allow-whitted, one the scene did not set is the path integrator's."""
        if allow_whitted and not m["fresnel_explicit"] and m["type"] in ("dielectric", "rough_dielectric"):
            return "exact"
        return m["fresnel"]

    for index, m in enumerate(exported["materials"]):
        name, mtype = m["name"], m["type"]
        where = f"materials.{_quote(name)}"
        if index not in used:
            _note(f"{path}: {where}: not used by any object; skipped")
            continue
        bsdf_id = f"mat{index}"
        if "normal_map" in m["textures"]:
            _fail(path, f"{where}.normal_map", "normal maps are not converted: Mitsuba's normalmap BSDF builds its "
                                               "tangent frame from each triangle's dp/du, vkrt from its own vertex "
                                               "tangents, and the two treat shading normals that face away from "
                                               "the light differently (remove normal_map for a Mitsuba reference)")
        if mtype == "lambert":
            bsdf = {"type": "twosided", "bsdf": {"type": "diffuse",
                                                 "reflectance": color_param(m, "albedo", where, index)}}
        elif mtype == "mirror":
            if m["fresnel"] != "none":
                _fail(path, f"{where}.fresnel", f"mirror with fresnel = \"{m['fresnel']}\" has no Mitsuba equivalent "
                                                "(only fresnel = \"none\" converts, to a conductor with material = "
                                                "\"none\")")
            refl = color_param(m, "reflectance", where, index)
            bsdf = {"type": "twosided", "bsdf": {"type": "conductor", "material": "none",
                                                 "specular_reflectance": refl}}
        elif mtype in ("dielectric", "rough_dielectric"):
            fresnel = fresnel_of(m)
            if fresnel != "exact":
                _fail(path, f"{where}.fresnel", f"dielectric with fresnel = \"{fresnel}\" has no Mitsuba equivalent "
                                                "(Mitsuba's dielectric uses the exact Fresnel equations; "
                                                "use fresnel = \"exact\" or omit the key)")
            roughness = roughness_param(m, where, index) if mtype == "rough_dielectric" else 0.0
            bsdf = glass(index, m, roughness)
        elif mtype == "pbr":
            refusal = pbr_glass_refusal(m)
            if refusal:
                _fail(path, f"{where}.{refusal[0]}", refusal[1])
            _note(f"{path}: {where}: pbr glass (transmission 1 into a volume) converted to Mitsuba's rough "
                  "dielectric, whose exact Fresnel differs from glTF's Schlick form by less than 0.01 away from "
                  "grazing, and whose Smith G is separable where glTF's is height-correlated")
            bsdf = glass(index, m, roughness_param(m, where, index))
        elif mtype == "conductor":
            roughness = roughness_param(m, where, index)
            if m["anisotropy"] != 0.0:
                _fail(path, f"{where}.anisotropy", "anisotropic conductors do not convert: vkrt orients the "
                                                   "anisotropy by a frame around the normal, Mitsuba by dp/du")
            tint = color_param(m, "tint", where, index)
            inner = {"type": "conductor", "eta": _rgb(m["eta"]), "k": _rgb(m["k"]), "specular_reflectance": tint}
            if is_rough(roughness):
                inner.update({"type": "roughconductor", **ggx(roughness)})
            bsdf = {"type": "twosided", "bsdf": inner}
        elif mtype == "plastic":
            # vkrt refuses a textured plastic roughness: its coating's energy table is per material.
            roughness = m["roughness"]
            inner = {"type": "plastic", "int_ior": m["ior"], "ext_ior": 1.0,
                     "diffuse_reflectance": color_param(m, "diffuse", where, index), "nonlinear": False}
            if roughness > 0:
                inner.update({"type": "roughplastic", **ggx(roughness)})
            bsdf = {"type": "twosided", "bsdf": inner}
        elif mtype in ("phong", "glossy"):
            _fail(path, f"{where}.type", f"material type '{mtype}' has no Mitsuba equivalent "
                                         f"(used by {used[index]}); only lambert, mirror (fresnel = \"none\") and "
                                         "dielectric (exact Fresnel) convert")
        else:
            _fail(path, f"{where}.type", f"material type '{mtype}' has no Mitsuba conversion")
        bsdf["id"] = bsdf_id
        scene[bsdf_id] = bsdf
        bsdf_ids[index] = bsdf_id

    # Only meshes have texture coordinates Mitsuba shares with vkrt.
    for kind, objects in shapes.items():
        for k, o in enumerate(objects):
            mat = o["material"]
            if mat in textured and kind != "mesh":
                _fail(path, _shape_where(kind, k),
                      f"material '{exported['materials'][mat]['name']}' has textures ({', '.join(textured[mat])}), "
                      f"but a {kind} has no texture coordinates that Mitsuba shares with vkrt (vkrt's "
                      "parametrisation of spheres, boxes, planes and triangles is its own); use a mesh with uvs "
                      "for a Mitsuba reference")
    for k, o in enumerate(shapes.get("mesh", [])):
        _check_mesh(_origin(path, o), _shape_where("mesh", k), o)
    for kind, records_of_kind in lights.items():
        for k, light in enumerate(records_of_kind):
            _check_light(_origin(path, light), f"lights.{kind}[{k}]", kind, light)

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

    def mesh(tris, key_prefix):
        file = files_dir / f"{key_prefix}.ply"
        _write_ply(file, [v for t in tris for v in t])
        return {"type": "ply", "filename": str(file.resolve()), "face_normals": True}

    def mesh_object(o, where, key, texture_keys):
        """A mesh instance as an obj/ply shape (material and medium are added by the caller).
        `texture_keys`: the material's textured keys (empty for none)."""
        file = Path(o["file"])
        shape_dict = {"type": MITSUBA_MESH_TYPES[file.suffix.lower()], "filename": str(file.resolve())}
        if o["normals"] == "smooth":
            # Mitsuba's recomputed vertex normals are angle-weighted and it
            # prefers the file's own; vkrt's are area-weighted from the
            # triangles alone: write them into a PLY of our own.
            smooth = files_dir / f"{key}_smooth.ply"
            write_smooth_mesh(mi, file, smooth, bool(texture_keys))
            shape_dict = {"type": "ply", "filename": str(smooth.resolve())}
        elif o["normals"] == "face" or not o["geometry"]["has_normals"]:
            # vkrt: no file normals means face normals; Mitsuba would compute smooth ones.
            shape_dict["face_normals"] = True
        if texture_keys:
            # Mitsuba's OBJ loader flips v by default, its PLY loader does not;
            # flipped, its bitmaps show the image as vkrt does (uv_transform_matrix).
            shape_dict["flip_tex_coords"] = True
        shape_dict["to_world"] = _matrix_transform(mi, o["matrix"])
        emission = o["emission"]
        if any(c > 0 for c in emission):
            shape_dict["emitter"] = {"type": "area", "radiance": _rgb(emission)}
            if not shape_dict.get("face_normals"):
                _note(f"{_origin(path, o)}: {where}: Mitsuba's area emitter picks its emitting side by the shading "
                      "normal, vkrt by the winding; they agree where the two normals are on the same side")
        bounds = o["world_bounds"]
        return shape_dict, [bounds["min"], bounds["max"]]

    plane_count = 0
    n = -1
    for kind, objects in shapes.items():
        for k, o in enumerate(objects):
            n += 1
            where = _shape_where(kind, k)
            mat = o["material"]
            if kind == "sphere":
                c, rad = o["center"], o["radius"]
                shape_dict = {"type": "sphere", "center": c, "radius": rad}
                extent_points += [[c[a] + s * rad for a in range(3)] for s in (-1, 1)]
            elif kind == "box":
                lo, hi = o["min"], o["max"]
                c = [(lo[a] + hi[a]) / 2 for a in range(3)]
                h = [(hi[a] - lo[a]) / 2 for a in range(3)]
                m4 = [[h[0], 0, 0, c[0]], [0, h[1], 0, c[1]], [0, 0, h[2], c[2]], [0, 0, 0, 1]]
                shape_dict = {"type": "cube", "to_world": _matrix_transform(mi, m4)}
                extent_points += [lo, hi]
            elif kind == "triangle":
                v = o["vertices"]
                if _norm(_cross(_sub(v[1], v[0]), _sub(v[2], v[0]))) == 0:
                    _note(f"{path}: {where}: degenerate triangle (zero area) skipped; it covers nothing")
                    continue
                shape_dict = mesh([v], f"object{n}")
                extent_points += v
            elif kind == "mesh":
                shape_dict, points = mesh_object(o, where, f"object{n}", textured.get(mat, []))
                extent_points += points
            elif kind == "plane":
                p, nrm = o["point"], o["normal"]  # vkrt's normal is unit already
                t, bt = _orthonormal_basis(nrm)
                hs = plane_half_size
                m4 = [[t[0] * hs, bt[0] * hs, nrm[0], p[0]], [t[1] * hs, bt[1] * hs, nrm[1], p[1]],
                      [t[2] * hs, bt[2] * hs, nrm[2], p[2]], [0, 0, 0, 1]]
                shape_dict = {"type": "rectangle", "to_world": _matrix_transform(mi, m4)}
                extent_points += [[p[a] + s * hs * (t[a] + bt[a]) for a in range(3)] for s in (-1, 1)]
                plane_count += 1
            else:
                _fail(path, where, f"shape kind '{kind}' has no Mitsuba conversion")
            shape_dict["bsdf"] = ref(bsdf_ids[mat])
            if mat in media_ids:
                shape_dict["interior"] = ref(media_ids[mat])
            scene[f"object{n}"] = shape_dict
    if plane_count:
        _note(f"{path}: {plane_count} infinite plane(s) approximated by square(s) of half-size "
              f"{plane_half_size:g} (--plane-half-size)")

    n = -1
    for kind, records_of_kind in lights.items():
        for k, light in enumerate(records_of_kind):
            n += 1
            where = f"lights.{kind}[{k}]"
            if kind == "point":
                pos = light["position"]
                scene[f"light{n}"] = {"type": "point", "position": pos, "intensity": _rgb(light["intensity"])}
                extent_points.append(pos)
            elif kind == "triangle":
                _triangle_light(scene, light, f"light{n}", mesh, black_bsdf, extent_points, f"{path}: {where}")
            elif kind == "directional":
                scene[f"light{n}"] = directional_light(light)
            elif kind == "spot":
                scene[f"light{n}"] = spot_light(mi, light)
                extent_points.append(light["position"])
            else:
                _fail(path, where, f"light kind '{kind}' has no Mitsuba conversion")

    bg = exported["background"]
    if bg.get("environment") is not None:
        scene["environment"] = environment_map(mi, bg["environment"], files_dir, path)
    elif bg["cubemap"] is not None:
        faces = load_cubemap_faces(path, [Path(bg["cubemap"][key]) for key in FACE_KEYS])
        n = faces.shape[1]
        # Mitsuba interpolates the equirectangular map bilinearly once more;
        # 128 columns per face texel keep that second interpolation within
        # ~1e-4 of the cube's own bilinear filter even at sharp edges.
        w = envmap_width or min(8192, max(1024, 128 * n))
        equirect = equirect_from_cubemap(faces, w, envmap_column_offset(mi))
        env_file = files_dir / "environment.exr"
        mi.Bitmap(equirect, mi.Bitmap.PixelFormat.RGB).write(str(env_file))
        scene["environment"] = {"type": "envmap", "filename": str(env_file.resolve())}
    elif any(c > 0 for c in bg["color"]):
        scene["environment"] = {"type": "constant", "radiance": _rgb(bg["color"])}

    # Camera last: the far clip must reach all geometry.
    far = 1e4
    for p in extent_points:
        far = max(far, 2.0 * _norm(_sub(p, eye)))
    scene["integrator"] = {"type": "volpath" if needs_volpath else "path", "max_depth": max_depth + 1}
    lens = _lens(cam)  # {} for a pinhole camera
    scene["sensor"] = {
        "type": "thinlens" if lens else "perspective",
        **lens,
        "fov": cam["fov"],
        "fov_axis": "y",
        "near_clip": 1e-3,
        "far_clip": far,
        "to_world": mi.ScalarTransform4f().look_at(origin=eye, target=target, up=up),
        "film": {"type": "hdrfilm", "width": cam["width"], "height": cam["height"], "rfilter": {"type": "box"},
                 "pixel_format": "rgb", "component_format": "float32"},
        "sampler": {"type": "independent", "sample_count": spp},
    }
    return scene


def _orthonormal_basis(n):
    """Unit vectors t, b with (t, b, n) a right-handed orthonormal basis, for a
    unit vector n (Duff et al. 2017)."""
    sign = 1.0 if n[2] >= 0 else -1.0
    a = -1.0 / (sign + n[2])
    b = n[0] * n[1] * a
    return [1.0 + sign * n[0] * n[0] * a, sign * b, -sign * n[0]], [b, sign + n[1] * n[1] * a, -n[1]]


def _lens(cam: dict) -> dict:
    """The thin lens keys of the sensor: {} for a pinhole camera (aperture_radius 0,
    or an export without the key). vkrt's focus_distance is Mitsuba's `thinlens`
    one: the distance from the eye to the plane in focus along the viewing
    direction; the aperture is a disc of aperture_radius perpendicular to it."""
    if float(cam.get("orthographic_height", 0.0)) > 0:
        raise ConversionError("camera: an orthographic camera (a glTF file's) is not converted; "
                              "Mitsuba's `orthographic` sensor scales its view by the to_world transform instead")
    aperture = float(cam.get("aperture_radius", 0.0))
    if aperture <= 0:
        return {}
    return {"aperture_radius": aperture, "focus_distance": float(cam["focus_distance"])}


def _check_light(path, where: str, kind: str, light: dict) -> None:
    """Lights that Mitsuba cannot render as vkrt does (refused before Mitsuba is needed)."""
    if kind == "directional" and light["angle"] > 0:
        _fail(path, f"{where}.angle", f"a directional light with angle = {light['angle']:g} (a disc of that "
                                      "apparent diameter in degrees) has no Mitsuba equivalent: Mitsuba's "
                                      "`directional` emitter is a delta light; use angle = 0 for a Mitsuba "
                                      "reference")
    if kind == "spot" and light["inner_cone_angle"] != light["outer_cone_angle"]:
        _fail(path, f"{where}.inner_cone_angle",
              f"a spot light with inner_cone_angle = {light['inner_cone_angle']:g} and outer_cone_angle = "
              f"{light['outer_cone_angle']:g} has no Mitsuba equivalent: between the cones vkrt's falloff is "
              "glTF's (t², t linear in the cosine of the angle), Mitsuba's `spot` ramps linearly in the angle "
              "itself; only a hard cone (inner_cone_angle = outer_cone_angle) converts")


def directional_light(light: dict) -> dict:
    """A delta directional light (angle 0): Mitsuba's `directional` takes the
    direction the light travels and the irradiance on a surface facing it, as vkrt."""
    return {"type": "directional", "direction": [float(x) for x in light["direction"]],
            "irradiance": _rgb(light["irradiance"])}


def spot_light(mi, light: dict) -> dict:
    """A hard-cone spot light (inner = outer cone angle): Mitsuba's `spot` with
    beam_width = cutoff_angle is 1 inside the cone and 0 outside (its ramp
    between them is empty), times the intensity on the axis. It points along its
    local +z: to_world's columns are a basis around the axis and the position
    (built in double, not with a float look_at, which would round position +
    direction)."""
    p = [float(x) for x in light["position"]]
    d = [float(x) for x in light["direction"]]
    length = _norm(d)
    d = [x / length for x in d]
    t, b = _orthonormal_basis(d)
    m4 = [[t[0], b[0], d[0], p[0]], [t[1], b[1], d[1], p[1]], [t[2], b[2], d[2], p[2]], [0, 0, 0, 1]]
    outer = float(light["outer_cone_angle"])
    return {"type": "spot", "intensity": _rgb(light["intensity"]), "cutoff_angle": outer, "beam_width": outer,
            "to_world": _matrix_transform(mi, m4)}


def environment_map(mi, env: dict, files_dir: Path, path) -> dict:
    """A lat-long environment ({file, scale, matrix}) as an `envmap`: vkrt's
    lat-long convention is that of Mitsuba's envmap with identity to_world, and
    vkrt's world direction = matrix · map direction is Mitsuba's to_world. A
    grey scale is the envmap's `scale`; a coloured one (Mitsuba's scale is one
    number) is applied to the image, written as a float EXR to
    files_dir/environment_scaled.exr (exact: float32 in, float32 out)."""
    import numpy as np

    if env.get("builtin") is not None:
        _fail(path, "background.environment",
              f"vkrt's built-in {env['builtin']} environment has no file: render the glTF scene with "
              "--environment FILE to convert it")
    file = Path(env["file"])
    scale = [float(x) for x in env["scale"]]
    m = [[float(x) for x in row] for row in env["matrix"]]
    to_world = _matrix_transform(mi, [m[0] + [0.0], m[1] + [0.0], m[2] + [0.0], [0.0, 0.0, 0.0, 1.0]])
    if scale[0] == scale[1] == scale[2]:
        return {"type": "envmap", "filename": str(file), "scale": scale[0], "to_world": to_world}
    try:
        bmp = mi.Bitmap(str(file))
    except Exception as e:  # noqa: BLE001 (Mitsuba raises RuntimeError and friends)
        _fail(path, "background.environment", f"cannot read '{file}': {e}")
    # The conversion the envmap plugin makes of a file it loads: linear RGB float.
    rgb = bmp.convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, False)
    data = np.array(rgb, dtype=np.float32).reshape(rgb.height(), rgb.width(), 3) * np.array(scale, np.float32)
    out = files_dir / "environment_scaled.exr"
    mi.Bitmap(data, mi.Bitmap.PixelFormat.RGB).write(str(out))
    _note(f"{path}: background.environment: scale = [{', '.join(f'{x:g}' for x in scale)}] applied to "
          f"{file.name}, written to {out}")
    return {"type": "envmap", "filename": str(out.resolve()), "to_world": to_world}


def _check_mesh(path, where: str, o: dict) -> None:
    """What Mitsuba cannot load or render as vkrt does."""
    file = Path(o["file"])
    if file.suffix.lower() not in MITSUBA_MESH_TYPES:
        _fail(path, f"{where}.file", f"'{file}': Mitsuba 3 has no glTF loader and this converter does not "
                                     "translate glTF; export the mesh as OBJ or PLY for a Mitsuba reference")
    if o["two_sided"]:
        _fail(path, f"{where}.two_sided", "a two-sided emissive mesh has no Mitsuba equivalent (its area "
                                          "emitter emits on the front side only); use two_sided = false")


def _triangle_light(scene, light, key, mesh, black_bsdf, extent_points, where) -> None:
    """A triangle light as one emitting triangle, or two back to back when two-sided."""
    v = light["vertices"]
    nrm = _cross(_sub(v[1], v[0]), _sub(v[2], v[0]))
    if _norm(nrm) == 0:
        _note(f"{where}: zero-area light skipped (vkrt drops it too)")
        return
    extent_points += v
    emitter = {"type": "area", "radiance": _rgb(light["radiance"])}
    front = mesh([v], key)
    front.update({"bsdf": black_bsdf(), "emitter": emitter})
    scene[key] = front
    if light["two_sided"]:
        # The reverse-wound twin emits on the other side. It sits a hair
        # behind the front triangle so that rays from either side meet
        # the triangle facing them first (coincident triangles would be
        # hit in arbitrary order).
        size = max(_norm(_sub(v[1], v[0])), _norm(_sub(v[2], v[1])), _norm(_sub(v[0], v[2])))
        unit = [x / _norm(nrm) for x in nrm]
        eps = 1e-5 * size
        back = [[p[a] - eps * unit[a] for a in range(3)] for p in (v[0], v[2], v[1])]
        back_dict = mesh([back], f"{key}_back")
        back_dict.update({"bsdf": black_bsdf(), "emitter": dict(emitter)})
        scene[f"{key}_back"] = back_dict


_PLUGIN_TAGS = {
    "twosided": "bsdf", "diffuse": "bsdf", "conductor": "bsdf", "dielectric": "bsdf",
    "roughconductor": "bsdf", "roughdielectric": "bsdf", "plastic": "bsdf", "roughplastic": "bsdf",
    "bitmap": "texture", "sphere": "shape", "cube": "shape", "rectangle": "shape", "ply": "shape", "obj": "shape",
    "area": "emitter", "point": "emitter", "constant": "emitter", "envmap": "emitter", "directional": "emitter",
    "spot": "emitter", "homogeneous": "medium", "perspective": "sensor", "thinlens": "sensor", "hdrfilm": "film",
    "independent": "sampler", "multijitter": "sampler", "stratified": "sampler", "ldsampler": "sampler",
    "orthogonal": "sampler", "box": "rfilter", "path": "integrator", "volpath": "integrator",
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
    ap.add_argument("--vkrt", default=None,
                    help="the vkrt binary that reads the scene (default: $VKRT, else build/vkrt)")
    args = ap.parse_args(argv)
    try:
        import mitsuba as mi
    except ImportError:
        print("to_mitsuba: error: cannot import mitsuba; run it in the environment made by "
              "tools/make_reference.py (.venv-mitsuba) or `pip install -r tools/requirements-mitsuba.txt`",
              file=sys.stderr)
        return 2
    mi.set_variant(args.variant)
    options = {"plane_half_size": args.plane_half_size, "envmap_width": args.envmap_width,
               "allow_whitted": args.allow_whitted, "vkrt": args.vkrt}
    try:
        if args.output:
            xml = Path(args.output)
            files = xml.parent / f"{xml.stem}_files"
            scene = convert(args.scene, files_dir=files, **options)
            write_xml(scene, xml)
            print(f"wrote {xml} (+ {files}/)")
        else:
            import pprint
            scene = convert(args.scene, **options)
            pprint.pprint(scene, sort_dicts=False, width=110)
    except ConversionError as e:
        print(f"to_mitsuba: error: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())

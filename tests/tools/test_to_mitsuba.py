"""Checks of tools/to_mitsuba.py (the vkrt -> Mitsuba 3 scene converter).

Not part of CI (CI has no Mitsuba). The converter reads each scene through
vkrt (`vkrt info SCENE --scene-json -`): build vkrt first; $VKRT names
another binary. Run inside the environment that tools/make_reference.py creates:

    .venv-mitsuba/bin/python tests/tools/test_to_mitsuba.py     # no pytest needed
    .venv-mitsuba/bin/python -m pytest tests/tools/test_to_mitsuba.py   # if pytest is installed

The refusal tests need only Python 3.11 and vkrt; the face-convention tests need numpy;
the rest render small scenes with Mitsuba's scalar_rgb variant and compare
them with closed forms (a few seconds each).
"""
from __future__ import annotations

import atexit
import copy
import math
import shutil
import sys
import tempfile
import textwrap
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "tools"))

import to_mitsuba  # noqa: E402

try:
    import numpy as np
except ImportError:  # pragma: no cover
    np = None
try:
    import mitsuba as mi
except ImportError:  # pragma: no cover
    mi = None


class Skip(Exception):
    pass


_STANDALONE = False  # set when run as a script


def _need(module, name):
    if module is None:
        if _STANDALONE:
            raise Skip(f"{name} is not installed")
        import pytest

        pytest.skip(f"{name} is not installed")


def _write(tmp: Path, text: str, name: str = "scene.toml") -> Path:
    path = tmp / name
    path.write_text(textwrap.dedent(text))
    return path


HEADER = """
[render]
integrator = "path"
max_depth = 1
[camera]
eye = [0.0, 0.0, 5.0]
target = [0.0, 0.0, 0.0]
fov = 30
width = 8
height = 6
"""


def _refusal(material: str, key: str, extra: str = "", header: str = HEADER):
    with tempfile.TemporaryDirectory() as tmp:
        path = _write(Path(tmp), header + textwrap.dedent(f"""
            [materials."odd one"]
            {material}
            [[objects]]
            shape = "sphere"
            material = "odd one"
            center = [0.0, 0.0, 0.0]
            radius = 1
            """) + extra)
        try:
            to_mitsuba.convert(path)
        except to_mitsuba.ConversionError as e:
            message = str(e)
        else:
            raise AssertionError(f"{material!r} was converted")
        assert str(path) in message, message
        assert key in message, message
        return message


# ----------------------------------------------------------------------------
# Refusals (plain Python)
# ----------------------------------------------------------------------------

def test_refuses_phong_and_glossy():
    _refusal('type = "phong"', 'materials."odd one".type')
    _refusal('type = "glossy"', 'materials."odd one".type')


def test_refuses_schlick():
    _refusal('type = "mirror"\nfresnel = "schlick"', 'materials."odd one".fresnel')
    _refusal('type = "dielectric"\nfresnel = "schlick"', 'materials."odd one".fresnel')


def test_refuses_pbr_other_than_volumetric_glass():
    # glTF's default pbr is an opaque metal: no Mitsuba BSDF is glTF's model.
    message = _refusal('type = "pbr"', 'materials."odd one".transmission')
    assert "Disney" in message, message
    glass = 'type = "pbr"\ntransmission = 1\nmetallic = 0\nthin_walled = false\n'
    _refusal(glass.replace("thin_walled = false\n", ""), 'materials."odd one".thin_walled')
    _refusal(glass + "clearcoat = 0.5", 'materials."odd one".clearcoat')
    _refusal(glass + "base_color = [1, 0.5, 0.5]", 'materials."odd one".base_color')
    _refusal(glass + "iridescence = 1", 'materials."odd one".iridescence')
    _refusal(glass + "anisotropy = 0.5", 'materials."odd one".anisotropy')


def test_pbr_glass_is_a_rough_dielectric_with_its_medium():
    _need(mi, "mitsuba")
    with tempfile.TemporaryDirectory() as tmp:
        path = _write(Path(tmp), HEADER + textwrap.dedent("""
            [materials.water]
            type = "pbr"
            transmission = 1
            metallic = 0
            thin_walled = false
            ior = 1.33
            roughness = 0.5
            absorption = [0.1, 0.4, 0.8]
            [[objects]]
            shape = "sphere"
            material = "water"
            center = [0.0, 0.0, 0.0]
            radius = 1
            """))
        d = to_mitsuba.convert(path)
    bsdf = d["mat0"]
    assert bsdf["type"] == "roughdielectric" and bsdf["int_ior"] == 1.33 and bsdf["alpha"] == 0.25, bsdf
    assert d["medium0"]["scale"] == 0.8, d["medium0"]


def test_refuses_whitted():
    header = HEADER.replace('integrator = "path"', 'integrator = "whitted"')
    _refusal('type = "lambert"', "render.integrator", header=header)
    header = HEADER.replace('integrator = "path"\n', "")
    _refusal('type = "lambert"', "render", header=header)


def test_refuses_unknown_keys():
    """vkrt refuses them; the converter passes its message on."""
    message = _refusal('type = "lambert"\nalbedo = 0.5\nshininess = 3', 'materials."odd one"')
    assert "'shininess'" in message, message


# ----------------------------------------------------------------------------
# Meshes (the dict only; numpy and Mitsuba for the transform objects)
# ----------------------------------------------------------------------------

QUAD_OBJ = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n"
QUAD_OBJ_WITH_NORMALS = QUAD_OBJ.replace("f 1 2 3 4", "vn 0 0 1\nf 1//1 2//1 3//1 4//1")
# A pyramid without its base: four outward-facing triangles meeting at the apex (vertex 4).
PYRAMID_PLY = """ply
format ascii 1.0
element vertex 5
property float x
property float y
property float z
element face 4
property list uchar int vertex_indices
end_header
-1 0 -1
1 0 -1
1 0 1
-1 0 1
0 2 0
3 1 0 4
3 2 1 4
3 3 2 4
3 0 3 4
"""


def _mesh_scene(tmp: Path, objects: str, files=None) -> Path:
    for name, text in (files or {"quad.obj": QUAD_OBJ}).items():
        (tmp / name).write_text(text)
    return _write(tmp, HEADER + '[materials.clay]\ntype = "lambert"\n' + textwrap.dedent(objects))


def _mesh_dict(objects: str, files=None, key="object0"):
    _need(mi, "mitsuba")
    tmp = Path(tempfile.mkdtemp(prefix="vkrt-mesh-test-"))
    atexit.register(shutil.rmtree, tmp, True)  # the dict refers to files in it
    d = to_mitsuba.convert(_mesh_scene(tmp, objects, files), files_dir=tmp / "files")
    return d[key], tmp


def _mesh_refusal(objects: str, key: str, files=None, fragment: str = ""):
    with tempfile.TemporaryDirectory() as tmp:
        path = _mesh_scene(Path(tmp), objects, files)
        try:
            to_mitsuba.convert(path, files_dir=Path(tmp) / "files")
        except to_mitsuba.ConversionError as e:
            message = str(e)
        else:
            raise AssertionError(f"converted: {objects}")
    assert str(path) in message and key in message and fragment in message, message
    return message


def _to_world(shape):
    return np.array(shape["to_world"].matrix, dtype=np.float64).reshape(4, 4)


def test_mesh_obj_without_normals_reads_the_same_file_with_face_normals():
    shape, tmp = _mesh_dict("""
        [[objects]]
        shape = "mesh"
        file = "quad.obj"
        material = "clay"
        """)
    assert shape["type"] == "obj"
    assert shape["filename"] == str((tmp / "quad.obj").resolve())
    # vkrt's "file" mode falls back to face normals; Mitsuba would make smooth ones.
    assert shape["face_normals"] is True
    assert np.allclose(_to_world(shape), np.eye(4))
    assert shape["bsdf"] == {"type": "ref", "id": "mat0"} and "emitter" not in shape


def test_mesh_obj_with_normals_keeps_them():
    shape, _ = _mesh_dict("""
        [[objects]]
        shape = "mesh"
        file = "quad.obj"
        material = "clay"
        normals = "file"
        """, {"quad.obj": QUAD_OBJ_WITH_NORMALS})
    assert shape["type"] == "obj" and "face_normals" not in shape
    face, _ = _mesh_dict("""
        [[objects]]
        shape = "mesh"
        file = "quad.obj"
        material = "clay"
        normals = "face"
        """, {"quad.obj": QUAD_OBJ_WITH_NORMALS})
    assert face["face_normals"] is True


def test_mesh_transform_is_translate_rotate_scale():
    shape, _ = _mesh_dict("""
        [[objects]]
        shape = "mesh"
        file = "quad.obj"
        material = "clay"
        scale = [2, 3, 4]
        rotate = { axis = [0, 2, 0], angle = 90 }
        translate = [1, -2, 5]
        """)
    # Right-handed 90 degrees about +y: x -> -z, z -> +x; scale first, translate last.
    expected = np.array([[0, 0, 4, 1], [0, 3, 0, -2], [-2, 0, 0, 5], [0, 0, 0, 1]], float)
    assert np.allclose(_to_world(shape), expected, atol=1e-6), _to_world(shape)
    uniform, _ = _mesh_dict("""
        [[objects]]
        shape = "mesh"
        file = "quad.obj"
        material = "clay"
        scale = 0.5
        rotate = { axis = [1, 1, 1], angle = 120 }
        """)
    # 120 degrees about the diagonal cycles the axes: x -> y -> z -> x.
    expected = 0.5 * np.array([[0, 0, 1], [1, 0, 0], [0, 1, 0]], float)
    assert np.allclose(_to_world(uniform)[:3, :3], expected, atol=1e-6), _to_world(uniform)


def test_mesh_matrix_is_used_as_given():
    rows = [[0, -1, 0, 0.5], [2, 0, 0, 1.5], [0, 0, 3, -1], [0, 0, 0, 1]]
    shape, _ = _mesh_dict(f"""
        [[objects]]
        shape = "mesh"
        file = "quad.obj"
        material = "clay"
        matrix = {rows}
        """)
    assert np.allclose(_to_world(shape), np.array(rows, float))


def test_mesh_ply_smooth_writes_area_weighted_normals():
    shape, tmp = _mesh_dict("""
        [[objects]]
        shape = "mesh"
        file = "pyramid.ply"
        material = "clay"
        normals = "smooth"
        """, {"pyramid.ply": PYRAMID_PLY})
    assert shape["type"] == "ply" and "face_normals" not in shape
    written = Path(shape["filename"])
    assert written.parent == (tmp / "files").resolve() and written.name.endswith(".ply")
    mesh = mi.load_dict({"type": "ply", "filename": str(written)})
    assert mesh.has_vertex_normals()
    n = np.array(mesh.vertex_normals_buffer()).reshape(-1, 3)
    # Apex: four equal faces, normals (0, 1, +-2)/sqrt5 and (+-2, 1, 0)/sqrt5 sum to +y.
    assert np.allclose(n[4], [0, 1, 0], atol=1e-6), n[4]
    # Corner (-1, 0, -1): two faces of the same area, normals along (0, 1, -2) and (-2, 1, 0).
    assert np.allclose(n[0], np.array([-2, 2, -2]) / np.sqrt(12), atol=1e-6), n[0]


def test_area_weighted_normals_weight_by_area_not_angle():
    _need(np, "numpy")
    # Vertex 0 is shared by a large triangle in z = 0 and a small one in x = 0,
    # with the same corner angle (90 degrees) at vertex 0.
    p = np.array([[0, 0, 0], [4, 0, 0], [0, 4, 0], [0, 1, 0], [0, 0, 1]], float)
    t = np.array([[0, 1, 2], [0, 3, 4]])
    n = to_mitsuba.area_weighted_normals(p, t)
    # Cross products (0, 0, 16) and (1, 0, 0); angle weighting would give (1, 0, 1) / sqrt(2).
    expected = np.array([1.0, 0.0, 16.0]) / np.sqrt(257)
    assert np.allclose(n[0], expected), n[0]


def test_area_weighted_normals_share_one_per_position():
    """vkrt welds vertices at one position (loaders split them at uv seams): so does the converter."""
    _need(np, "numpy")
    # Two faces at a right angle; the edge's vertices are stored twice, once per face.
    p = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    t = np.array([[0, 1, 2], [3, 4, 5]])
    n = to_mitsuba.area_weighted_normals(p, t)
    edge = np.array([1.0, 0.0, 1.0]) / np.sqrt(2)  # (0, 0, 1) + (1, 0, 0), equal areas
    for v in (0, 2, 3, 4):
        assert np.allclose(n[v], edge), (v, n[v])
    assert np.allclose(n[1], [0, 0, 1]) and np.allclose(n[5], [1, 0, 0]), n


def test_the_scene_is_read_by_vkrt():
    """vkrt's refusal is the converter's, in vkrt's words; a missing vkrt is named."""
    with tempfile.TemporaryDirectory() as tmp:
        path = _write(Path(tmp), HEADER.replace("fov = 30", "fov = 300"))
        try:
            to_mitsuba.convert(path)
        except to_mitsuba.ConversionError as e:
            assert f"{path}:" in str(e) and "camera.fov" in str(e), e
        else:
            raise AssertionError("fov = 300 was converted")
        try:
            to_mitsuba.convert(path, vkrt=str(Path(tmp) / "no-vkrt"))
        except to_mitsuba.ConversionError as e:
            assert "no-vkrt" in str(e) and "--vkrt" in str(e), e
        else:
            raise AssertionError("converted without vkrt")


def test_mesh_emission_is_a_one_sided_area_emitter_that_still_scatters():
    shape, _ = _mesh_dict("""
        [[objects]]
        shape = "mesh"
        file = "quad.obj"
        material = "clay"
        emission = [18.4, 11.0, 2.75]
        """)
    assert shape["emitter"] == {"type": "area", "radiance": {"type": "rgb", "value": [18.4, 11.0, 2.75]}}
    assert shape["bsdf"] == {"type": "ref", "id": "mat0"}


def test_mesh_emission_side_is_counter_clockwise():
    """The quad (counter-clockwise seen from +z) glows seen from +z, is black from -z."""
    _need(mi, "mitsuba")
    if mi.variant() is None:
        mi.set_variant("scalar_rgb")
    objects = """
        [materials.black]
        type = "lambert"
        albedo = 0
        [[objects]]
        shape = "mesh"
        file = "quad.obj"
        material = "black"
        translate = [-0.5, -0.5, 0]
        emission = [3, 2, 1]
        """
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        front = _mesh_scene(tmp, objects)
        d = to_mitsuba.convert(front, files_dir=tmp / "files")
        img_front = np.array(mi.render(mi.load_dict(d), spp=4), dtype=np.float64)
        back = _write(tmp, front.read_text().replace("eye = [0.0, 0.0, 5.0]", "eye = [0.0, 0.0, -5.0]"))
        img_back = np.array(mi.render(mi.load_dict(to_mitsuba.convert(back, files_dir=tmp / "files")), spp=4),
                            dtype=np.float64)
    assert np.allclose(img_front[2:4, 3:5], [3, 2, 1]), img_front[2:4, 3:5]
    assert np.all(img_back == 0), img_back.max()


def test_mesh_refusals():
    mesh = '[[objects]]\nshape = "mesh"\nmaterial = "clay"\n'
    _mesh_refusal(mesh + 'file = "quad.obj"\nscale = 2\nmatrix = [[1, 0, 0, 0], [0, 1, 0, 0], '
                  '[0, 0, 1, 0], [0, 0, 0, 1]]\n', "objects[0].scale", fragment="matrix")
    _mesh_refusal(mesh + 'file = "quad.obj"\nnormal = "face"\n', "objects[0]", fragment="'normal'")
    _mesh_refusal(mesh + 'file = "quad.obj"\nnormals = "flat"\n', "objects[0].normals")
    _mesh_refusal(mesh + 'file = "missing.obj"\n', "objects[0].file", fragment="missing.obj")
    _mesh_refusal(mesh + 'file = "quad.stl"\n', "objects[0].file", {"quad.stl": "solid"})
    _mesh_refusal(mesh + 'file = "box.gltf"\n', "objects[0].file", {"box.gltf": "{}"}, fragment="glTF")
    # The converter's own refusal names the mesh's table in the file and its place in vkrt's export.
    message = _mesh_refusal(mesh + 'file = "quad.obj"\nemission = 1\ntwo_sided = true\n', "shapes.mesh[0].two_sided")
    assert "scene.toml:13:1:" in message, message
    _mesh_refusal(mesh + 'file = "quad.obj"\nscale = [1, 0, 1]\n', "objects[0].scale")
    _mesh_refusal(mesh + 'file = "quad.obj"\nrotate = { axis = [0, 0, 0], angle = 3 }\n',
                  "objects[0].rotate.axis")
    _mesh_refusal(mesh + 'file = "quad.obj"\nmatrix = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0]]\n',
                  "objects[0].matrix")
    _mesh_refusal(mesh + 'file = "bad.obj"\n', "objects[0].file", {"bad.obj": "v 0 0 0\nf 1 2 3\n"},
                  fragment="bad.obj:2")


# ----------------------------------------------------------------------------
# Cube face convention (numpy)
# ----------------------------------------------------------------------------

def test_face_directions_follow_cubefaces_h():
    _need(np, "numpy")
    # Texel (s, t) = (0, 0) is the top-left of each stored face (CubeFaces.h).
    expected = {0: (1, 1, 1), 1: (-1, 1, -1), 2: (-1, 1, -1), 3: (-1, -1, 1), 4: (-1, 1, 1), 5: (1, 1, -1)}
    for face, d in expected.items():
        got = to_mitsuba._face_direction(face, np.array(-1.0), np.array(-1.0))
        assert np.allclose(got, d), (face, got, d)
    rng = np.random.default_rng(1)
    for face in range(6):
        sc, tc = rng.uniform(-0.999, 0.999, (2, 100))
        g, s, t = to_mitsuba._select_face(to_mitsuba._face_direction(face, sc, tc))
        assert np.all(g == face)
        assert np.allclose(2 * s - 1, sc) and np.allclose(2 * t - 1, tc)


def test_cube_lookup_is_seamless():
    _need(np, "numpy")
    n = 4
    faces = np.random.default_rng(2).uniform(0, 1, (6, n, n, 3))
    # Approaching a cube edge from either face gives the same filtered value.
    for d in ([1, 0.3, 1], [1, 1, -0.2], [-0.4, -1, -1], [1, 1, 1]):
        d = np.array(d, float)
        e = 1e-9
        a = to_mitsuba.cube_lookup(faces, (d + [e, 0, 0])[None])
        b = to_mitsuba.cube_lookup(faces, (d + [0, e, 0])[None])
        c = to_mitsuba.cube_lookup(faces, (d + [0, 0, e])[None])
        assert np.allclose(a, b, atol=1e-6) and np.allclose(a, c, atol=1e-6), (d, a, b, c)


# ----------------------------------------------------------------------------
# Renders compared with closed forms (Mitsuba, scalar_rgb)
# ----------------------------------------------------------------------------

def _render(tmp: Path, text: str, spp: int, max_depth_override=None, seed: int = 7):
    if mi.variant() is None:
        mi.set_variant("scalar_rgb")
    d = to_mitsuba.convert(_write(tmp, text), files_dir=tmp / "files")
    if max_depth_override is not None:
        d["integrator"]["max_depth"] = max_depth_override
    return np.array(mi.render(mi.load_dict(d), spp=spp, seed=seed), dtype=np.float64)


def _camera_rays(eye, target, up, fov, w, h, sub):
    """vkrt's pinhole camera (GpuScene.cpp, camera.glsl): sub x sub points per pixel."""
    eye, target, up = (np.asarray(v, float) for v in (eye, target, up))
    f = target - eye
    f /= np.linalg.norm(f)
    r = np.cross(f, up)
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    hh = math.tan(math.radians(fov) / 2)
    hw = hh * w / h
    o = (np.arange(sub) + 0.5) / sub
    sx, sy = np.meshgrid(o, o)
    px = np.arange(w)[None, :, None] + sx.ravel()[None, None, :]
    py = np.arange(h)[:, None, None] + sy.ravel()[None, None, :]
    px, py = np.broadcast_arrays(px, py)
    d = (2 * px / w - 1)[..., None] * hw * r + (1 - 2 * py / h)[..., None] * hh * u + f
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def _tl(v):
    return "[" + ", ".join(repr(float(x)) for x in v) + "]"


def test_point_light_on_lambert_floor_matches_closed_form():
    """rho * I * cos / (pi d^2), averaged over each pixel; camera, pixel layout,
    lambert albedo, point intensity and max_depth = 1 (Mitsuba 2) in one go."""
    _need(mi, "mitsuba")
    rho, intensity, light = np.array([0.5, 0.3, 0.8]), np.array([10.0, 5.0, 2.0]), np.array([0.7, 1.5, -0.4])
    eye, target, fov, w, h = [0.3, 3.0, 2.5], [0.0, 0.0, 0.0], 50, 32, 24
    text = f"""
        [render]
        integrator = "path"
        max_depth = 1
        [camera]
        eye = {eye}
        target = {target}
        fov = {fov}
        width = {w}
        height = {h}
        [materials.floor]
        type = "lambert"
        albedo = {_tl(rho)}
        [materials.wall]
        type = "lambert"
        albedo = 0.9
        [[objects]]
        shape = "box"
        material = "floor"
        min = [-20, -1, -20]
        max = [20, 0, 20]
        [[objects]] # would add indirect light if max_depth were off by one
        shape = "box"
        material = "wall"
        min = [-20, 0, -4]
        max = [20, 5, -3]
        [[lights]]
        type = "point"
        position = {_tl(light)}
        intensity = {_tl(intensity)}
        """
    with tempfile.TemporaryDirectory() as tmp:
        img = _render(Path(tmp), text, 1024)
        black = _render(Path(tmp), text, 4, max_depth_override=1)
    d = _camera_rays(eye, target, [0, 1, 0], fov, w, h, 16)
    e = np.array(eye, float)
    t = -e[1] / d[..., 1]
    p = e + t[..., None] * d
    v = light - p
    dist2 = (v * v).sum(-1)
    cos = np.clip(v[..., 1] / np.sqrt(dist2), 0, None)
    expected = (rho * intensity * (cos / (math.pi * dist2))[..., None]).mean(2)
    floor = (d[..., 1] < -0.05).all(2) & (p[..., 2] > -2.9).all(2)
    rel = np.abs(img[floor] - expected[floor]) / expected[floor]
    assert floor.sum() > 300
    assert rel.mean() < 2e-3 and rel.max() < 1.5e-2, (rel.mean(), rel.max())
    assert black.max() == 0.0  # Mitsuba max_depth 1 = emitters only


def test_triangle_light_sidedness():
    _need(mi, "mitsuba")
    # cross(v1 - v0, v2 - v0) = cross((2, 0, 0), (1, 0, 2)) = (0, -4, 0): faces -y.
    down = [[-1.0, 0.0, -1.0], [1.0, 0.0, -1.0], [0.0, 0.0, 1.0]]
    def scene(verts, eye, two_sided):
        return f"""
            [render]
            integrator = "path"
            max_depth = 1
            [camera]
            eye = {eye}
            target = [0.0, 0.0, -0.2]
            up = [0.0, 0.0, -1.0]
            fov = 10
            width = 4
            height = 4
            [[lights]]
            type = "triangle"
            vertices = [{_tl(verts[0])}, {_tl(verts[1])}, {_tl(verts[2])}]
            radiance = [3.0, 2.0, 1.0]
            two_sided = {"true" if two_sided else "false"}
            """
    with tempfile.TemporaryDirectory() as tmp:
        below = _render(Path(tmp), scene(down, [0.0, -3.0, -0.2], False), 4)
        above = _render(Path(tmp), scene(down, [0.0, 3.0, -0.2], False), 4)
        above2 = _render(Path(tmp), scene(down, [0.0, 3.0, -0.2], True), 4)
        below2 = _render(Path(tmp), scene(down, [0.0, -3.0, -0.2], True), 4)
    le = np.array([3.0, 2.0, 1.0])
    assert np.allclose(below, le), below  # front side (counter-clockwise seen from below)
    assert np.all(above == 0), above      # back side: black
    assert np.allclose(above2, le) and np.allclose(below2, le)


def test_environment_cubemap_orientation():
    """Six flat-coloured faces: looking along each axis shows that face."""
    _need(mi, "mitsuba")
    if mi.variant() is None:
        mi.set_variant("scalar_rgb")
    colours = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 0], [1, 0, 1], [0, 1, 1]], np.float32)
    axes = [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]]
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        for key, c in zip(to_mitsuba.FACE_KEYS, colours):
            mi.Bitmap(np.broadcast_to(c, (8, 8, 3)).copy(), mi.Bitmap.PixelFormat.RGB).write(str(tmp / f"{key}.exr"))
        faces = "".join(f'{k} = "{k}.exr"\n' for k in to_mitsuba.FACE_KEYS)
        for axis, c in zip(axes, colours):
            up = [0, 0, 1] if axis[1] else [0, 1, 0]
            img = _render(tmp, f"""
                [render]
                integrator = "path"
                max_depth = 1
                [camera]
                eye = [0.0, 0.0, 0.0]
                target = {_tl(axis)}
                up = {_tl(up)}
                fov = 20
                width = 4
                height = 4
                [background.cubemap]
                """ + faces, 4)
            assert np.allclose(img[1:3, 1:3], c, atol=1e-4), (axis, img[1:3, 1:3])


def test_environment_matches_bilinear_cube_lookup():
    """Faces whose texels encode their direction: the rendered image equals the
    Vulkan bilinear cube lookup of vkrt's camera rays."""
    _need(mi, "mitsuba")
    if mi.variant() is None:
        mi.set_variant("scalar_rgb")
    n = 16
    o = (np.arange(n) + 0.5) / n
    s, t = np.meshgrid(o, o)
    eye, target, up, fov, w, h = [0, 0, 0], [0.3, 0.4, -1.0], [0, 1, 0], 70, 32, 24
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        stack = []
        for f, key in enumerate(to_mitsuba.FACE_KEYS):
            d = to_mitsuba._face_direction(f, 2 * s - 1, 2 * t - 1)
            d /= np.linalg.norm(d, axis=-1, keepdims=True)
            texels = (0.5 + 0.5 * d).astype(np.float32)
            stack.append(texels)
            mi.Bitmap(texels, mi.Bitmap.PixelFormat.RGB).write(str(tmp / f"{key}.exr"))
        img = _render(tmp, f"""
            [render]
            integrator = "path"
            max_depth = 1
            [camera]
            eye = {_tl(eye)}
            target = {_tl(target)}
            fov = {fov}
            width = {w}
            height = {h}
            [background.cubemap]
            """ + "".join(f'{k} = "{k}.exr"\n' for k in to_mitsuba.FACE_KEYS), 256)
    rays = _camera_rays(eye, target, up, fov, w, h, 8)
    expected = to_mitsuba.cube_lookup(np.stack(stack).astype(np.float64), rays).mean(2)
    err = np.abs(img - expected)
    assert err.mean() < 5e-4 and err.max() < 5e-3, (err.mean(), err.max())


def test_glass_slab_with_absorption():
    """Normal incidence through a slab: (1-R)^2 T / (1 - R^2 T^2), T = exp(-k d);
    checks dielectric Fresnel, Beer-Lambert and the cancelling eta^2 factors."""
    _need(mi, "mitsuba")
    n, kappa, thick = 1.5, np.array([2.5, 0.2, 0.0]), 1.0
    text = f"""
        [render]
        integrator = "path"
        max_depth = 20
        [camera]
        eye = [0.0, 0.0, 5.0]
        target = [0.0, 0.0, 0.0]
        fov = 1
        width = 4
        height = 3
        [materials.glass]
        type = "dielectric"
        ior = {n}
        absorption = {_tl(kappa)}
        [[objects]]
        shape = "box"
        material = "glass"
        min = [-50.0, -50.0, -0.5]
        max = [50.0, 50.0, 0.5]
        [[lights]]
        type = "triangle"
        vertices = [[-100.0, -100.0, -2.0], [100.0, -100.0, -2.0], [0.0, 100.0, -2.0]]
        radiance = 1
        """
    with tempfile.TemporaryDirectory() as tmp:
        runs = np.array([_render(Path(tmp), text, 4096, seed=k).mean((0, 1)) for k in range(8)])
    r = ((n - 1) / (n + 1)) ** 2
    tr = np.exp(-kappa * thick)
    expected = (1 - r) ** 2 * tr / (1 - r * r * tr * tr)
    got = runs.mean(0)
    # volpath's spectral MIS makes samples far from 0/1: use the spread of the runs.
    tol = 5 * runs.std(0, ddof=1) / np.sqrt(len(runs)) + 1e-5
    assert np.all(np.abs(got - expected) < tol), (got, expected, tol)


def test_single_glass_interface_scales_radiance_by_inverse_eta_squared():
    """Documents Mitsuba's convention: radiance entering a dielectric is divided
    by eta^2 (and multiplied by eta^2 on leaving). A camera outside looking at a
    light through one interface (an open surface) sees (1 - R) / eta^2."""
    _need(mi, "mitsuba")
    n = 1.5
    text = f"""
        [render]
        integrator = "path"
        max_depth = 4
        [camera]
        eye = [0.0, 0.0, 5.0]
        target = [0.0, 0.0, 0.0]
        fov = 1
        width = 4
        height = 3
        [materials.glass]
        type = "dielectric"
        ior = {n}
        [[objects]]
        shape = "triangle"
        material = "glass"
        vertices = [[-50.0, -50.0, 0.0], [50.0, -50.0, 0.0], [0.0, 50.0, 0.0]]
        [[lights]]
        type = "triangle"
        vertices = [[-100.0, -100.0, -2.0], [100.0, -100.0, -2.0], [0.0, 100.0, -2.0]]
        radiance = 1
        """
    with tempfile.TemporaryDirectory() as tmp:
        img = _render(Path(tmp), text, 4096)
    r = ((n - 1) / (n + 1)) ** 2
    assert abs(img.mean() - (1 - r) / n**2) < 0.01, img.mean()


def test_metals_are_vkrts():
    """A named metal converts to exactly the numbers of src/material/Metals.cpp (vkrt exports them)."""
    import re

    _need(mi, "mitsuba")
    source = (REPO / "src" / "material" / "Metals.cpp").read_text()
    rows = re.findall(r'\{"(\w+)", \{([^}]*)\}, \{([^}]*)\}\}', source)
    assert len(rows) >= 5, rows
    for name, eta, k in rows:
        with tempfile.TemporaryDirectory() as tmp:
            path = _write(Path(tmp), HEADER + f'[materials.m]\ntype = "conductor"\nmetal = "{name}"\n'
                          '[[objects]]\nshape = "sphere"\nmaterial = "m"\ncenter = [0.0, 0.0, 0.0]\nradius = 1\n')
            inner = to_mitsuba.convert(path, files_dir=Path(tmp) / "files")["mat0"]["bsdf"]
        assert inner["eta"]["value"] == [float(x) for x in eta.split(",")], (name, inner)
        assert inner["k"]["value"] == [float(x) for x in k.split(",")], (name, inner)


# ----------------------------------------------------------------------------
# Textures
# ----------------------------------------------------------------------------

def _srgb_to_linear(c):
    """The exact sRGB EOTF (IEC 61966-2-1), as shaders/lib/texture.glsl decodes."""
    c = np.asarray(c, np.float64)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def _vkrt_wrap(i, n, wrap):
    """wrapTexelIndex of shaders/lib/texture.glsl."""
    if wrap == "mirror":
        j = (i + 2 * n * 1000) % (2 * n)
        return np.where(j < n, j, 2 * n - 1 - j)
    if wrap == "repeat":
        return i % n
    return np.clip(i, 0, n - 1)


def _vkrt_lookup(texels, uv, scale=(1.0, 1.0), wrap="repeat"):
    """vkrt's level-0 bilinear lookup (sampleTextureLevel) of linear texels
    (h x w x c, row 0 the file's top row) at uv[..., 2] times the uv scale;
    v runs up from the bottom row."""
    h, w = texels.shape[:2]
    u = uv[..., 0] * scale[0]
    v = uv[..., 1] * scale[1]
    sx, sy = u * w - 0.5, (1.0 - v) * h - 0.5
    x0, y0 = np.floor(sx).astype(np.int64), np.floor(sy).astype(np.int64)
    fx, fy = (sx - x0)[..., None], (sy - y0)[..., None]
    xs = [_vkrt_wrap(x0, w, wrap), _vkrt_wrap(x0 + 1, w, wrap)]
    ys = [_vkrt_wrap(y0, h, wrap), _vkrt_wrap(y0 + 1, h, wrap)]
    top = (1 - fx) * texels[ys[0], xs[0]] + fx * texels[ys[0], xs[1]]
    bottom = (1 - fx) * texels[ys[1], xs[0]] + fx * texels[ys[1], xs[1]]
    return (1 - fy) * top + fy * bottom


# A unit quad in z = 0 facing +z whose uvs run from UV_LO to UV_HI, so that
# lookups leave [0, 1] and the wrap modes show. Mesh uv = UV_LO + (x, y) * (UV_HI - UV_LO).
UV_LO, UV_HI = (np.array([-0.7, -0.4]), np.array([1.6, 1.9])) if np is not None else (None, None)


def _uv_quad_obj():
    corners = [(0, 0), (1, 0), (1, 1), (0, 1)]
    uvs = [UV_LO + np.array(c) * (UV_HI - UV_LO) for c in corners]
    return ("".join(f"v {x} {y} 0\n" for x, y in corners) + "".join(f"vt {float(u)!r} {float(v)!r}\n" for u, v in uvs)
            + "f 1/1 2/2 3/3 4/4\n")


def _uv_quad_ply():
    corners = [(0, 0), (1, 0), (1, 1), (0, 1)]
    rows = "".join(f"{x} {y} 0 {float(uv[0])!r} {float(uv[1])!r}\n"
                   for (x, y), uv in ((c, UV_LO + np.array(c) * (UV_HI - UV_LO)) for c in corners))
    return ("ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
            "property float u\nproperty float v\nelement face 2\nproperty list uchar int vertex_indices\n"
            "end_header\n" + rows + "3 0 1 2\n3 0 2 3\n")


def _texture_scene(tmp: Path, material: str, mesh_file: str = "quad.obj", shape: str = "mesh") -> Path:
    obj = (f'shape = "mesh"\nfile = "{mesh_file}"\n' if shape == "mesh" else
           'shape = "sphere"\ncenter = [0.0, 0.0, 0.0]\nradius = 1\n' if shape == "sphere" else
           'shape = "box"\nmin = [0.0, 0.0, -1.0]\nmax = [1.0, 1.0, 0.0]\n' if shape == "box" else
           'shape = "triangle"\nvertices = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]\n')
    return _write(tmp, HEADER + "[materials.tex]\n" + textwrap.dedent(material) + "[[objects]]\n" + obj
                  + 'material = "tex"\n')


def _write_texture(path: Path, texels, linear_png=False):
    """Random test images: EXR as float, PNG as 8-bit (RGB or RGBA)."""
    if path.suffix == ".exr":
        mi.Bitmap(texels.astype(np.float32)).write(str(path))
    else:
        mi.Bitmap(texels.astype(np.uint8)).write(str(path))


def _hit_quad(scene, points):
    """Surface interactions of rays from z = 1 straight down onto quad points (x, y)."""
    si = []
    for x, y in points:
        ray = mi.Ray3f(mi.Point3f(float(x), float(y), 1.0), mi.Vector3f(0.0, 0.0, -1.0))
        hit = scene.ray_intersect(ray)
        assert hit.is_valid(), (x, y)
        si.append(hit)
    return si


def _quad_points(n=200, seed=3):
    return np.random.default_rng(seed).uniform(0.02, 0.98, (n, 2))


def test_texture_refusals():
    """Refused before Mitsuba is needed: textured materials on non-mesh shapes,
    per-axis wraps, keys vkrt does not take, plastic roughness textures, normal maps."""
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        _need(mi, "mitsuba")
        _write_texture(tmp / "t.png", np.zeros((2, 2, 3), np.uint8))  # vkrt loads the textures it parses
        (tmp / "quad.obj").write_text(_uv_quad_obj())

        def refused(material, key, shape="mesh", fragment=""):
            path = _texture_scene(tmp, material, shape=shape)
            try:
                to_mitsuba.convert(path, files_dir=tmp / "files")
            except to_mitsuba.ConversionError as e:
                message = str(e)
            else:
                raise AssertionError(f"converted: {material} on a {shape}")
            assert str(path) in message and key in message and fragment in message, message
            return message

        lambert = 'type = "lambert"\nalbedo = { texture = "t.png" }\n'
        for shape in ("sphere", "box", "triangle"):
            message = refused(lambert, f"shapes.{shape}[0]", shape=shape, fragment=f"a {shape}")
            assert "'tex'" in message and "albedo" in message, message
        refused('type = "lambert"\nalbedo = { texture = "t.png", wrap = ["repeat", "clamp"] }\n',
                "materials.tex.albedo.wrap", fragment="one")
        refused('type = "lambert"\nalbedo = { texture = "t.png", wrap = "border" }\n', "materials.tex.albedo.wrap")
        refused('type = "lambert"\nalbedo = { texture = "t.png", channel = "g" }\n',
                "materials.tex.albedo", fragment="unknown key 'channel'")
        refused('type = "lambert"\nalbedo = { texture = "t.png", scale = [1, 0] }\n', "materials.tex.albedo.scale")
        # vkrt locates a texture it cannot load by line and column only.
        refused('type = "lambert"\nalbedo = { texture = "missing.png" }\n', "scene.toml:13:22",
                fragment="missing.png")
        refused('type = "lambert"\nalbedo = { texture = "quad.obj" }\n', "scene.toml:13:22", fragment="not an image")
        refused('type = "conductor"\nroughness = { texture = "t.png", channel = "x" }\n',
                "materials.tex.roughness.channel")
        refused('type = "plastic"\nroughness = { texture = "t.png" }\n', "materials.tex.roughness",
                fragment="cannot be a texture")  # vkrt's refusal
        refused('type = "lambert"\nnormal_map = { texture = "t.png" }\n', "materials.tex.normal_map")


def test_texture_on_mesh_without_uvs_is_refused():
    _need(mi, "mitsuba")
    png = np.zeros((2, 2, 3), np.uint8)
    lambert = '[materials.clay]\ntype = "lambert"\nalbedo = { texture = "t.png" }\n'
    mesh = '[[objects]]\nshape = "mesh"\nmaterial = "clay"\n'
    # vkrt refuses these itself. (An OBJ whose corners have uvs only in part is vkrt's to judge too: its
    # loader accepts one, and so does the converter.)
    for name, text in (("quad.obj", QUAD_OBJ), ("pyramid.ply", PYRAMID_PLY)):
        with tempfile.TemporaryDirectory() as tmp:
            tmp = Path(tmp)
            _write_texture(tmp / "t.png", png)
            (tmp / name).write_text(text)
            path = _write(tmp, HEADER + lambert + mesh + f'file = "{name}"\n')
            try:
                to_mitsuba.convert(path, files_dir=tmp / "files")
            except to_mitsuba.ConversionError as e:
                message = str(e)
            else:
                raise AssertionError(f"converted {name} without uvs")
        assert "objects[0].material" in message and "texture coordinates" in message and "'clay'" in message, message


def test_texture_becomes_a_bitmap():
    """The bitmap's keys: the scene's own file, raw for linear data, bilinear,
    the wrap mode; flip_tex_coords on the mesh."""
    _need(mi, "mitsuba")
    tmp = Path(tempfile.mkdtemp(prefix="vkrt-texture-test-"))
    atexit.register(shutil.rmtree, tmp, True)
    (tmp / "quad.obj").write_text(_uv_quad_obj())
    _write_texture(tmp / "t.png", np.zeros((2, 2, 3)))
    _write_texture(tmp / "t.exr", np.zeros((2, 2, 3)))
    cases = [('{ texture = "t.png" }', False, "repeat"), ('{ texture = "t.png", linear = true }', True, "repeat"),
             ('{ texture = "t.exr", wrap = "clamp" }', True, "clamp"),
             ('{ texture = "t.png", wrap = ["mirror", "mirror"] }', False, "mirror")]
    for table, raw, wrap in cases:
        d = to_mitsuba.convert(_texture_scene(tmp, f'type = "lambert"\nalbedo = {table}\n'), files_dir=tmp / "f")
        bitmap = d["mat0"]["bsdf"]["reflectance"]
        name = "t.exr" if ".exr" in table else "t.png"
        assert bitmap["type"] == "bitmap" and bitmap["filename"] == str((tmp / name).resolve()), bitmap
        assert bitmap["raw"] is raw and bitmap["wrap_mode"] == wrap and bitmap["filter_type"] == "bilinear", bitmap
        assert "to_uv" not in bitmap  # scale [1, 1]
        assert d["object0"]["flip_tex_coords"] is True
    d = to_mitsuba.convert(_texture_scene(tmp, 'type = "conductor"\ntint = { texture = "t.png", scale = 3 }\n'
                                               'roughness = 0.2\n'), files_dir=tmp / "f")
    tint = d["mat0"]["bsdf"]["specular_reflectance"]
    # vkrt reads (3u, 3v); Mitsuba sees v' = 1 - v and needs image y = 1 - 3v = -2 + 3v'.
    assert np.allclose(np.array(tint["to_uv"].matrix), [[3, 0, 0], [0, 3, -2], [0, 0, 1]]), tint["to_uv"]


def _check_lookups(tmp, mesh_file, table, texels, scale, wrap, tol, via_xml=False):
    d = to_mitsuba.convert(_texture_scene(tmp, f'type = "lambert"\nalbedo = {table}\n', mesh_file),
                           files_dir=tmp / "files")
    if via_xml:
        to_mitsuba.write_xml(d, tmp / "scene.xml")
        scene = mi.load_file(str(tmp / "scene.xml"))
    else:
        scene = mi.load_dict(d)
    points = _quad_points()
    got = np.array([np.array(si.bsdf().eval_diffuse_reflectance(si)).ravel() for si in _hit_quad(scene, points)])
    expected = _vkrt_lookup(texels, UV_LO + points * (UV_HI - UV_LO), scale, wrap)
    err = np.abs(got - expected).max()
    assert err < tol, (mesh_file, table, err)


def test_texture_lookup_matches_vkrts_convention():
    """Mitsuba's bitmap on the converted mesh returns what vkrt's lookup does
    (texture.glsl: bilinear, texel centres, wrap, v up from the bottom row, uv
    scale), for OBJ (which Mitsuba flips by default) and PLY (which it does
    not), every wrap mode, scales that are negative and fractional, float EXR
    and 8-bit sRGB PNG."""
    _need(mi, "mitsuba")
    if mi.variant() is None:
        mi.set_variant("scalar_rgb")
    rng = np.random.default_rng(11)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        (tmp / "quad.obj").write_text(_uv_quad_obj())
        (tmp / "quad.ply").write_text(_uv_quad_ply())
        texels = rng.uniform(0, 1, (3, 5, 3))  # non-square, odd sizes: a flipped axis shows
        _write_texture(tmp / "t.exr", texels)
        png = rng.integers(0, 256, (4, 3, 3))
        _write_texture(tmp / "t.png", png)
        for mesh_file in ("quad.obj", "quad.ply"):
            for wrap in ("repeat", "clamp", "mirror"):
                for scale in ((1.0, 1.0), (2.0, 3.0), (-1.5, 0.75)):
                    table = f'{{ texture = "t.exr", wrap = "{wrap}", scale = [{scale[0]}, {scale[1]}] }}'
                    _check_lookups(tmp, mesh_file, table, texels, scale, wrap, 1e-5)
        _check_lookups(tmp, "quad.obj", '{ texture = "t.png", scale = [2, -2] }', _srgb_to_linear(png / 255.0),
                       (2.0, -2.0), "repeat", 2e-3)
        _check_lookups(tmp, "quad.obj", '{ texture = "t.png", linear = true, wrap = "mirror" }', png / 255.0,
                       (1.0, 1.0), "mirror", 1e-5)
        _check_lookups(tmp, "quad.ply", '{ texture = "t.exr", wrap = "mirror", scale = [2, 0.5] }', texels,
                       (2.0, 0.5), "mirror", 1e-5, via_xml=True)


def test_roughness_texture_becomes_an_alpha_bitmap():
    """A roughness texture: the chosen channel, decoded as vkrt decodes it,
    interpolated as vkrt interpolates roughness, then squared (GGX alpha)."""
    _need(mi, "mitsuba")
    if mi.variant() is None:
        mi.set_variant("scalar_rgb")
    rng = np.random.default_rng(5)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        (tmp / "quad.obj").write_text(_uv_quad_obj())
        rgba = rng.integers(0, 256, (4, 6, 4))
        _write_texture(tmp / "r.png", rgba)
        cases = [('channel = "g", linear = true', rgba[..., 1] / 255.0),
                 ('channel = "b"', _srgb_to_linear(rgba[..., 2] / 255.0)),
                 ('channel = "a"', rgba[..., 3] / 255.0),  # alpha is never sRGB
                 ('', _srgb_to_linear(rgba[..., 0] / 255.0))]  # default channel "r"
        for wrap in ("repeat", "clamp", "mirror"):
            for keys, roughness in cases:
                for mtype in ("conductor", "rough_dielectric"):
                    extra = f', {keys}' if keys else ""
                    table = f'{{ texture = "r.png", wrap = "{wrap}", scale = [1.5, 2]{extra} }}'
                    d = to_mitsuba.convert(_texture_scene(tmp, f'type = "{mtype}"\nroughness = {table}\n'),
                                           files_dir=tmp / "files")
                    bsdf = d["mat0"]["bsdf"] if mtype == "conductor" else d["mat0"]
                    assert bsdf["type"] in ("roughconductor", "roughdielectric"), bsdf
                    alpha = mi.load_dict(bsdf["alpha"])
                    assert alpha.is_spatially_varying()
                    uv = rng.uniform(-1, 2, (300, 2))
                    got = []
                    for u, v in uv:
                        si = mi.SurfaceInteraction3f()
                        si.uv = mi.Point2f(float(u), 1.0 - float(v))  # as Mitsuba's flipped OBJ delivers
                        got.append(float(np.array(alpha.eval_1(si)).ravel()[0]))
                    r = _vkrt_lookup(roughness[..., None], uv, (1.5, 2.0), wrap)[..., 0]
                    expected = np.maximum(r * r, 1e-4)
                    # Exact at the 7x finer texel centres; in between about (dr)^2 / (4 * 49).
                    dr = np.abs(np.diff(roughness, axis=0)).max() + np.abs(np.diff(roughness, axis=1)).max()
                    tol = dr * dr / 196 + 1e-6
                    err = np.abs(np.array(got) - expected).max()
                    assert err < tol, (wrap, keys, mtype, err, tol)


def test_smooth_textured_mesh_keeps_its_uvs():
    """normals = "smooth": the converter's own PLY carries the uvs, split at
    the seam (one position, two uvs), with one normal per position."""
    _need(mi, "mitsuba")
    if mi.variant() is None:
        mi.set_variant("scalar_rgb")
    # Two triangles folded along the shared edge 1-3 (a roof), whose shared
    # vertices have different uvs on either side.
    obj = ("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 1\n"
           "vt 0 0\nvt 0.5 0\nvt 0.5 1\nvt 0.6 0\nvt 0.6 1\nvt 1 1\n"
           "f 1/1 2/2 4/3\nf 2/4 3/6 4/5\n")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        (tmp / "roof.obj").write_text(obj)
        _write_texture(tmp / "t.exr", np.zeros((2, 2, 3)))
        path = _write(tmp, HEADER + '[materials.clay]\ntype = "lambert"\nalbedo = { texture = "t.exr" }\n'
                      '[[objects]]\nshape = "mesh"\nfile = "roof.obj"\nmaterial = "clay"\nnormals = "smooth"\n')
        d = to_mitsuba.convert(path, files_dir=tmp / "files")
        shape = d["object0"]
        assert shape["type"] == "ply" and shape["flip_tex_coords"] is True
        mesh = mi.load_dict({"type": "ply", "filename": shape["filename"], "flip_tex_coords": False})
        p = np.array(mesh.vertex_positions_buffer()).reshape(-1, 3)
        uv = np.array(mesh.vertex_texcoords_buffer()).reshape(-1, 2)
        n = np.array(mesh.vertex_normals_buffer()).reshape(-1, 3)
    assert len(p) == 6  # vertices 2 and 4 split at the seam
    by_uv = {(round(float(a), 3), round(float(b), 3)): (tuple(float(x) for x in q), m)
             for a, b, q, m in zip(uv[:, 0], uv[:, 1], p, n)}
    assert by_uv[(0.5, 0.0)][0] == by_uv[(0.6, 0.0)][0] == (1.0, 0.0, 0.0)
    assert by_uv[(0.5, 1.0)][0] == by_uv[(0.6, 1.0)][0] == (0.0, 1.0, 1.0)
    # Both copies of a split vertex keep the one smooth normal of its position.
    assert np.allclose(by_uv[(0.5, 0.0)][1], by_uv[(0.6, 0.0)][1])
    # Face cross products cross((1, 0, 0), (0, 1, 1)) = (0, -1, 1) and cross((0, 1, 0), (-1, 1, 1)) = (1, 0, 1).
    assert np.allclose(by_uv[(0.5, 0.0)][1], np.array([1, -1, 2]) / np.sqrt(6), atol=1e-6)


def test_textured_quad_renders_upright():
    """Render check of the orientation: a texture of 2 x 2 coloured blocks on a
    quad facing the camera under a white background (a lambert surface then
    shows its albedo) appears as in the file: top-left block at the top left."""
    _need(mi, "mitsuba")
    if mi.variant() is None:
        mi.set_variant("scalar_rgb")
    colours = np.array([[[0.8, 0.1, 0.1], [0.1, 0.8, 0.1]], [[0.1, 0.1, 0.8], [0.8, 0.8, 0.1]]])  # row 0 = top
    quad = "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n"
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        (tmp / "quad.obj").write_text(quad)
        _write_texture(tmp / "t.exr", np.kron(colours, np.ones((2, 2, 1))))  # 4 x 4 texels
        img = _render(tmp, """
            [render]
            integrator = "path"
            max_depth = 1
            [camera]
            eye = [0.0, 0.0, 2.0]
            target = [0.0, 0.0, 0.0]
            fov = 40
            width = 8
            height = 8
            [materials.t]
            type = "lambert"
            albedo = { texture = "t.exr", wrap = "clamp" }
            [[objects]]
            shape = "mesh"
            file = "quad.obj"
            material = "t"
            [background]
            color = 1.0
            """, 1024)
    # The quad fills the view (2 tan 20 deg < 1); pixels 0, 1 and 6, 7 of each axis see
    # |x|, |y| > 0.36, beyond the texel centres at +-0.25 where the bilinear filter blends blocks.
    for row, rows in enumerate(((0, 2), (6, 8))):
        for col, cols in enumerate(((0, 2), (6, 8))):
            mean = img[rows[0]:rows[1], cols[0]:cols[1]].mean((0, 1))
            assert np.allclose(mean, colours[row, col], atol=0.03), (row, col, mean)


# ----------------------------------------------------------------------------
# Thin lens, directional and spot lights, lat-long environments. The scenes are
# hand-made exports (docs/scene-json.md and the keys these features add),
# given to convert() in place of `vkrt info SCENE --scene-json -`.
# ----------------------------------------------------------------------------

def _export(**parts):
    """An export of an empty 8 x 6 scene whose camera at z = 5 looks at the
    origin; `parts` replace top-level keys."""
    scene = {
        "format": "vkrt-scene", "version": 1,
        "scene": {"path": "/nowhere/scene.toml", "hash": "fnv1a64:0000000000000000"},
        "render": {"integrator": "path", "max_depth": 1},
        "camera": {"eye": [0.0, 0.0, 5.0], "target": [0.0, 0.0, 0.0], "up": [0.0, 1.0, 0.0], "fov": 30.0,
                   "width": 8, "height": 6, "aperture_radius": 0.0, "focus_distance": 5.0},
        "materials": [],
        "shapes": {"sphere": [], "box": [], "triangle": [], "plane": [], "mesh": []},
        "lights": {"point": [], "triangle": [], "directional": [], "spot": []},
        "background": {"color": [0.0, 0.0, 0.0], "cubemap": None, "environment": None},
        "textures": [],
        "warnings": [],
    }
    scene.update(copy.deepcopy(parts))
    return scene


def _lights(**kinds):
    return dict(_export()["lights"], **kinds)


def _convert_export(export: dict, tmp: Path) -> dict:
    """convert() of tmp/scene.toml as if vkrt exported `export` for it."""
    real = to_mitsuba.read_scene_json
    to_mitsuba.read_scene_json = lambda path, vkrt=None: copy.deepcopy(export)
    try:
        return to_mitsuba.convert(tmp / "scene.toml", files_dir=tmp / "files")
    finally:
        to_mitsuba.read_scene_json = real


def _export_refusal(export: dict, key: str, fragment: str = "") -> str:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "scene.toml"
        try:
            _convert_export(export, Path(tmp))
        except to_mitsuba.ConversionError as e:
            message = str(e)
        else:
            raise AssertionError(f"converted: {key}")
    assert f"{path}: {key}: " in message and fragment in message, message
    return message


# A lambert floor (the top of a box at y = 0) that fills the view of FLOOR_CAMERA.
FLOOR_ALBEDO = [0.8, 0.5, 0.25]
FLOOR = {"materials": [{"name": "floor", "type": "lambert", "albedo": FLOOR_ALBEDO, "textures": {},
                        "where": "scene.toml:10:1"}],
         "shapes": {"sphere": [], "box": [{"min": [-50.0, -1.0, -50.0], "max": [50.0, 0.0, 50.0], "material": 0}],
                    "triangle": [], "plane": [], "mesh": []},
         "camera": {"eye": [0.5, 4.0, 1.0], "target": [0.0, 0.0, 0.0], "up": [0.0, 1.0, 0.0], "fov": 30.0,
                    "width": 8, "height": 6, "aperture_radius": 0.0, "focus_distance": 4.15}}


def _mitsuba_scalar():
    _need(mi, "mitsuba")
    if mi.variant() is None:
        mi.set_variant("scalar_rgb")


def _unit(v):
    v = np.asarray(v, np.float64)
    return v / np.linalg.norm(v)


def test_thin_lens_camera_is_mitsubas_thinlens():
    """aperture_radius > 0: `thinlens` with vkrt's aperture_radius and
    focus_distance, which Mitsuba measures as vkrt does: the rays through one
    film point leave a disc of that radius across the viewing direction and
    meet the pinhole ray on the plane focus_distance ahead along it, off axis
    too. aperture_radius 0, or an export without the keys: `perspective`."""
    _mitsuba_scalar()
    cam = dict(_export()["camera"], eye=[1.0, 2.0, 3.0], target=[2.0, 1.0, -4.0], fov=60.0, aperture_radius=0.25,
               focus_distance=4.0)
    old = _export()
    del old["camera"]["aperture_radius"], old["camera"]["focus_distance"]
    with tempfile.TemporaryDirectory() as tmp:
        sensor = _convert_export(_export(camera=cam), Path(tmp))["sensor"]
        pinhole = _convert_export(_export(), Path(tmp))["sensor"]
        older = _convert_export(old, Path(tmp))["sensor"]
        xml_scene = _convert_export(_export(camera=cam), Path(tmp))
        to_mitsuba.write_xml(xml_scene, Path(tmp) / "scene.xml")
        from_xml = mi.load_file(str(Path(tmp) / "scene.xml")).sensors()[0]
    assert sensor["type"] == "thinlens" and sensor["aperture_radius"] == 0.25 and sensor["focus_distance"] == 4.0
    assert sensor["fov"] == 60.0 and sensor["fov_axis"] == "y", sensor
    for s in (pinhole, older):
        assert s["type"] == "perspective" and "aperture_radius" not in s and "focus_distance" not in s, s
    camera = mi.load_dict(sensor)
    reference = mi.load_dict({k: v for k, v in sensor.items() if k not in ("aperture_radius", "focus_distance")}
                             | {"type": "perspective"})
    eye = np.array(cam["eye"])
    forward = _unit(np.array(cam["target"]) - eye)
    lens_samples = np.random.default_rng(4).uniform(0, 1, (12, 2))
    widest = 0.0
    for film in ((0.5, 0.5), (0.05, 0.9), (0.8, 0.2)):
        ray, _ = reference.sample_ray(0.0, 0.5, mi.Point2f(*film), mi.Point2f(0.5, 0.5))
        d = np.array(ray.d, np.float64)
        in_focus = eye + d * 4.0 / (d @ forward)
        for cam_ in (camera, from_xml):
            for lens in lens_samples:
                ray, _ = cam_.sample_ray(0.0, 0.5, mi.Point2f(*film), mi.Point2f(*lens))
                o, d = np.array(ray.o, np.float64), np.array(ray.d, np.float64)
                on_lens = o - d * ((o - eye) @ forward) / (d @ forward)  # Mitsuba starts rays at the near clip
                radius = np.linalg.norm(on_lens - eye)
                assert radius <= 0.25 + 1e-6, radius
                widest = max(widest, radius)
                hit = o + d * (4.0 - (o - eye) @ forward) / (d @ forward)
                assert np.allclose(hit, in_focus, atol=1e-5), (film, lens, hit, in_focus)
    assert widest > 0.2, widest


def test_directional_light_is_mitsubas_directional():
    """angle 0: `directional`, the direction light travels and the irradiance.
    A lambert floor lit at 36.87 degrees from its normal shows
    albedo · E · cos / pi in every pixel (dict and XML)."""
    _mitsuba_scalar()
    direction, irradiance = [0.6, -0.8, 0.0], [2.0, 1.0, 0.5]
    export = _export(**FLOOR, lights=_lights(directional=[{"direction": direction, "irradiance": irradiance,
                                                          "angle": 0.0}]))
    with tempfile.TemporaryDirectory() as tmp:
        d = _convert_export(export, Path(tmp))
        assert d["light0"] == {"type": "directional", "direction": direction,
                               "irradiance": {"type": "rgb", "value": irradiance}}, d["light0"]
        img = np.array(mi.render(mi.load_dict(d), spp=4), np.float64)
        to_mitsuba.write_xml(d, Path(tmp) / "scene.xml")
        img_xml = np.array(mi.render(mi.load_file(str(Path(tmp) / "scene.xml")), spp=4), np.float64)
    expected = np.array(FLOOR_ALBEDO) * np.array(irradiance) * 0.8 / math.pi
    for image in (img, img_xml):
        assert np.allclose(image, expected, rtol=1e-4, atol=0), (image.min((0, 1)), image.max((0, 1)), expected)


def test_soft_directional_light_is_refused():
    """A sun disc (angle > 0) has no Mitsuba emitter; refused before Mitsuba is needed."""
    sun = {"direction": [0.0, -1.0, 0.0], "irradiance": [1.0, 1.0, 1.0], "angle": 0.53}
    message = _export_refusal(_export(lights=_lights(directional=[dict(sun, angle=0.0), sun])),
                              "lights.directional[1].angle", "angle = 0.53")
    assert "delta" in message, message


def _spot_factor(emitter, position, point):
    """The spot's intensity towards `point`, times distance² (W/sr)."""
    it = mi.Interaction3f()
    it.p = mi.Point3f(*[float(x) for x in point])
    ds, weight = emitter.sample_direction(it, mi.Point2f(0.5, 0.5))
    assert np.allclose(np.array(ds.p, np.float64), position, atol=1e-6)
    return np.array(weight, np.float64).ravel() * float(np.sum((np.asarray(point) - position) ** 2))


def test_spot_light_hard_cone_is_mitsubas_spot():
    """inner = outer cone angle: `spot` with beam_width = cutoff_angle, which in
    Mitsuba is a hard cone (its linear ramp from beam_width to cutoff_angle is
    empty): the full intensity up to the cone angle, nothing beyond, around an
    axis along `direction` from `position` (dict and XML)."""
    _mitsuba_scalar()
    position, axis, intensity, cone = np.array([1.0, 2.0, -0.5]), _unit([0.3, -1.0, 0.2]), [3.0, 2.0, 1.0], 25.0
    spot = {"position": position.tolist(), "direction": axis.tolist(), "intensity": intensity,
            "inner_cone_angle": cone, "outer_cone_angle": cone}
    with tempfile.TemporaryDirectory() as tmp:
        d = _convert_export(_export(lights=_lights(spot=[spot])), Path(tmp))
        to_mitsuba.write_xml(d, Path(tmp) / "scene.xml")
        from_xml = mi.load_file(str(Path(tmp) / "scene.xml")).emitters()[0]
    light = d["light0"]
    assert light["type"] == "spot" and light["cutoff_angle"] == light["beam_width"] == cone, light
    assert light["intensity"] == {"type": "rgb", "value": intensity}, light
    m = np.array(light["to_world"].matrix, np.float64)
    assert np.allclose(m[:3, :3].T @ m[:3, :3], np.eye(3), atol=1e-6) and np.linalg.det(m[:3, :3]) > 0, m
    assert np.allclose(m[:3, 2], axis, atol=1e-6) and np.allclose(m[:3, 3], position), m
    across = (_unit(np.cross(axis, [1.0, 0.0, 0.0])), _unit(np.cross(axis, [0.0, 0.0, 1.0])))
    for emitter in (mi.load_dict(light), from_xml):
        for angle, inside in ((0.0, 1), (10.0, 1), (24.9, 1), (24.99, 1), (25.01, 0), (26.0, 0), (60.0, 0),
                              (120.0, 0)):
            for side in across:
                a = math.radians(angle)
                point = position + 2.5 * (math.cos(a) * axis + math.sin(a) * side)
                got = _spot_factor(emitter, position, point)
                assert np.allclose(got, np.array(intensity) * inside, rtol=1e-4, atol=1e-6), (angle, got)


def test_spot_light_with_soft_edge_is_refused():
    """inner < outer cone angle: vkrt's falloff between the cones is glTF's,
    t² with t linear in the cosine; Mitsuba's spot ramps linearly in the angle.
    Refused before Mitsuba is needed; where Mitsuba is installed, the two
    falloffs are shown to differ."""
    spot = {"position": [0.0, 1.0, 0.0], "direction": [0.0, -1.0, 0.0], "intensity": [1.0, 1.0, 1.0],
            "inner_cone_angle": 20.0, "outer_cone_angle": 30.0}
    hard = dict(spot, inner_cone_angle=30.0)
    _export_refusal(_export(lights=_lights(spot=[hard, spot])), "lights.spot[1].inner_cone_angle", "glTF")
    if mi is None:
        return
    _mitsuba_scalar()
    emitter = mi.load_dict({"type": "spot", "cutoff_angle": 30.0, "beam_width": 20.0})  # looks along +z
    a = math.radians(25.0)
    mitsuba = _spot_factor(emitter, np.zeros(3), [math.sin(a), 0.0, math.cos(a)])[0]
    c = [math.cos(math.radians(x)) for x in (25.0, 20.0, 30.0)]
    gltf = ((c[0] - c[2]) / (c[1] - c[2])) ** 2
    assert abs(mitsuba - 0.5) < 1e-4 and abs(gltf - 0.299) < 1e-3, (mitsuba, gltf)


def _latlong_lookup(texels, d):
    """vkrt's lat-long lookup of texels (h x w x 3, row 0 the +y pole) in map
    directions d[..., 3]: column i at u = (i + 0.5) / w, row j at v = j / (h - 1),
    direction (sin φ sin θ, cos θ, −cos φ sin θ) for φ = 2πu, θ = πv, bilinear,
    wrapping in u."""
    h, w = texels.shape[:2]
    d = d / np.linalg.norm(d, axis=-1, keepdims=True)
    u = np.mod(np.arctan2(d[..., 0], -d[..., 2]) / (2 * np.pi), 1.0)
    v = np.arccos(np.clip(d[..., 1], -1.0, 1.0)) / np.pi
    x = u * w - 0.5
    y = v * (h - 1)
    x0 = np.floor(x).astype(np.int64)
    y0 = np.minimum(np.floor(y).astype(np.int64), h - 2)
    fx, fy = (x - x0)[..., None], (y - y0)[..., None]
    xa, xb = np.mod(x0, w), np.mod(x0 + 1, w)
    top = (1 - fx) * texels[y0, xa] + fx * texels[y0, xb]
    bottom = (1 - fx) * texels[y0 + 1, xa] + fx * texels[y0 + 1, xb]
    return (1 - fy) * top + fy * bottom


def _rotation(axis, degrees):
    """Right-handed rotation about `axis` (rows)."""
    k = _unit(axis)
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    a = math.radians(degrees)
    return np.eye(3) + math.sin(a) * kx + (1 - math.cos(a)) * kx @ kx


def test_latlong_environment_is_mitsubas_envmap():
    """A lat-long map: `envmap` of the file with to_world = vkrt's rotation; a
    grey scale is its `scale`, a coloured one is applied to the image. The
    converted emitter's radiance in a world direction w is scale times vkrt's
    bilinear lookup of the map at matrix⁻¹ w (random texels on an odd,
    non-square map: a half-texel or row convention error shows), from the dict
    and from the XML."""
    _mitsuba_scalar()
    rng = np.random.default_rng(8)
    texels = rng.uniform(0.1, 1.0, (5, 7, 3)).astype(np.float32)
    texels[0], texels[-1] = texels[0, 0], texels[-1, 0]  # a pole is one direction: its row is one colour
    rotation = _rotation([1.0, 2.0, 3.0], 40.0)
    directions = [_unit(v) for v in rng.normal(size=(300, 3))]
    # The poles, and the seam u = 0 (between the last column and the first).
    directions += [rotation @ [0.0, 1.0, 0.0], rotation @ [0.0, -1.0, 0.0], rotation @ [0.0, 0.0, -1.0]]
    directions = np.array(directions)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        sky = tmp / "sky.exr"
        mi.Bitmap(texels, mi.Bitmap.PixelFormat.RGB).write(str(sky))
        for scale in ([2.0, 2.0, 2.0], [0.5, 1.0, 3.0]):
            environment = {"file": str(sky), "scale": scale, "matrix": rotation.tolist()}
            d = _convert_export(_export(background={"color": [0.0, 0.0, 0.0], "cubemap": None,
                                                    "environment": environment}), tmp)
            env = d["environment"]
            assert env["type"] == "envmap" and sum(v.get("type") in ("envmap", "constant") for v in d.values()
                                                   if isinstance(v, dict)) == 1, d
            if scale[0] == scale[1] == scale[2]:
                assert env["filename"] == str(sky) and env["scale"] == 2.0, env
            else:
                assert "scale" not in env and Path(env["filename"]).parent == (tmp / "files").resolve(), env
            m = np.array(env["to_world"].matrix, np.float64)
            assert np.allclose(m[:3, :3], rotation, atol=1e-6) and np.allclose(m[:3, 3], 0) and m[3, 3] == 1, m
            to_mitsuba.write_xml(d, tmp / "scene.xml")
            from_xml = mi.load_file(str(tmp / "scene.xml")).emitters()[0]
            expected = np.array(scale) * _latlong_lookup(texels.astype(np.float64), directions @ rotation)
            for emitter in (mi.load_dict(env), from_xml):
                got = []
                for w in directions:
                    si = mi.SurfaceInteraction3f()
                    si.wi = mi.Vector3f(*(-w))
                    got.append(np.array(emitter.eval(si), np.float64).ravel())
                err = np.abs(np.array(got) - expected).max()
                assert err < 2e-5 * max(scale), (scale, err)


def test_latlong_hdr_reads_as_stb_image_decodes_it():
    """A Radiance .hdr map: Mitsuba decodes RGBE as stb_image (vkrt's decoder)
    does, mantissa · 2^(exponent − 136) without Ward's + 0.5, whether the
    envmap reads the file (grey scale) or the converter does (coloured scale).
    Checked at texel centres, where the lookup is the texel itself."""
    _mitsuba_scalar()
    w, h = 6, 4
    rng = np.random.default_rng(9)
    # Ward's + 0.5 would change these mantissas by 0.2 % or more.
    rgbe = np.concatenate([rng.integers(64, 256, (h, w, 3)), rng.integers(127, 131, (h, w, 1))], -1).astype(np.uint8)
    rgbe[0], rgbe[-1] = rgbe[0, 0], rgbe[-1, 0]  # one colour per pole
    stb = rgbe[..., :3] * np.exp2(rgbe[..., 3:].astype(np.float64) - 136)
    phi = 2 * np.pi * (np.arange(w) + 0.5) / w
    theta = np.pi * np.arange(h) / (h - 1)
    d = np.stack(np.broadcast_arrays(np.sin(phi) * np.sin(theta[:, None]), np.cos(theta[:, None]) + 0 * phi,
                                     -np.cos(phi) * np.sin(theta[:, None])), -1)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        sky = tmp / "sky.hdr"
        # Flat (uncompressed) scanlines: width < 8.
        sky.write_bytes(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (h, w) + rgbe.tobytes())
        for scale in ([1.5, 1.5, 1.5], [0.5, 1.0, 3.0]):
            environment = {"file": str(sky), "scale": scale, "matrix": np.eye(3).tolist()}
            d_env = _convert_export(_export(background={"color": [0.0, 0.0, 0.0], "cubemap": None,
                                                        "environment": environment}), tmp)["environment"]
            emitter = mi.load_dict(d_env)
            for j in range(h):
                for i in range(w):
                    si = mi.SurfaceInteraction3f()
                    si.wi = mi.Vector3f(*(-d[j, i]))
                    got = np.array(emitter.eval(si), np.float64).ravel()
                    expected = np.array(scale) * stb[j, i]
                    assert np.allclose(got, expected, rtol=1e-4, atol=0), (scale, j, i, got, expected)


def test_latlong_environment_lights_a_lambert_floor():
    """A constant-colour lat-long map c with a coloured scale s over a lambert
    floor (max_depth = 1: direct light only): the floor shows albedo · c · s,
    whatever the rotation."""
    _mitsuba_scalar()
    c, s = np.array([0.2, 0.4, 0.8]), np.array([0.5, 1.0, 3.0])
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        sky = tmp / "sky.exr"
        mi.Bitmap(np.broadcast_to(c, (9, 16, 3)).astype(np.float32), mi.Bitmap.PixelFormat.RGB).write(str(sky))
        environment = {"file": str(sky), "scale": s.tolist(), "matrix": _rotation([0.0, 1.0, 1.0], 70.0).tolist()}
        d = _convert_export(_export(**FLOOR, background={"color": [0.0, 0.0, 0.0], "cubemap": None,
                                                          "environment": environment}), tmp)
        runs = np.array([np.array(mi.render(mi.load_dict(d), spp=256, seed=k), np.float64).mean((0, 1))
                         for k in range(4)])
    expected = np.array(FLOOR_ALBEDO) * c * s
    got = runs.mean(0)
    tol = 5 * runs.std(0, ddof=1) / np.sqrt(len(runs)) + 1e-4 * expected
    assert np.all(np.abs(got - expected) < tol) and np.all(tol < 0.01 * expected), (got, expected, tol)


def test_thin_lens_lights_and_environment_through_vkrt():
    """The same conversions from a scene file, as vkrt exports it (its key
    names, the rotation as rows), and its refusals located in the file."""
    _mitsuba_scalar()
    header = HEADER.replace("height = 6\n", "height = 6\naperture_radius = 0.1\nfocus_distance = 4\n")
    lights = textwrap.dedent("""
        [[lights]]
        type = "directional"
        direction = [0.0, -1.0, 0.0]
        irradiance = [2.0, 1.0, 0.5]
        [[lights]]
        type = "spot"
        position = [0.0, 3.0, 0.0]
        direction = [0.0, -1.0, 0.0]
        intensity = 5
        inner_cone_angle = 20
        outer_cone_angle = 20
        """)
    environment = textwrap.dedent("""
        [background.environment]
        file = "sky.exr"
        scale = [1.0, 2.0, 3.0]
        rotate = { axis = [0, 1, 0], angle = 90 }
        """)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        mi.Bitmap(np.ones((4, 8, 3), np.float32), mi.Bitmap.PixelFormat.RGB).write(str(tmp / "sky.exr"))
        d = to_mitsuba.convert(_write(tmp, header + lights + environment), files_dir=tmp / "files")
        sensor, sun, spot, env = d["sensor"], d["light0"], d["light1"], d["environment"]
        assert sensor["type"] == "thinlens" and sensor["aperture_radius"] == 0.1 and sensor["focus_distance"] == 4.0
        assert sun == {"type": "directional", "direction": [0.0, -1.0, 0.0],
                       "irradiance": {"type": "rgb", "value": [2.0, 1.0, 0.5]}}, sun
        assert spot["type"] == "spot" and spot["cutoff_angle"] == spot["beam_width"] == 20.0, spot
        m = np.array(spot["to_world"].matrix, np.float64)
        assert np.allclose(m[:3, 2], [0, -1, 0]) and np.allclose(m[:3, 3], [0, 3, 0]), m
        # 90 degrees about +y: the map's +x is the world's -z, its +z the world's +x.
        m = np.array(env["to_world"].matrix, np.float64)
        assert np.allclose(m[:3, :3], [[0, 0, 1], [0, 1, 0], [-1, 0, 0]], atol=1e-12), m
        assert env["type"] == "envmap" and "scale" not in env, env
        scaled = mi.Bitmap(env["filename"])
        assert np.allclose(np.array(scaled), [1.0, 2.0, 3.0]), np.array(scaled)[0, 0]
        # Pinhole by default; no environment, no emitter.
        d = to_mitsuba.convert(_write(tmp, HEADER + lights), files_dir=tmp / "files")
        assert d["sensor"]["type"] == "perspective" and "environment" not in d
        soft_sun = lights.replace("irradiance = [2.0, 1.0, 0.5]\n", "irradiance = [2.0, 1.0, 0.5]\nangle = 0.5\n")
        _expect_refusal(_write(tmp, HEADER + soft_sun), "lights.directional[0].angle")
        soft_spot = lights.replace("inner_cone_angle = 20", "inner_cone_angle = 10")
        _expect_refusal(_write(tmp, HEADER + soft_spot), "lights.spot[0].inner_cone_angle")


def _expect_refusal(path: Path, key: str) -> str:
    try:
        to_mitsuba.convert(path, files_dir=path.parent / "files")
    except to_mitsuba.ConversionError as e:
        message = str(e)
    else:
        raise AssertionError(f"converted {path.read_text()}")
    assert f"{path}: {key}: " in message, message
    return message


if __name__ == "__main__":
    _STANDALONE = True
    failures = 0
    for name, fn in list(globals().items()):
        if name.startswith("test_") and callable(fn):
            try:
                fn()
                print(f"PASS {name}")
            except Skip as e:
                print(f"SKIP {name}: {e}")
            except Exception as e:  # noqa: BLE001
                failures += 1
                print(f"FAIL {name}: {type(e).__name__}: {e}")
    sys.exit(1 if failures else 0)

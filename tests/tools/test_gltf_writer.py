"""Checks of tools/gltf_writer.py (vkrt's glTF 2.0 writer) and of the scenes it
ships in scenes/gltf/. Python 3.11 standard library only:

    python3 tests/tools/test_gltf_writer.py            # no pytest needed
    python3 -m pytest tests/tools/test_gltf_writer.py  # if pytest is installed

The files are read back independently of the writer: JSON (no key twice),
.glb chunks, base64 buffers, PNG chunks; accessor bounds and byte lengths
are checked against glTF 2.0's rules, extensionsUsed against every
extension the file names, and lights-camera.toml's camera, lights and
matrices against world matrices computed here from the node hierarchy.
With $VKRT naming a vkrt binary, each scene is also loaded by `vkrt info`
(material = "file"); without it that check is skipped.
"""
from __future__ import annotations

import base64
import json
import math
import os
import struct
import subprocess
import sys
import tempfile
import tomllib
import zlib
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
SCENES = REPO / "scenes" / "gltf"
sys.path.insert(0, str(REPO / "tools"))

import gltf_writer as gw  # noqa: E402

SHIPPED_GLTF = ["lights-camera.gltf", "transmission.gltf", "texture-transform.gltf",
                "texture-transform-baked.gltf"]


class Skip(Exception):
    pass


_STANDALONE = False  # set when run as a script


def _skip(reason: str):
    if _STANDALONE:
        raise Skip(reason)
    import pytest

    pytest.skip(reason)


_written: dict[str, Path] = {}


def _fresh() -> Path:
    """The scenes written once into a temporary folder (with .glb copies)."""
    if "dir" not in _written:
        out = Path(tempfile.mkdtemp(prefix="gltf-writer-test-"))
        gw.write_scenes(out, glb=True)
        _written["dir"] = out
    return _written["dir"]


# ---------------------------------------------------------------------------
# Reading files back


def _no_duplicates(pairs):
    keys = [k for k, _ in pairs]
    assert len(keys) == len(set(keys)), f"a JSON object has a key twice: {keys}"
    return dict(pairs)


def load(path: Path) -> tuple[dict, list[bytes]]:
    """The JSON document and the bytes of each of its buffers."""
    raw = path.read_bytes()
    if raw[:4] == b"glTF":
        magic, version, length = struct.unpack_from("<4sII", raw, 0)
        assert version == 2 and length == len(raw), (version, length, len(raw))
        chunks, offset = [], 12
        while offset < len(raw):
            size, kind = struct.unpack_from("<I4s", raw, offset)
            assert size % 4 == 0, f"chunk {kind} of {size} bytes is not padded to 4"
            chunks.append((kind, raw[offset + 8:offset + 8 + size]))
            offset += 8 + size
        assert offset == len(raw)
        assert chunks[0][0] == b"JSON" and all(k == b"BIN\0" for k, _ in chunks[1:]) and len(chunks) <= 2
        text = chunks[0][1]
        assert text.rstrip(b" ") == text.rstrip(), "the JSON chunk is padded with spaces only"
        doc = json.loads(text.decode("utf-8"), object_pairs_hook=_no_duplicates)
        bin_chunk = chunks[1][1] if len(chunks) > 1 else None
    else:
        doc = json.loads(raw.decode("utf-8"), object_pairs_hook=_no_duplicates)
        bin_chunk = None
    buffers = []
    for i, buffer in enumerate(doc.get("buffers", [])):
        uri = buffer.get("uri")
        if uri is None:
            assert i == 0 and bin_chunk is not None, "only a .glb's first buffer may lack a uri"
            assert buffer["byteLength"] <= len(bin_chunk) <= buffer["byteLength"] + 3
            data = bin_chunk[:buffer["byteLength"]]
        else:
            prefix = "data:application/octet-stream;base64,"
            assert uri.startswith(prefix), f"buffer {i}: expected an embedded base64 buffer"
            data = base64.b64decode(uri[len(prefix):], validate=True)
            assert len(data) == buffer["byteLength"], (len(data), buffer["byteLength"])
        buffers.append(data)
    return doc, buffers


COMPONENTS = {5120: ("b", 1), 5121: ("B", 1), 5122: ("h", 2), 5123: ("H", 2), 5125: ("I", 4), 5126: ("f", 4)}
WIDTHS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}


def accessor_values(doc: dict, buffers: list[bytes], index: int) -> list[tuple]:
    """An accessor's elements, checked to lie inside its bufferView and buffer."""
    a = doc["accessors"][index]
    fmt, size = COMPONENTS[a["componentType"]]
    width = WIDTHS[a["type"]]
    view = doc["bufferViews"][a["bufferView"]]
    stride = view.get("byteStride", size * width)
    start = view.get("byteOffset", 0) + a.get("byteOffset", 0)
    assert start % size == 0, f"accessor {index} is not aligned to its component size"
    assert a.get("byteOffset", 0) + (a["count"] - 1) * stride + size * width <= view["byteLength"], \
        f"accessor {index} overruns bufferView {a['bufferView']}"
    data = buffers[view["buffer"]]
    return [struct.unpack_from(f"<{width}{fmt}", data, start + i * stride) for i in range(a["count"])]


def extension_names(value) -> set[str]:
    names: set[str] = set()
    if isinstance(value, dict):
        for key, each in value.items():
            if key == "extensions":
                assert isinstance(each, dict)
                names.update(each)
            names |= extension_names(each)
    elif isinstance(value, list):
        for each in value:
            names |= extension_names(each)
    return names


# ---------------------------------------------------------------------------
# Independent transforms (row-major 4x4)


def quat_matrix(q) -> list[list[float]]:
    x, y, z, w = q
    return [[1 - 2 * y * y - 2 * z * z, 2 * x * y - 2 * w * z, 2 * x * z + 2 * w * y],
            [2 * x * y + 2 * w * z, 1 - 2 * x * x - 2 * z * z, 2 * y * z - 2 * w * x],
            [2 * x * z - 2 * w * y, 2 * y * z + 2 * w * x, 1 - 2 * x * x - 2 * y * y]]


def local_matrix(node: dict) -> list[list[float]]:
    if "matrix" in node:
        m = node["matrix"]
        return [[m[c * 4 + r] for c in range(4)] for r in range(4)]
    t = node.get("translation", [0, 0, 0])
    s = node.get("scale", [1, 1, 1])
    r = quat_matrix(node.get("rotation", [0, 0, 0, 1]))
    return [[r[i][0] * s[0], r[i][1] * s[1], r[i][2] * s[2], t[i]] for i in range(3)] + [[0, 0, 0, 1]]


def multiply(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(4)) for j in range(4)] for i in range(4)]


def world_matrices(doc: dict) -> dict[int, list[list[float]]]:
    out = {}

    def visit(node, parent):
        out[node] = multiply(parent, local_matrix(doc["nodes"][node]))
        for child in doc["nodes"][node].get("children", []):
            visit(child, out[node])

    identity = [[1.0 if i == j else 0.0 for j in range(4)] for i in range(4)]
    for root in doc["scenes"][doc.get("scene", 0)]["nodes"]:
        visit(root, identity)
    return out


def column(m, j, w=0.0):
    """m applied to the unit vector j (w = 1: to the origin)."""
    v = [0.0, 0.0, 0.0]
    if j is not None:
        v[abs(j) - 1] = math.copysign(1.0, j)
    return [m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2] + m[i][3] * w for i in range(3)]


def unit(v):
    n = math.sqrt(sum(c * c for c in v))
    return [c / n for c in v]


def close(a, b, tol=1e-12) -> bool:
    return all(abs(x - y) <= tol * max(1.0, abs(y)) for x, y in zip(a, b, strict=True))


# ---------------------------------------------------------------------------
# glTF 2.0 rules


def validate(doc: dict, buffers: list[bytes]) -> None:
    """The glTF 2.0 rules the writer is responsible for (what the Khronos
    validator reports as errors, and its warnings about unused data)."""
    assert doc["asset"]["version"] == "2.0"
    for key in ("extensionsRequired",):
        assert set(doc.get(key, [])) <= set(doc.get("extensionsUsed", []))
    used = set(doc.get("extensionsUsed", []))
    named = extension_names(doc)
    assert used == named, f"extensionsUsed {sorted(used)} but the file names {sorted(named)}"
    assert len(doc.get("extensionsUsed", [])) == len(used), "extensionsUsed lists a name twice"

    views = doc.get("bufferViews", [])
    view_used = [False] * len(views)
    for i, view in enumerate(views):
        assert 0 <= view["buffer"] < len(buffers)
        assert view["byteLength"] >= 1 and view.get("byteOffset", 0) >= 0
        assert view.get("byteOffset", 0) + view["byteLength"] <= doc["buffers"][view["buffer"]]["byteLength"], \
            f"bufferView {i} overruns its buffer"
        assert view.get("target", 34962) in (34962, 34963)
        if "byteStride" in view:
            assert 4 <= view["byteStride"] <= 252 and view["byteStride"] % 4 == 0

    accessors = doc.get("accessors", [])
    accessor_used = [False] * len(accessors)
    values = {}
    for i, a in enumerate(accessors):
        assert a["componentType"] in COMPONENTS and a["type"] in WIDTHS and a["count"] >= 1
        view_used[a["bufferView"]] = True
        values[i] = accessor_values(doc, buffers, i)
        for c in (c for e in values[i] for c in e):
            assert math.isfinite(c)
        for key in ("min", "max"):
            if key in a:
                assert len(a[key]) == WIDTHS[a["type"]]
        if "min" in a:
            width = WIDTHS[a["type"]]
            assert a["min"] == [min(e[k] for e in values[i]) for k in range(width)], f"accessor {i} min"
            assert a["max"] == [max(e[k] for e in values[i]) for k in range(width)], f"accessor {i} max"

    def check_view_target(accessor: int, target: int):
        view = views[accessors[accessor]["bufferView"]]
        assert view.get("target") == target, f"accessor {accessor}'s bufferView needs target {target}"

    materials = doc.get("materials", [])
    for m, mesh in enumerate(doc.get("meshes", [])):
        assert mesh["primitives"]
        for p in mesh["primitives"]:
            attributes = p["attributes"]
            assert p.get("mode", 4) == 4
            counts = set()
            for name, index in attributes.items():
                accessor_used[index] = True
                a = accessors[index]
                counts.add(a["count"])
                check_view_target(index, 34962)
                assert a["componentType"] == 5126 and "normalized" not in a
                want = {"POSITION": "VEC3", "NORMAL": "VEC3", "TEXCOORD_0": "VEC2"}[name]
                assert a["type"] == want, (name, a["type"])
                if name == "POSITION":
                    assert "min" in a and "max" in a, "POSITION needs min and max"
                if name == "NORMAL":
                    for n in values[index]:
                        assert abs(math.sqrt(sum(c * c for c in n)) - 1.0) < 1e-6, n
            assert "POSITION" in attributes and len(counts) == 1
            vertices = counts.pop()
            index = p["indices"]
            accessor_used[index] = True
            a = accessors[index]
            check_view_target(index, 34963)
            assert a["type"] == "SCALAR" and a["componentType"] in (5121, 5123, 5125)
            restart = {5121: 0xFF, 5123: 0xFFFF, 5125: 0xFFFFFFFF}[a["componentType"]]
            flat = [e[0] for e in values[index]]
            assert len(flat) % 3 == 0 and all(0 <= i < vertices and i != restart for i in flat)
            for t in range(0, len(flat), 3):
                assert len(set(flat[t:t + 3])) == 3, f"mesh {m}: triangle {t // 3} is degenerate"
            if "material" in p:
                assert 0 <= p["material"] < len(materials)
            uses_texture = "baseColorTexture" in materials[p["material"]].get("pbrMetallicRoughness", {}) \
                if "material" in p else False
            if uses_texture:
                assert "TEXCOORD_0" in attributes
    assert all(accessor_used), "an accessor is not used"

    textures = doc.get("textures", [])
    for material in materials:
        pbr = material.get("pbrMetallicRoughness", {})
        colour = pbr.get("baseColorFactor", [1, 1, 1, 1])
        assert len(colour) == 4 and all(0 <= c <= 1 for c in colour)
        assert 0 <= pbr.get("metallicFactor", 1) <= 1 and 0 <= pbr.get("roughnessFactor", 1) <= 1
        emissive = material.get("emissiveFactor", [0, 0, 0])
        assert len(emissive) == 3 and all(0 <= c <= 1 for c in emissive)
        if "baseColorTexture" in pbr:
            info = pbr["baseColorTexture"]
            assert 0 <= info["index"] < len(textures)
            transform = info.get("extensions", {}).get("KHR_texture_transform")
            if transform is not None:
                assert set(transform) <= {"offset", "rotation", "scale", "texCoord"}
                assert len(transform.get("offset", [0, 0])) == 2 and len(transform.get("scale", [1, 1])) == 2
        ext = material.get("extensions", {})
        if "KHR_materials_emissive_strength" in ext:
            assert ext["KHR_materials_emissive_strength"]["emissiveStrength"] >= 0
        if "KHR_materials_transmission" in ext:
            assert 0 <= ext["KHR_materials_transmission"]["transmissionFactor"] <= 1
        if "KHR_materials_ior" in ext:
            ior = ext["KHR_materials_ior"]["ior"]
            assert ior == 0 or ior >= 1

    images = doc.get("images", [])
    for texture in textures:
        assert 0 <= texture["source"] < len(images)
        if "sampler" in texture:
            sampler = doc["samplers"][texture["sampler"]]
            assert sampler.get("magFilter", 9729) in (9728, 9729)
            assert sampler.get("minFilter", 9987) in (9728, 9729, 9984, 9985, 9986, 9987)
            assert sampler.get("wrapS", 10497) in (10497, 33071, 33648)
            assert sampler.get("wrapT", 10497) in (10497, 33071, 33648)
    for image in images:
        assert image["mimeType"] == "image/png" and "uri" not in image
        view = views[image["bufferView"]]
        view_used[image["bufferView"]] = True
        assert "target" not in view and "byteStride" not in view
        start = view.get("byteOffset", 0)
        png = buffers[view["buffer"]][start:start + view["byteLength"]]
        read_png(png)
    assert all(view_used), "a bufferView is not used"

    for camera in doc.get("cameras", []):
        assert camera["type"] == "perspective"
        p = camera["perspective"]
        assert 0 < p["yfov"] < math.pi and p["znear"] > 0 and p.get("aspectRatio", 1) > 0
        if "zfar" in p:
            assert p["zfar"] > p["znear"]

    lights = doc.get("extensions", {}).get("KHR_lights_punctual", {}).get("lights", [])
    for light in lights:
        assert light["type"] in ("point", "spot", "directional")
        assert len(light.get("color", [1, 1, 1])) == 3 and all(0 <= c <= 1 for c in light.get("color", []))
        assert light.get("intensity", 1) >= 0
        assert ("spot" in light) == (light["type"] == "spot")
        if light["type"] == "spot":
            inner = light["spot"].get("innerConeAngle", 0.0)
            outer = light["spot"].get("outerConeAngle", math.pi / 4)
            assert 0 <= inner < outer <= math.pi / 2

    nodes = doc.get("nodes", [])
    parent = {}
    for i, node in enumerate(nodes):
        for child in node.get("children", []):
            assert 0 <= child < len(nodes) and child != i
            assert child not in parent, f"node {child} has two parents"
            parent[child] = i
        if "mesh" in node:
            assert 0 <= node["mesh"] < len(doc["meshes"])
        if "camera" in node:
            assert 0 <= node["camera"] < len(doc["cameras"])
        light = node.get("extensions", {}).get("KHR_lights_punctual")
        if light is not None:
            assert 0 <= light["light"] < len(lights)
        if "matrix" in node:
            assert not {"translation", "rotation", "scale"} & set(node), "matrix with TRS"
            m = node["matrix"]
            assert len(m) == 16 and m[3] == 0 and m[7] == 0 and m[11] == 0 and m[15] == 1
        if "rotation" in node:
            q = node["rotation"]
            assert len(q) == 4 and abs(math.sqrt(sum(c * c for c in q)) - 1.0) < 1e-9
        for key in ("translation", "scale"):
            if key in node:
                assert len(node[key]) == 3
    for i in range(len(nodes)):  # no cycles: every walk up ends
        seen, at = set(), i
        while at in parent:
            assert at not in seen, f"node {i} is its own ancestor"
            seen.add(at)
            at = parent[at]
    assert 0 <= doc.get("scene", 0) < len(doc["scenes"])
    reached = set()
    for scene in doc["scenes"]:
        for root in scene["nodes"]:
            assert root not in parent, f"scene root {root} has a parent"
            stack = [root]
            while stack:
                reached.add(stack[-1])
                stack += nodes[stack.pop()].get("children", [])
    assert reached == set(range(len(nodes))), "a node is in no scene"


def read_png(data: bytes) -> tuple[int, int, int, list[tuple[int, ...]]]:
    """width, height, channels and pixels (rows from the top) of an 8-bit RGB(A) PNG, CRCs checked."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    offset, idat, header = 8, b"", None
    kinds = []
    while offset < len(data):
        (length,) = struct.unpack_from(">I", data, offset)
        kind = data[offset + 4:offset + 8]
        body = data[offset + 8:offset + 8 + length]
        (crc,) = struct.unpack_from(">I", data, offset + 8 + length)
        assert crc == zlib.crc32(kind + body) & 0xFFFFFFFF, f"bad CRC in {kind}"
        kinds.append(kind)
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        offset += 12 + length
    assert kinds[0] == b"IHDR" and kinds[-1] == b"IEND" and offset == len(data)
    width, height, depth, colour, _, _, interlace = header
    assert depth == 8 and colour in (2, 6) and interlace == 0
    channels = 3 if colour == 2 else 4
    raw = zlib.decompress(idat)
    assert len(raw) == height * (1 + width * channels)
    pixels = []
    for row in range(height):
        line = raw[row * (1 + width * channels):(row + 1) * (1 + width * channels)]
        assert line[0] == 0, "only filter type None is written"
        pixels += [tuple(line[1 + x * channels:1 + (x + 1) * channels]) for x in range(width)]
    return width, height, channels, pixels


def read_obj(path: Path) -> tuple[list, list, list, list]:
    v, vt, vn, f = [], [], [], []
    for line in path.read_text().splitlines():
        parts = line.split()
        if not parts or parts[0].startswith("#"):
            continue
        if parts[0] == "v":
            v.append([float(c) for c in parts[1:]])
        elif parts[0] == "vt":
            vt.append([float(c) for c in parts[1:]])
        elif parts[0] == "vn":
            vn.append([float(c) for c in parts[1:]])
        elif parts[0] == "f":
            f.append([[int(k) - 1 for k in corner.split("/")] for corner in parts[1:]])
        else:
            raise AssertionError(f"{path}: unexpected line {line!r}")
    return v, vt, vn, f


# ---------------------------------------------------------------------------
# Tests


def test_validator_catches_mistakes():
    """The checks above can fail: each planted mistake is reported."""
    import copy

    doc, buffers = load(SCENES / "texture-transform.gltf")
    validate(doc, buffers)

    def planted(change):
        bad, data = copy.deepcopy(doc), list(buffers)
        data = change(bad, data) or data
        try:
            validate(bad, data)
        except (AssertionError, IndexError, KeyError, struct.error):
            return
        raise AssertionError(f"{change.__name__} was not caught")

    def wrong_min(d, b):
        d["accessors"][0]["min"][0] -= 0.5

    def missing_extension(d, b):
        d["extensionsUsed"].remove("KHR_texture_transform")

    def extra_extension(d, b):
        d["extensionsUsed"].append("KHR_materials_clearcoat")

    def view_overruns(d, b):
        d["bufferViews"][-1]["byteLength"] += 4

    def accessor_overruns(d, b):
        d["accessors"][0]["count"] += 1

    def index_target(d, b):
        d["bufferViews"][d["accessors"][d["meshes"][0]["primitives"][0]["indices"]]["bufferView"]]["target"] = 34962

    def index_out_of_range(d, b):
        view = d["bufferViews"][d["accessors"][d["meshes"][0]["primitives"][0]["indices"]]["bufferView"]]
        data = bytearray(b[0])
        struct.pack_into("<H", data, view["byteOffset"], 999)
        return [bytes(data)]

    def spot_cones(d, b):
        d["extensions"]["KHR_lights_punctual"]["lights"][0].update(
            type="spot", spot={"innerConeAngle": 0.5, "outerConeAngle": 0.4})

    def two_parents(d, b):
        d["nodes"][0]["children"] = [1]
        d["nodes"][2]["children"] = [1]

    def matrix_and_trs(d, b):
        d["nodes"][0]["matrix"] = gw.to_column_major(gw.identity())

    for change in (wrong_min, missing_extension, extra_extension, view_overruns, accessor_overruns, index_target,
                   index_out_of_range, spot_cones, two_parents, matrix_and_trs):
        planted(change)


def test_png_round_trip():
    pixels = gw.checker_pixels(8, 4, (255, 0, 0), (0, 0, 255), marks={(3, 0): (0, 255, 0)})
    for level in (None, 6):
        w, h, channels, back = read_png(gw.png_bytes(8, 8, pixels, level=level))
        assert (w, h, channels) == (8, 8, 3) and back == pixels
    rgba = [(x * 16, y * 16, 7, 128) for y in range(16) for x in range(16)]
    assert read_png(gw.png_bytes(16, 16, rgba))[3] == rgba
    assert pixels[0] == (255, 0, 0) and pixels[2] == (0, 0, 255) and pixels[6] == (0, 255, 0)


def test_zlib_stored_blocks():
    for size in (0, 1, 65535, 65536, 200_000):
        data = bytes((i * 7) % 251 for i in range(size))
        assert zlib.decompress(gw.zlib_stored(data)) == data


def test_shipped_scenes_validate():
    for name in SHIPPED_GLTF:
        doc, buffers = load(SCENES / name)
        validate(doc, buffers)
        assert doc["asset"]["extras"]["description"], f"{name} says what it exercises"
        assert doc["asset"]["generator"] == gw.GENERATOR


def test_glb_copies_validate_and_match():
    out = _fresh()
    for name in SHIPPED_GLTF:
        text_doc, text_buffers = load(out / name)
        glb_doc, glb_buffers = load(out / name.replace(".gltf", ".glb"))
        validate(glb_doc, glb_buffers)
        assert glb_buffers == text_buffers
        del text_doc["buffers"][0]["uri"]
        assert glb_doc == text_doc


def test_writing_twice_gives_identical_bytes():
    first = _fresh()
    second = Path(tempfile.mkdtemp(prefix="gltf-writer-test-"))
    subprocess.run([sys.executable, str(REPO / "tools" / "gltf_writer.py"), "scenes", str(second), "--glb"],
                   check=True, capture_output=True)
    files = sorted(p.relative_to(first) for p in first.rglob("*") if p.is_file())
    assert files == sorted(p.relative_to(second) for p in second.rglob("*") if p.is_file())
    for rel in files:
        assert (first / rel).read_bytes() == (second / rel).read_bytes(), f"{rel} differs between runs"


def test_shipped_scenes_are_up_to_date():
    fresh = _fresh()
    for path in sorted(fresh.rglob("*")):
        rel = path.relative_to(fresh)
        if path.is_dir() or path.suffix == ".glb":
            continue
        shipped = SCENES / rel
        assert shipped.is_file(), f"scenes/gltf/{rel} is missing: run tools/gltf_writer.py scenes scenes/gltf"
        assert shipped.read_bytes() == path.read_bytes(), \
            f"scenes/gltf/{rel} is stale: run tools/gltf_writer.py scenes scenes/gltf"
        assert shipped.stat().st_size < 100_000, f"scenes/gltf/{rel} is {shipped.stat().st_size} bytes"


def test_extensions_used():
    expected = {
        "lights-camera.gltf": {"KHR_lights_punctual"},
        "transmission.gltf": {"KHR_lights_punctual", "KHR_materials_transmission", "KHR_materials_ior"},
        "texture-transform.gltf": {"KHR_lights_punctual", "KHR_texture_transform",
                                   "KHR_materials_emissive_strength"},
        "texture-transform-baked.gltf": {"KHR_lights_punctual", "KHR_materials_emissive_strength"},
    }
    for name, names in expected.items():
        doc, _ = load(SCENES / name)
        assert doc["extensionsUsed"] == sorted(names), (name, doc["extensionsUsed"])
        assert "extensionsRequired" not in doc
    # A document without extensions lists none.
    g = gw.Gltf()
    g.add_scene([g.add_node("empty")])
    assert "extensionsUsed" not in g.to_json()


def _lights(doc):
    return doc["extensions"]["KHR_lights_punctual"]["lights"]


def _light_nodes(doc):
    return {i: _lights(doc)[n["extensions"]["KHR_lights_punctual"]["light"]]
            for i, n in enumerate(doc["nodes"]) if "KHR_lights_punctual" in n.get("extensions", {})}


def test_lights_camera_content():
    doc, _ = load(SCENES / "lights-camera.gltf")
    nodes = doc["nodes"]
    (cam_node,) = [i for i, n in enumerate(nodes) if "camera" in n]
    assert {"translation", "rotation"} <= set(nodes[cam_node]) and "matrix" not in nodes[cam_node]
    p = doc["cameras"][nodes[cam_node]["camera"]]["perspective"]
    assert p["yfov"] == 0.6 and p["aspectRatio"] == 4 / 3
    parents = {c: i for i, n in enumerate(nodes) for c in n.get("children", [])}
    users: dict[int, list[int]] = {}
    for i, n in enumerate(nodes):
        if "mesh" in n:
            users.setdefault(n["mesh"], []).append(i)
    shared = [m for m, u in users.items() if len(u) == 2]
    assert shared, "one mesh is instanced by two nodes"
    a, b = users[shared[0]]
    assert a in parents and any(k in nodes[parents[a]] for k in ("translation", "rotation", "scale"))
    assert "matrix" in nodes[b] and b not in parents
    kinds = sorted(light["type"] for light in _light_nodes(doc).values())
    assert kinds == ["directional", "point", "spot"]
    assert all("mesh" not in nodes[i] and "camera" not in nodes[i] for i in _light_nodes(doc))
    spot = next(light for light in _lights(doc) if light["type"] == "spot")
    assert spot["spot"]["innerConeAngle"] < spot["spot"]["outerConeAngle"]
    assert any(m["pbrMetallicRoughness"]["metallicFactor"] == 1.0 for m in doc["materials"])
    assert "KHR_lights_environment" not in doc.get("extensionsUsed", [])
    # The camera sees every mesh node's origin.
    world = world_matrices(doc)
    eye, forward, up = column(world[cam_node], None, 1.0), unit(column(world[cam_node], -3)), \
        unit(column(world[cam_node], 2))
    right = unit([forward[1] * up[2] - forward[2] * up[1], forward[2] * up[0] - forward[0] * up[2],
                  forward[0] * up[1] - forward[1] * up[0]])
    for i in (i for i, n in enumerate(nodes) if "mesh" in n):
        d = [c - e for c, e in zip(column(world[i], None, 1.0), eye)]
        depth = sum(x * y for x, y in zip(d, forward))
        assert depth > 0
        assert abs(sum(x * y for x, y in zip(d, up))) / depth < math.tan(p["yfov"] / 2)
        assert abs(sum(x * y for x, y in zip(d, right))) / depth < math.tan(p["yfov"] / 2) * p["aspectRatio"]


def test_transmission_content():
    doc, _ = load(SCENES / "transmission.gltf")
    by_name = {m["name"]: m for m in doc["materials"]}
    glass, frosted = by_name["glass"], by_name["frosted glass"]
    assert glass["extensions"] == {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                                   "KHR_materials_ior": {"ior": 1.5}}
    assert glass["pbrMetallicRoughness"]["roughnessFactor"] == 0.0
    assert frosted["extensions"] == {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                                     "KHR_materials_ior": {"ior": 1.33}}
    assert frosted["pbrMetallicRoughness"]["roughnessFactor"] == 0.3
    assert "baseColorTexture" in by_name["checker floor"]["pbrMetallicRoughness"]
    assert len(doc["cameras"]) == 1
    assert [light["type"] for light in _lights(doc)] == ["directional"]


def test_texture_transform_content():
    doc, buffers = load(SCENES / "texture-transform.gltf")
    by_name = {m["name"]: m for m in doc["materials"]}
    info = by_name["transformed checker"]["pbrMetallicRoughness"]["baseColorTexture"]
    transform = info["extensions"]["KHR_texture_transform"]
    assert transform["scale"] == [3.0, 2.0] and transform["rotation"] == 0.3 and transform["offset"] != [0, 0]
    lamp = by_name["lamp"]
    assert lamp["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"] == 4.0
    assert any(lamp["emissiveFactor"])
    assert [light["type"] for light in _lights(doc)] == ["point"] and len(doc["cameras"]) == 1
    view = doc["bufferViews"][doc["images"][doc["textures"][info["index"]]["source"]]["bufferView"]]
    png = buffers[0][view["byteOffset"]:view["byteOffset"] + view["byteLength"]]
    w, h, _, pixels = read_png(png)
    assert (w, h) == (16, 16) and pixels[0] != pixels[w - 1]


def texture_transform_uv(transform: dict, u: float, v: float) -> tuple[float, float]:
    """KHR_texture_transform as its specification writes it: T(offset) * R(rotation) *
    S(scale) applied to (u, v, 1), with R = [[cos, sin], [-sin, cos]]; double precision."""
    ox, oy = transform.get("offset", [0.0, 0.0])
    sx, sy = transform.get("scale", [1.0, 1.0])
    r = transform.get("rotation", 0.0)
    su, sv = sx * u, sy * v
    return (math.cos(r) * su + math.sin(r) * sv + ox, -math.sin(r) * su + math.cos(r) * sv + oy)


def test_texture_transform_baked_matches():
    """texture-transform-baked.gltf is texture-transform.gltf with each
    KHR_texture_transform baked into the uvs: the same JSON but for the
    extension (and extensionsUsed, the description and the buffer's bytes), and
    the same buffer but for the baked uv accessors, whose values are the
    transform of the original uvs to within float32 rounding."""
    import copy

    doc, buffers = load(SCENES / "texture-transform.gltf")
    baked, baked_buffers = load(SCENES / "texture-transform-baked.gltf")
    expected = copy.deepcopy(doc)
    transforms: dict[int, dict] = {}  # uv accessor -> its transform
    untransformed: set[int] = set()  # uv accessors read without a transform
    for mesh in doc["meshes"]:
        for p in mesh["primitives"]:
            material = doc["materials"][p["material"]] if "material" in p else {}
            info = material.get("pbrMetallicRoughness", {}).get("baseColorTexture", {})
            transform = info.get("extensions", {}).get("KHR_texture_transform")
            assert info.get("texCoord", 0) == 0
            uv = p["attributes"]["TEXCOORD_0"]
            if transform is None:
                untransformed.add(uv)
            else:
                assert transforms.get(uv, transform) == transform
                transforms[uv] = transform
    assert transforms, "texture-transform.gltf has a transformed texture"
    assert not untransformed & set(transforms), "a transformed uv accessor is also read untransformed"
    for material in expected["materials"]:
        info = material["pbrMetallicRoughness"].get("baseColorTexture", {})
        info.get("extensions", {}).pop("KHR_texture_transform", None)
        if "extensions" in info and not info["extensions"]:
            del info["extensions"]
    expected["extensionsUsed"] = sorted(extension_names({k: v for k, v in expected.items()
                                                         if k != "extensionsUsed"}))
    assert "KHR_texture_transform" not in expected["extensionsUsed"]
    for each in (expected, baked):
        assert each["asset"]["extras"].pop("description")
        del each["buffers"][0]["uri"]
    assert baked == expected, "only the texture transform (and the uv bytes) differ"

    # Bytes outside the baked uv accessors are the same; inside, the transformed uvs.
    before, after = buffers[0], baked_buffers[0]
    assert len(before) == len(after)
    spans = []
    for accessor, transform in transforms.items():
        view = doc["bufferViews"][doc["accessors"][accessor]["bufferView"]]
        spans.append((view["byteOffset"], view["byteOffset"] + view["byteLength"]))
        original = accessor_values(doc, buffers, accessor)
        new = accessor_values(baked, baked_buffers, accessor)
        assert len(original) == len(new) >= 3
        for (u, v), got in zip(original, new):
            want = texture_transform_uv(transform, u, v)
            for g, w in zip(got, want):
                # within the rounding to float32 (half an ulp), plus double-precision slack
                assert abs(g - w) <= 2.0 ** -24 * abs(w) + 1e-15, ((u, v), got, want)
        assert [list(e) for e in new] != [list(e) for e in original]
    outside = bytearray(before), bytearray(after)
    for start, end in spans:
        for data in outside:
            data[start:end] = bytes(end - start)
    assert outside[0] == outside[1], "the buffers differ outside the baked uvs"


def test_bake_texture_transforms():
    # The writer's own transform is the specification's.
    transform = {"offset": [0.25, -0.5], "rotation": 1.1, "scale": [3.0, 0.5]}
    for uv in ((0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (0.375, -2.5)):
        assert close(gw.apply_texture_transform(transform, uv), texture_transform_uv(transform, *uv))
    # A uv accessor shared by a transformed and an untransformed material is refused, and
    # the document baked is left as it was.
    g = gw.Gltf()
    tex = g.add_png_texture("t", gw.png_bytes(1, 1, [(1, 2, 3)]))
    moved = g.add_material("moved", base_color_texture=gw.TextureRef(tex, rotation=0.5))
    still = g.add_material("still", base_color_texture=gw.TextureRef(tex))
    shared = gw.quad()
    g.add_scene([g.add_node("q", mesh=g.add_mesh("q", [(shared, moved), (shared, still)]))])
    before = g.gltf_bytes()
    try:
        gw.bake_texture_transforms(g)
    except ValueError:
        pass
    else:
        raise AssertionError("a shared uv accessor under two transforms was baked")
    assert g.gltf_bytes() == before
    # Each its own quad: baked, and the input is untouched.
    g = gw.Gltf()
    tex = g.add_png_texture("t", gw.png_bytes(1, 1, [(1, 2, 3)]))
    moved = g.add_material("moved", base_color_texture=gw.TextureRef(tex, rotation=0.5))
    still = g.add_material("still", base_color_texture=gw.TextureRef(tex))
    g.add_scene([g.add_node("q", mesh=g.add_mesh("q", [(gw.quad(), moved), (gw.quad(), still)]))])
    before = g.gltf_bytes()
    baked = gw.bake_texture_transforms(g, description="baked")
    assert g.gltf_bytes() == before
    doc = baked.to_json()
    assert "extensionsUsed" not in doc and doc["asset"]["extras"]["description"] == "baked"
    assert baked.mesh_data[0][0][0].texcoords == [[gw.f32(c) for c in texture_transform_uv({"rotation": 0.5}, *uv)]
                                                  for uv in gw.quad().texcoords]
    assert baked.mesh_data[0][1][0].texcoords == gw.quad().texcoords


def test_toml_matches_the_node_hierarchy():
    doc, buffers = load(SCENES / "lights-camera.gltf")
    scene = tomllib.loads((SCENES / "lights-camera.toml").read_text())
    world = world_matrices(doc)
    nodes = doc["nodes"]

    (cam_node,) = [i for i, n in enumerate(nodes) if "camera" in n]
    m = world[cam_node]
    cam = scene["camera"]
    p = doc["cameras"][nodes[cam_node]["camera"]]["perspective"]
    eye = column(m, None, 1.0)
    assert close(cam["eye"], eye)
    assert close([t - e for t, e in zip(cam["target"], cam["eye"])], unit(column(m, -3)))
    assert close(cam["up"], unit(column(m, 2)))
    assert close([cam["fov"]], [math.degrees(p["yfov"])])
    assert cam["width"] / cam["height"] == p["aspectRatio"]

    light_nodes = _light_nodes(doc)
    assert len(scene["lights"]) == len(light_nodes)
    for entry, (node, light) in zip(scene["lights"], light_nodes.items()):
        m = world[node]
        assert entry["type"] == light["type"]
        power = [c * light["intensity"] for c in light["color"]]
        if light["type"] in ("point", "spot"):
            assert close(entry["position"], column(m, None, 1.0)) and close(entry["intensity"], power)
        if light["type"] in ("spot", "directional"):
            assert close(entry["direction"], unit(column(m, -3)))
        if light["type"] == "directional":
            assert close(entry["irradiance"], power)
        if light["type"] == "spot":
            assert close([entry["inner_cone_angle"], entry["outer_cone_angle"]],
                         [math.degrees(light["spot"]["innerConeAngle"]),
                          math.degrees(light["spot"]["outerConeAngle"])])
            assert 0 < entry["outer_cone_angle"] < 90

    mesh_nodes = [i for i in world if "mesh" in nodes[i]]
    assert len(scene["objects"]) == len(mesh_nodes)
    for entry, node in zip(scene["objects"], mesh_nodes):
        assert entry["shape"] == "mesh"
        assert entry["matrix"][3] == [0.0, 0.0, 0.0, 1.0]
        assert all(close(row, want) for row, want in zip(entry["matrix"], world[node]))
        (primitive,) = doc["meshes"][nodes[node]["mesh"]]["primitives"]
        material = doc["materials"][primitive["material"]]
        table = scene["materials"][entry["material"]]
        assert entry["material"] == material["name"]
        pbr = material["pbrMetallicRoughness"]
        assert table == {"type": "pbr", "base_color": pbr["baseColorFactor"][:3],
                         "metallic": pbr["metallicFactor"], "roughness": pbr["roughnessFactor"]}
        # The OBJ holds the very float32 values of the glTF buffer, and the same triangles.
        v, vt, vn, faces = read_obj(SCENES / entry["file"])
        attributes = primitive["attributes"]
        f32 = gw.f32
        assert [[f32(c) for c in p] for p in v] == [list(e) for e in accessor_values(doc, buffers,
                                                                                        attributes["POSITION"])]
        assert [[f32(c) for c in n] for n in vn] == [list(e) for e in accessor_values(doc, buffers,
                                                                                         attributes["NORMAL"])]
        assert [[f32(u), f32(1.0 - f32(w))] for u, w in vt] == [
            list(e) for e in accessor_values(doc, buffers, attributes["TEXCOORD_0"])]
        indices = [e[0] for e in accessor_values(doc, buffers, primitive["indices"])]
        assert [c[0] for face in faces for c in face] == indices
        assert all(c[0] == c[1] == c[2] for face in faces for c in face)
    assert set(scene) == {"camera", "materials", "objects", "lights"}, "no [render] and no [background]"


def test_world_matrices_agree_with_the_writer():
    g, named = gw.lights_camera()
    mine = g.world_matrices()
    doc, _ = load(SCENES / "lights-camera.gltf")
    theirs = world_matrices(doc)
    assert set(mine) == set(theirs)
    for node in mine:
        assert all(close(a, b) for a, b in zip(mine[node], theirs[node]))
    # The child cube sits on the floor: its rig's scale 1.25 and its own +0.5.
    cube = theirs[named["cube A"]]
    assert close([cube[1][3]], [0.625])


def test_mesh_helpers():
    for mesh in (gw.cube(2.0), gw.quad(3.0, 1.0, (2.0, 1.0)), gw.uv_sphere(0.5, 12, 6)):
        for t in range(0, len(mesh.indices), 3):
            a, b, c = (mesh.positions[i] for i in mesh.indices[t:t + 3])
            n = gw.cross(gw.sub(b, a), gw.sub(c, a))
            assert math.sqrt(gw.dot(n, n)) > 0, "no degenerate triangles"
            # Counter-clockwise seen from the side the vertex normals face.
            avg = [sum(mesh.normals[i][k] for i in mesh.indices[t:t + 3]) for k in range(3)]
            assert gw.dot(n, avg) > 0
    low, high = gw.cube(2.0).bounds()
    assert low == [-1.0, -1.0, -1.0] and high == [1.0, 1.0, 1.0]
    sphere = gw.uv_sphere(0.5, 12, 6)
    assert all(abs(math.sqrt(gw.dot(p, p)) - 0.5) < 1e-12 for p in sphere.positions)
    assert len(sphere.indices) == 3 * (2 * 12 * 6 - 2 * 12)


def test_transforms():
    q = gw.quat_look_at((1.0, 2.0, 3.0), (0.0, 0.0, 0.0))
    r = gw.quat_to_mat3(q)
    assert close([-r[i][2] for i in range(3)], gw.normalize((-1.0, -2.0, -3.0)))
    assert r[1][1] > 0
    m = gw.trs_matrix((1.0, 2.0, 3.0), gw.quat_axis_angle((0, 1, 0), 0.7), (2.0, 3.0, 4.0))
    assert gw.from_column_major(gw.to_column_major(m)) == m
    product = gw.mat_mul(m, gw.mat_inverse(m))
    assert all(close(row, [1.0 if i == j else 0.0 for j in range(4)]) for i, row in enumerate(product))
    assert close(gw.quat_from_mat3(gw.quat_to_mat3([0.0, 1.0, 0.0, 0.0])), [0.0, 1.0, 0.0, 0.0])
    both = gw.quat_mul(gw.quat_axis_angle((0, 1, 0), 0.25), gw.quat_axis_angle((0, 1, 0), 0.5))
    assert close(both, gw.quat_axis_angle((0, 1, 0), 0.75))
    first_x_then_y = gw.quat_to_mat3(gw.quat_mul(gw.quat_axis_angle((0, 1, 0), math.pi / 2),
                                                 gw.quat_axis_angle((1, 0, 0), math.pi / 2)))
    # +Y -> (x by 90) +Z -> (y by 90) +X
    assert close([first_x_then_y[i][1] for i in range(3)], [1.0, 0.0, 0.0])


def test_api_refuses_invalid_input():
    g = gw.Gltf()

    def refused(call, *args, **kwargs):
        try:
            call(*args, **kwargs)
        except ValueError:
            return
        raise AssertionError(f"{call.__name__}{args}{kwargs} was accepted")

    refused(g.add_spot_light, inner_cone_angle=0.5, outer_cone_angle=0.5)
    refused(g.add_spot_light, inner_cone_angle=0.1, outer_cone_angle=2.0)
    refused(g.add_camera, 0.0)
    refused(g.add_material, "x", base_color=(2.0, 0.0, 0.0, 1.0))
    refused(g.add_material, "x", ior=0.5)
    refused(g.add_node, "x", matrix=gw.identity(), translation=(1, 2, 3))
    refused(g.add_node, "x", rotation=(0.0, 0.0, 0.0, 2.0))
    refused(g.add_node, "x", mesh=0)
    child = g.add_node("child")
    g.add_node("parent", children=[child])
    refused(g.add_node, "second parent", children=[child])
    refused(g.add_scene, [child])
    refused(gw.MeshData, [[0, 0, 0]], [0, 0, 1])
    refused(g.to_json)  # no scene yet


def test_small_glb_round_trip():
    g = gw.Gltf(description="round trip")
    tex = g.add_png_texture("t", gw.png_bytes(2, 2, [(1, 2, 3), (4, 5, 6), (7, 8, 9), (10, 11, 12)]),
                            g.add_sampler(wrap_s=gw.CLAMP_TO_EDGE))
    mat = g.add_material("m", base_color_texture=gw.TextureRef(tex, rotation=0.5), emissive=(1.0, 1.0, 1.0),
                         emissive_strength=2.0)
    tri = gw.MeshData([[0.1, 0.2, 0.3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], [0, 1, 2],
                      texcoords=[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    g.add_scene([g.add_node("tri", mesh=g.add_mesh("tri", [(tri, mat)]))])
    with tempfile.TemporaryDirectory() as tmp:
        for name in ("t.glb", "t.gltf"):
            doc, buffers = load(g.write(Path(tmp) / name))
            validate(doc, buffers)
            assert doc["accessors"][0]["min"] == [gw.f32(0.0), 0.0, 0.0]
            assert doc["accessors"][0]["max"] == [1.0, 1.0, gw.f32(0.3)]
            assert doc["extensionsUsed"] == ["KHR_materials_emissive_strength", "KHR_texture_transform"]


def test_vkrt_loads_the_scenes():
    binary = os.environ.get("VKRT")
    if not binary:
        _skip("set VKRT to a vkrt binary to load the scenes with it")
    with tempfile.TemporaryDirectory() as tmp:
        for name in SHIPPED_GLTF:
            toml = Path(tmp) / (name + ".toml")
            toml.write_text(f"""[camera]
eye = [0, 2, 6]
target = [0, 0.5, 0]
fov = 40
width = 32
height = 24
[[objects]]
shape = "mesh"
file = {json.dumps(str(SCENES / name))}
material = "file"
""")
            result = subprocess.run([binary, "info", str(toml)], capture_output=True, text=True)
            assert result.returncode == 0, result.stderr
        result = subprocess.run([binary, "info", str(SCENES / "lights-camera.toml")], capture_output=True,
                                text=True)
        assert result.returncode == 0, result.stderr
        for phrase in ("mesh 4", "point 1", "directional 1", "spot 1", "pbr 3"):
            assert phrase in result.stdout, (phrase, result.stdout)


if __name__ == "__main__":
    _STANDALONE = True
    failures = passed = skipped = 0
    for name, fn in list(globals().items()):
        if name.startswith("test_") and callable(fn):
            try:
                fn()
                passed += 1
                print(f"PASS {name}")
            except Skip as e:
                skipped += 1
                print(f"SKIP {name}: {e}")
            except Exception as e:  # noqa: BLE001
                failures += 1
                print(f"FAIL {name}: {type(e).__name__}: {e}")
    print(f"{passed} passed, {failures} failed, {skipped} skipped")
    sys.exit(1 if failures else 0)

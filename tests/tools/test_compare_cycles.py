"""Checks of tools/compare_cycles.py's metrics, verdict, framing camera and
temporary glTF copy. NumPy and pytest only: no Blender, no Vulkan device,
no rendering. Debian's python3 has both (tools/install-deps.sh):

    python3 -m pytest -q tests/tools/test_compare_cycles.py
"""
from __future__ import annotations

import copy
import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "tools"))

import compare_cycles as cc  # noqa: E402


def image(seed=1, h=24, w=32, low=0.2, high=1.0):
    return np.random.default_rng(seed).uniform(low, high, size=(h, w, 3))


# ---------------------------------------------------------------- metrics


def test_identical_images_agree_exactly():
    a = image()
    m = cc.compare_images(a, a.copy())
    assert m["mean_rel_diff"] == 0.0
    assert m["share_over"] == 0.0
    assert cc.verdict(m) == "pass"


def test_a_20_percent_brighter_image():
    a = image()
    m = cc.compare_images(1.2 * a, a)
    assert m["mean_rel_diff"] == pytest.approx(0.2, abs=1e-12)
    assert m["share_over"] == 1.0
    assert cc.verdict(m) == "fail"
    # and darker: -20 %, every pixel still over 10 %
    m = cc.compare_images(0.8 * a, a)
    assert m["mean_rel_diff"] == pytest.approx(-0.2, abs=1e-12)
    assert m["share_over"] == 1.0


def test_luminance_weights_are_rec709():
    rgb = np.zeros((1, 3, 3))
    rgb[0, 0, 0] = rgb[0, 1, 1] = rgb[0, 2, 2] = 1.0
    assert cc.luminance(rgb)[0].tolist() == pytest.approx([0.2126, 0.7152, 0.0722])
    assert cc.luminance(np.ones((2, 2, 3))) == pytest.approx(np.ones((2, 2)))


def test_box_blur_keeps_constants_and_averages_neighbours():
    assert cc.box_blur3(np.full((5, 7), 3.0)) == pytest.approx(np.full((5, 7), 3.0))
    spike = np.zeros((5, 5))
    spike[2, 2] = 9.0
    blurred = cc.box_blur3(spike)
    assert blurred[1:4, 1:4] == pytest.approx(np.ones((3, 3)))
    assert blurred.sum() == pytest.approx(9.0)


def test_blur_hides_single_pixel_noise_but_not_a_region():
    a = np.ones((20, 20))
    noisy = a.copy()
    noisy[5, 5] = 1.5  # one hot pixel: +50 % alone, +5.6 % after the 3x3 blur
    assert cc.share_over(noisy, a) == 0.0
    region = a.copy()
    region[:, :10] = 1.3  # half the image 30 % brighter
    share = cc.share_over(region, a)
    assert 0.45 <= share <= 0.55


def test_black_pixels_do_not_dominate():
    cycles = np.ones((10, 10))
    cycles[:, :5] = 0.0
    vkrt = cycles.copy()
    vkrt[:, :5] = 1e-3  # a tiny absolute difference on black: under the floor (5 % of the mean)
    assert cc.share_over(vkrt, cycles) == 0.0
    # half the image 1e-3 brighter: the mean 0.5 grows by 5e-4, +0.1 %
    assert cc.mean_relative_difference(vkrt, cycles) == pytest.approx(0.001)


def test_share_threshold_is_strict_and_tolerance_configurable():
    a = np.ones((8, 8))
    assert cc.share_over(1.05 * a, a) == 0.0
    assert cc.share_over(1.05 * a, a, tolerance=0.04) == 1.0


def test_verdict_thresholds():
    assert cc.verdict({"mean_rel_diff": 0.029, "share_over": 0.049}) == "pass"
    assert cc.verdict({"mean_rel_diff": -0.031, "share_over": 0.0}) == "fail"
    assert cc.verdict({"mean_rel_diff": 0.0, "share_over": 0.051}) == "fail"


def test_different_sizes_are_refused():
    with pytest.raises(ValueError):
        cc.compare_images(np.ones((4, 4, 3)), np.ones((4, 5, 3)))


def test_png_writer_and_tonemap(tmp_path):
    rgb8 = cc.side_by_side(image(), image(2), np.zeros((24, 32)))
    assert rgb8.shape == (24, 3 * 32 + 8, 3)
    assert cc.tonemap(np.array([[[0.0, 1.0, 5.0]]])).tolist() == [[[0, 255, 255]]]
    path = tmp_path / "x.png"
    cc.write_png(path, rgb8)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


# ------------------------------------------------------ cameras and glTF


def box_gltf(lower=(-1, -2, -3), upper=(3, 2, 1), translation=None, camera=False):
    """A minimal glTF: one triangle primitive whose POSITION spans lower..upper."""
    node = {"name": "box", "mesh": 0}
    if translation:
        node["translation"] = list(translation)
    gltf = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [node],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
        "materials": [{"name": "red", "pbrMetallicRoughness": {"baseColorFactor": [1, 0, 0, 1]}}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3",
             "min": list(lower), "max": list(upper)},
            {"bufferView": 1, "componentType": 5123, "count": 36, "type": "SCALAR"},
        ],
        "bufferViews": [{"buffer": 0, "byteLength": 96}, {"buffer": 0, "byteOffset": 96, "byteLength": 72}],
        "buffers": [{"uri": "box.bin", "byteLength": 168}],
    }
    if camera:
        gltf["cameras"] = [{"type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.1}}]
        gltf["nodes"].append({"name": "cam", "camera": 0, "translation": [0, 1, 10]})
        gltf["scenes"][0]["nodes"].append(1)
    return gltf


def test_framing_camera_by_hand():
    # Box from (-1,-2,-3) to (3,2,1): centre (1,0,-1), diagonal (4,4,4), radius 2*sqrt(3).
    camera = cc.framing_camera((-1, -2, -3), (3, 2, 1))
    radius = 2.0 * math.sqrt(3.0)
    distance = 1.1 * radius / math.sin(math.radians(20.0))  # 3.8105118 / 0.3420201
    assert distance == pytest.approx(11.141191, rel=1e-6)
    d = np.array([0.35, 0.3, 1.0]) / math.sqrt(0.35 ** 2 + 0.3 ** 2 + 1.0)
    assert camera["target"] == pytest.approx([1.0, 0.0, -1.0])
    assert camera["eye"] == pytest.approx((np.array([1.0, 0.0, -1.0]) + distance * d).tolist())
    # by hand: |(0.35, 0.3, 1)| = sqrt(1.2125) = 1.1011357, d = (0.317854, 0.272446, 0.908153)
    assert camera["eye"] == pytest.approx([4.541268, 3.035373, 9.117909], abs=2e-6)
    assert camera["up"] == [0.0, 1.0, 0.0]
    assert camera["fov_y"] == 40.0


def test_framing_camera_of_an_empty_box():
    camera = cc.framing_camera((np.inf,) * 3, (-np.inf,) * 3)
    assert camera["target"] == [0.0, 0.0, 0.0]
    assert np.linalg.norm(camera["eye"]) == pytest.approx(1.1 / math.sin(math.radians(20.0)))


def test_choose_camera_frames_the_moved_and_rotated_instances():
    gltf = box_gltf(lower=(-1, -1, -1), upper=(1, 1, 1), translation=(10, 0, 0))
    # a second instance turned 90 degrees about Y and scaled: its box corners span x 4..8
    gltf["nodes"].append({"mesh": 0, "translation": [6, 0, 0], "scale": [2, 1, 1],
                          "rotation": [0, math.sin(math.pi / 4), 0, math.cos(math.pi / 4)]})
    gltf["scenes"][0]["nodes"].append(1)
    camera, origin = cc.choose_camera(gltf)
    assert "framing" in origin
    # x from 5 (6 - 1) to 11, y -1..1, z -2..2 (the scaled x axis turned onto z)
    expected = cc.framing_camera((5, -1, -2), (11, 1, 2))
    assert camera["eye"] == pytest.approx(expected["eye"])
    assert camera["target"] == pytest.approx([8.0, 0.0, 0.0])


def test_choose_camera_takes_the_files_first_camera():
    gltf = box_gltf(camera=True)
    camera, origin = cc.choose_camera(gltf)
    assert "file's camera 0" in origin
    assert camera["eye"] == pytest.approx([0, 1, 10])
    assert camera["fov_y"] == pytest.approx(math.degrees(0.5))
    forward = np.subtract(camera["target"], camera["eye"])
    assert forward / np.linalg.norm(forward) == pytest.approx([0, 0, -1])
    assert camera["up"] == pytest.approx([0, 1, 0])


def test_camera_node_matrix_looks_down_minus_z_at_the_target():
    camera = {"eye": [1, 2, 3], "target": [1, 2, -7], "up": [0, 1, 0]}
    m = np.array(cc.camera_node_matrix(camera)).reshape(4, 4).T  # column-major
    assert m[:3, 3] == pytest.approx([1, 2, 3])
    assert m[:3, :3] == pytest.approx(np.eye(3))
    camera = cc.framing_camera((-1, -1, -1), (1, 1, 1))
    m = np.array(cc.camera_node_matrix(camera)).reshape(4, 4).T
    forward = m[:3, :3] @ [0, 0, -1]
    to_target = np.subtract(camera["target"], camera["eye"])
    assert forward == pytest.approx(to_target / np.linalg.norm(to_target))
    assert m[:3, :3] @ m[:3, :3].T == pytest.approx(np.eye(3))
    assert np.linalg.det(m[:3, :3]) == pytest.approx(1.0)


def test_temporary_copy_gets_a_camera_node_and_keeps_the_rest(tmp_path):
    source = tmp_path / "model.gltf"
    original = box_gltf()
    source.write_text(json.dumps(original))
    gltf = json.loads(source.read_text())
    camera, _ = cc.choose_camera(gltf)
    index = cc.add_camera(gltf, camera, 4 / 3)
    copy_path = cc.write_temporary_copy(source, gltf)
    try:
        assert copy_path.parent == source.parent  # relative URIs ("box.bin") still resolve
        assert copy_path.name.startswith(".") and copy_path.suffix == ".gltf"
        written = json.loads(copy_path.read_text())
        assert index == 0 and len(written["cameras"]) == 1
        assert written["cameras"][0]["perspective"]["yfov"] == pytest.approx(math.radians(40.0))
        node = written["nodes"][-1]
        assert node["camera"] == index
        assert written["scenes"][0]["nodes"] == [0, len(written["nodes"]) - 1]
        # the walk now meets the new camera; it reproduces the chosen one
        again, origin = cc.choose_camera(written)
        assert "file's camera 0" in origin
        assert again["eye"] == pytest.approx(camera["eye"])
        # everything else is the original, untouched
        for key in ("asset", "meshes", "materials", "accessors", "bufferViews", "buffers", "scene"):
            assert written[key] == original[key]
        assert written["nodes"][:-1] == original["nodes"]
        # a second copy has another name, and the source file is unchanged
        other = cc.write_temporary_copy(source, gltf)
        assert other != copy_path
        other.unlink()
        assert json.loads(source.read_text()) == original
    finally:
        copy_path.unlink(missing_ok=True)


def test_a_file_camera_stays_and_the_added_one_is_named_by_index():
    gltf = box_gltf(camera=True)
    camera, _ = cc.choose_camera(gltf)
    index = cc.add_camera(gltf, camera, 4 / 3)
    assert index == 1
    assert gltf["cameras"][0] == {"type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.1}}


def test_strip_by_design_removes_only_the_listed_extensions():
    gltf = box_gltf()
    gltf["materials"][0]["extensions"] = {"KHR_materials_iridescence": {"iridescenceFactor": 1},
                                          "KHR_materials_sheen": {"sheenColorFactor": [1, 1, 1]},
                                          "KHR_materials_emissive_strength": {"emissiveStrength": 2}}
    gltf["materials"].append({"alphaMode": "BLEND"})
    gltf["extensionsUsed"] = ["KHR_materials_iridescence", "KHR_materials_sheen", "KHR_materials_emissive_strength"]
    removed = cc.strip_by_design(gltf)
    assert removed == ["KHR_materials_iridescence"]  # vkrt renders sheen, clearcoat and specular: compared
    del gltf["materials"][0]["extensions"]["KHR_materials_sheen"]
    assert gltf["materials"][0]["extensions"] == {"KHR_materials_emissive_strength": {"emissiveStrength": 2}}
    assert gltf["materials"][1] == {"alphaMode": "BLEND"}  # both renderers honour alpha modes
    assert gltf["extensionsUsed"] == ["KHR_materials_sheen", "KHR_materials_emissive_strength"]


def test_only_transmission_without_a_volume_is_thin_walled():
    gltf = box_gltf()
    assert not cc.has_thin_walled_transmission(gltf)
    gltf["materials"][0]["extensions"] = {"KHR_materials_transmission": {"transmissionFactor": 0.5}}
    assert cc.has_thin_walled_transmission(gltf)
    gltf["materials"][0]["extensions"]["KHR_materials_volume"] = {"thicknessFactor": 0.0}
    assert cc.has_thin_walled_transmission(gltf)
    gltf["materials"][0]["extensions"]["KHR_materials_volume"] = {"thicknessFactor": 0.01}
    assert not cc.has_thin_walled_transmission(gltf)


def test_default_material_is_made_explicit():
    gltf = box_gltf()
    assert not cc.make_default_material_explicit(copy.deepcopy(gltf))
    del gltf["meshes"][0]["primitives"][0]["material"]
    assert cc.make_default_material_explicit(gltf)
    assert gltf["meshes"][0]["primitives"][0]["material"] == 1
    assert gltf["materials"][1] == {"name": "compare_cycles_default"}


def test_emission_and_lights_are_found():
    gltf = box_gltf()
    assert not cc.has_emission(gltf)
    gltf["materials"][0]["emissiveFactor"] = [0, 0.5, 0]
    assert cc.has_emission(gltf)
    gltf["extensions"] = {"KHR_lights_punctual": {"lights": [
        {"type": "spot", "intensity": 2, "color": [1, 0.5, 0], "spot": {"outerConeAngle": 0.5}}]}}
    gltf["nodes"][0]["extensions"] = {"KHR_lights_punctual": {"light": 0}}
    (light,) = cc.punctual_lights(gltf)
    assert light["type"] == "spot"
    assert light["power"] == pytest.approx([2, 1, 0])
    assert light["direction"] == pytest.approx([0, 0, -1])
    assert light["inner"] == 0.0 and light["outer"] == 0.5


def test_an_orthographic_first_camera_is_kept_with_vkrts_view_height():
    gltf = box_gltf(camera=True)
    gltf["cameras"][0] = {"type": "orthographic", "orthographic": {"xmag": 3, "ymag": 1.5, "znear": 0, "zfar": 9}}
    gltf["nodes"][1]["scale"] = [1, 2, 1]
    camera, origin = cc.choose_camera(gltf)
    assert "orthographic" in origin
    assert camera["ortho_height"] == pytest.approx(2 * 1.5 * 2)
    assert "fov_y" not in camera
    index = cc.add_camera(gltf, camera, 2.0)
    added = gltf["cameras"][index]
    assert added["type"] == "orthographic"
    assert added["orthographic"]["ymag"] == pytest.approx(3.0)
    assert added["orthographic"]["xmag"] == pytest.approx(6.0)

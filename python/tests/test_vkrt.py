"""The Python module against the command line and its own promises
(docs/python.md). Run by ctest (python/CMakeLists.txt) with the build's
package on PYTHONPATH, VKRT_BINARY naming the vkrt executable and
VKRT_TEST_DEVICE the device (lavapipe)."""

import os
import signal
import subprocess
import threading
from pathlib import Path

import numpy as np
import pytest

import vkrt

REPO = Path(__file__).resolve().parents[2]
DEFAULT_SCENE = REPO / "scenes" / "default.toml"
BINARY = os.environ.get("VKRT_BINARY", str(REPO / "build" / "vkrt"))
DEVICE = os.environ.get("VKRT_TEST_DEVICE", "")

SMALL = dict(width=48, height=36, device=DEVICE)


@pytest.fixture(scope="module")
def scene():
    return vkrt.Scene.load(DEFAULT_SCENE)


def cli_render(tmp_path, *args):
    out = tmp_path / "cli.exr"
    device = ["--device", DEVICE] if DEVICE else []
    subprocess.run([BINARY, "render", str(DEFAULT_SCENE), "-o", str(out), *device, *args], check=True,
                   capture_output=True)
    return vkrt.read_exr(out)


# ---------------------------------------------------------------- errors

def test_a_scene_error_names_file_line_and_column(tmp_path):
    # The default scene with its camera's fov (on some line n) out of range.
    lines = DEFAULT_SCENE.read_text().splitlines()
    n = next(i for i, line in enumerate(lines) if line.replace(" ", "").startswith("fov=")) + 1
    lines[n - 1] = "fov = 400"
    with pytest.raises(vkrt.SceneError) as caught:
        vkrt.Scene.from_toml("\n".join(lines), base_dir=DEFAULT_SCENE.parent)
    error = caught.value
    assert error.line == n
    assert error.column is not None and error.column >= 1
    assert error.file.endswith("<string>")
    assert "fov" in str(error)
    assert str(error).startswith(f"{error.file}:{n}:")
    assert error.message and error.message in str(error)


def test_a_syntax_error_is_a_scene_error(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("[camera\n")
    with pytest.raises(vkrt.SceneError) as caught:
        vkrt.Scene.load(bad)
    assert caught.value.file == str(bad)
    assert caught.value.line == 1


def test_a_missing_file_is_a_scene_error_without_position(tmp_path):
    missing = tmp_path / "nowhere.toml"
    with pytest.raises(vkrt.SceneError) as caught:
        vkrt.Scene.load(missing)
    assert caught.value.file == str(missing)
    assert caught.value.line is None and caught.value.column is None
    assert "nowhere.toml" in str(caught.value)


@pytest.mark.parametrize("arguments, words", [
    (dict(spp=0), "spp"),
    (dict(sampler="halton"), "sampler"),
    (dict(integrator="bdpt"), "integrator"),
    (dict(aovs=["albedo", "albedo"]), "twice"),
    (dict(aovs=["colour"]), "unknown AOV"),
    (dict(width=0), "width"),
    (dict(accel="embree"), "accel"),
    (dict(time_budget=-1.0), "time_budget"),
    (dict(spp=-1), "spp: must be between 1 and 1073741824"),
    (dict(spp=2**40), "spp: must be between"),
    (dict(spp=2**31, time_budget=1), "spp: must be between"),
    (dict(width=-5), "width: must be between 1 and 16384"),
    (dict(seed=-1), "seed: must be between 0 and 4294967295"),
])
def test_bad_arguments_raise_value_errors_naming_them(scene, arguments, words):
    with pytest.raises(ValueError, match=words):
        vkrt.render(scene, **{**SMALL, **arguments})


@pytest.mark.parametrize("call, words", [
    (lambda s: vkrt.render(s, accel=None, **SMALL), "accel: expected one of 'auto', 'own', 'driver', got NoneType"),
    (lambda s: vkrt.render(s, aovs=None, **SMALL), "aovs: expected a name or a list of names"),
    (lambda s: vkrt.render(s, spp="3", **SMALL), "spp: expected an integer, got str"),
    (lambda s: vkrt.render(s, spp=True, **SMALL), "spp: expected an integer, got bool"),
    (lambda s: vkrt.render(s, time_budget="1", **SMALL), "time_budget: expected a number or None"),
    (lambda s: next(vkrt.progressive(s, batches="3", **SMALL)), "batches: expected an integer, got str"),
    # bool('no') is True: a flag takes True or False alone.
    (lambda s: vkrt.render(s, variance="no", **SMALL), "variance: expected True or False, got str 'no'"),
    (lambda s: vkrt.render(s, variance=0, **SMALL), "variance: expected True or False, got int 0"),
    (lambda s: next(vkrt.progressive(s, variance=None, **SMALL)), "variance: expected True or False, got NoneType"),
])
def test_wrong_types_raise_type_errors_naming_the_argument(scene, call, words):
    with pytest.raises(TypeError) as caught:
        call(scene)
    assert words in str(caught.value)
    assert "__init__" not in str(caught.value), "pybind11's own message lists the native signature"


def test_a_device_index_is_accepted_as_the_command_line_takes_it(scene):
    # The index of the device the other tests use (VKRT_TEST_DEVICE may name it), as `vkrt devices` lists it.
    listed = vkrt.devices()
    chosen = next(d for d in listed if (DEVICE.lower() in d["name"].lower() if DEVICE else d["default"]))
    by_index = vkrt.render(scene, spp=1, seed=2, width=8, height=8, device=chosen["index"])
    by_name = vkrt.render(scene, spp=1, seed=2, width=8, height=8, device=chosen["name"])
    assert np.array_equal(by_index.image, by_name.image)


def test_a_result_is_not_saved_over_the_scene_it_rendered(tmp_path):
    scene_file = tmp_path / "x.toml"
    scene_file.write_text('[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\nfov = 40\n[background]\ncolor = 0.5\n')
    before = scene_file.read_bytes()
    result = vkrt.render(vkrt.Scene.load(scene_file), spp=1, **SMALL)
    with pytest.raises(Exception, match="the scene file"):
        result.save(scene_file)
    assert scene_file.read_bytes() == before


def test_a_result_is_not_saved_over_a_buffer_the_scenes_gltf_read(tmp_path):
    # The buffer has an image's name: save() through a link to it overwrote it before.
    import struct
    (tmp_path / "x.exr").write_bytes(struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0))
    (tmp_path / "model.gltf").write_text(
        '{"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],'
        ' "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],'
        ' "buffers": [{"uri": "x.exr", "byteLength": 36}], "bufferViews": [{"buffer": 0, "byteLength": 36}],'
        ' "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",'
        ' "min": [0, 0, 0], "max": [1, 1, 0]}]}')
    (tmp_path / "link.exr").symlink_to(tmp_path / "x.exr")
    before = (tmp_path / "x.exr").read_bytes()
    result = vkrt.render(vkrt.Scene.load(tmp_path / "model.gltf"), spp=1, **SMALL)
    for path in (tmp_path / "x.exr", tmp_path / "link.exr"):
        with pytest.raises(Exception, match="a glTF file the scene imports, or a buffer it reads"):
            result.save(path)
    assert (tmp_path / "x.exr").read_bytes() == before


def test_a_material_is_checked_where_the_scene_uses_it():
    scene = vkrt.Scene.from_toml("""
[camera]
eye = [0, 1, 4]
target = [0, 0, 0]
fov = 40
[materials.white]
type = "pbr"
[[objects]]
shape = "sphere"
center = [0, 0, 0]
radius = 1
material = "white"
[[objects]]
shape = "plane"
point = [0, -1, 0]
normal = [0, 1, 0]
material = "white"
""")
    with pytest.raises(ValueError, match="only meshes can use an emissive material"):
        scene.set_material("white", type="pbr", emission=5)
    # Refused, the material is what it was: no emission.
    assert vkrt.render(scene, spp=1, width=8, height=8, device=DEVICE).image.max() == 0.0


def test_camera_values_beyond_float32_are_refused(scene):
    copy = scene.copy()
    with pytest.raises(ValueError, match="aperture_radius: must be between 0 and 1e"):
        copy.set_camera(aperture=1e300)
    with pytest.raises(ValueError, match="focus_distance"):
        copy.set_camera(aperture=0.1, focus_distance=1e20)


def test_measure_error_with_nothing_comparable_is_an_error():
    nan = np.full((2, 2, 3), np.nan, dtype=np.float32)
    with pytest.raises(ValueError, match="nothing to compare"):
        vkrt.measure_error(nan, np.zeros((2, 2, 3), dtype=np.float32))
    assert vkrt.measure_error(np.ones((2, 2, 3)), np.ones((2, 2, 3)))["rmse"] == 0.0


def test_a_device_that_does_not_exist_is_named(scene):
    with pytest.raises(Exception, match="no-such-device"):
        vkrt.render(scene, spp=1, width=8, height=8, device="no-such-device")


# ---------------------------------------------------------------- results

def test_info_describes_the_scene(scene):
    info = scene.info()
    assert info["integrator"] in ("path", "whitted")
    assert info["width"] > 0 and info["height"] > 0
    assert sum(info["shapes"].values()) > 0
    assert any(name.startswith("VKRT_") for name in info["defines"])
    assert info["triangles"] == 0


def test_shapes_and_dtypes(scene):
    r = vkrt.render(scene, spp=2, variance=True, aovs=["albedo", "depth", "normal", "position"], **SMALL)
    assert r.image.shape == (36, 48, 3) and r.image.dtype == np.float32
    assert r.variance.shape == (36, 48, 3)
    assert r.albedo.shape == (36, 48, 3)
    assert r.normal.shape == (36, 48, 3)
    assert r.position.shape == (36, 48, 3)
    assert r.depth.shape == (36, 48)
    assert r.spp == 2
    assert np.isfinite(r.image).all() and r.image.max() > 0
    assert r.metadata["aovs"] == "albedo,depth,normal,position"
    plain = vkrt.render(scene, spp=1, **SMALL)
    assert plain.variance is None and plain.depth is None
    # Views of the pixels save() writes (no copy), so read-only.
    assert not r.image.flags.owndata and not r.image.flags.writeable
    with pytest.raises(ValueError, match="read-only"):
        r.image[0, 0, 0] = 1.0
    assert np.array_equal(r.image.copy(), r.image)


def test_the_image_equals_vkrt_render_bit_for_bit(scene, tmp_path):
    arrays, metadata = cli_render(tmp_path, "--spp", "4", "--seed", "7", "--width", "48", "--height", "36")
    r = vkrt.render(scene, spp=4, seed=7, **SMALL)
    assert np.array_equal(r.image.view(np.uint32), arrays["image"].view(np.uint32))
    # The saved EXR holds the same pixels and the same kind of header.
    saved = tmp_path / "python.exr"
    r.save(saved)
    again, saved_metadata = vkrt.read_exr(saved)
    assert np.array_equal(again["image"].view(np.uint32), arrays["image"].view(np.uint32))
    assert set(saved_metadata) == set(metadata)
    for key in ("seed", "spp", "sampler", "integrator"):
        if key in metadata:
            assert saved_metadata[key] == metadata[key], key


def test_read_exr_returns_every_layer_render_writes(scene, tmp_path):
    aovs = ["albedo", "depth", "normal", "position"]
    r = vkrt.render(scene, spp=2, seed=4, variance=True, aovs=aovs, **SMALL)
    saved = tmp_path / "layers.exr"
    r.save(saved)
    arrays, _ = vkrt.read_exr(saved)
    assert set(arrays) == {"image", "variance", *aovs}
    for name in ("image", "variance", *aovs):
        assert arrays[name].shape == getattr(r, name).shape, name
        assert np.array_equal(arrays[name], getattr(r, name), equal_nan=True), name


def test_save_writes_the_format_its_extension_names(scene, tmp_path):
    r = vkrt.render(scene, spp=2, seed=1, **SMALL)
    png = tmp_path / "out.png"
    r.save(png)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    r.save(tmp_path / "filmic.png", exposure=1.0, filmic=True)
    assert (tmp_path / "filmic.png").read_bytes() != png.read_bytes()
    for bad in ("out.jpg", "out"):
        with pytest.raises(ValueError, match=r"\.exr \(OpenEXR"):
            r.save(tmp_path / bad)
        assert not (tmp_path / bad).exists()
    with pytest.raises(ValueError, match="exposure"):
        r.save(tmp_path / "x.png", exposure=float("nan"))
    layered = vkrt.render(scene, spp=2, variance=True, **SMALL)
    with pytest.raises(ValueError, match="variance"):
        layered.save(tmp_path / "layered.png")


def test_variance_and_aov_layers_equal_vkrt_render(scene, tmp_path):
    arrays, _ = cli_render(tmp_path, "--spp", "3", "--seed", "2", "--width", "48", "--height", "36", "--variance",
                           "--aov", "albedo")
    r = vkrt.render(scene, spp=3, seed=2, variance=True, aovs=["albedo"], **SMALL)
    assert np.array_equal(r.variance, arrays["variance"])
    assert np.array_equal(r.albedo, arrays["albedo"])


def test_a_different_seed_gives_a_different_image(scene):
    a = vkrt.render(scene, spp=1, seed=1, **SMALL)
    b = vkrt.render(scene, spp=1, seed=2, **SMALL)
    assert not np.array_equal(a.image, b.image)


# ---------------------------------------------------------------- progressive

def test_progressive_yields_the_running_mean(scene):
    frames = list(vkrt.progressive(scene, batches=3, spp_per_batch=2, seed=5, **SMALL))
    assert [f.spp for f in frames] == [2, 4, 6]
    for f in frames:
        whole = vkrt.render(scene, spp=f.spp, seed=5, **SMALL)
        assert np.array_equal(f.image, whole.image), f.spp
    # The running mean of k batches is the mean of its batches' own means
    # (to rounding): batch 2's samples are 2 * mean4 - mean2.
    second = 2.0 * frames[1].image.astype(np.float64) - frames[0].image
    assert np.allclose((frames[0].image + second) / 2.0, frames[1].image, rtol=1e-5, atol=1e-6)


# ---------------------------------------------------------------- overrides

def test_a_camera_override_equals_the_same_scene_written_out(tmp_path):
    text = DEFAULT_SCENE.read_text()
    scene = vkrt.Scene.from_toml(text, base_dir=DEFAULT_SCENE.parent)
    camera = scene.camera
    moved_eye = [camera["eye"][0] + 0.25, camera["eye"][1] + 0.1, camera["eye"][2]]
    before = vkrt.render(scene, spp=2, seed=3, **SMALL)
    moved = scene.copy()
    moved.set_camera(eye=moved_eye, fov=camera["fov"] * 0.9)
    after = vkrt.render(moved, spp=2, seed=3, **SMALL)
    assert not np.array_equal(before.image, after.image)
    assert scene.camera["eye"] == camera["eye"]  # the copy changed, not the original

    # The same camera from the file's text: the same image, bit for bit.
    import re
    rewritten = re.sub(r"(?m)^eye\s*=.*$", "eye = [%r, %r, %r]" % tuple(moved_eye), text, count=1)
    rewritten = re.sub(r"(?m)^fov\s*=.*$", "fov = %r" % (camera["fov"] * 0.9), rewritten, count=1)
    assert rewritten != text
    written = vkrt.Scene.from_toml(rewritten, base_dir=DEFAULT_SCENE.parent)
    assert np.array_equal(vkrt.render(written, spp=2, seed=3, **SMALL).image, after.image)


def test_a_camera_the_parser_refuses_changes_nothing(scene):
    copy = scene.copy()
    before = copy.camera
    with pytest.raises(ValueError, match="fov"):
        copy.set_camera(fov=180.0)
    with pytest.raises(ValueError, match="camera"):
        copy.set_camera(target=before["eye"])
    with pytest.raises(ValueError, match="aperture"):
        copy.set_camera(aperture=-1.0)
    assert copy.camera == before


# ---------------------------------------------------------------- devices, threads, interrupt

def test_devices_lists_the_default_device():
    devices = vkrt.devices()
    assert devices, "no Vulkan device"
    defaults = [d for d in devices if d["default"]]
    assert len(defaults) == 1 and defaults[0]["suitable"]
    for d in devices:
        assert {"index", "name", "type", "driver", "api", "ray_query"} <= set(d)


def test_two_threads_render_on_one_device(scene):
    expected = {seed: vkrt.render(scene, spp=2, seed=seed, **SMALL).image for seed in (11, 12)}
    results, errors = {}, []

    def work(seed):
        try:
            results[seed] = vkrt.render(scene, spp=2, seed=seed, **SMALL).image
        except Exception as e:  # pragma: no cover - reported below
            errors.append(e)

    threads = [threading.Thread(target=work, args=(seed,)) for seed in (11, 12)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=300)
    assert not errors
    for seed in (11, 12):
        assert np.array_equal(results[seed], expected[seed])


def interrupt_after(seconds):
    timer = threading.Timer(seconds, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    return timer


def test_ctrl_c_stops_progressive_with_the_image_so_far(scene):
    # The signal comes once rendering runs (a Ctrl-C while the session is
    # made, before any frame, raises KeyboardInterrupt like any other call).
    timer = None
    frames = []
    try:
        for frame in vkrt.progressive(scene, batches=100000, spp_per_batch=1, seed=1, **SMALL):
            frames.append(frame)
            timer = timer or interrupt_after(1.0)
    finally:
        timer and timer.cancel()
    assert frames, "nothing rendered before the interrupt"
    last = frames[-1]
    assert last.interrupted
    assert 0 < last.spp < 100000
    assert np.isfinite(last.image).all() and last.image.max() > 0
    # The device is still usable.
    assert vkrt.render(scene, spp=1, **SMALL).spp == 1


def test_ctrl_c_in_the_loop_body_also_stops_progressive_cleanly(scene):
    import time
    timer = None
    frames = []
    try:
        for frame in vkrt.progressive(scene, batches=1000, spp_per_batch=1, seed=1, **SMALL):
            frames.append(frame)
            timer = timer or interrupt_after(0.5)
            time.sleep(0.2)  # most of the time is spent here, outside the render
    finally:
        timer and timer.cancel()
    assert frames[-1].interrupted and 0 < frames[-1].spp < 1000
    assert [f.spp for f in frames[:-1]] == list(range(1, len(frames)))
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # put back


def test_ctrl_c_stops_render_with_keyboard_interrupt(scene):
    timer = interrupt_after(1.0)
    try:
        with pytest.raises(KeyboardInterrupt):
            vkrt.render(scene, spp=1 << 20, **SMALL)
    finally:
        timer.cancel()
    assert vkrt.render(scene, spp=1, **SMALL).spp == 1


# ---------------------------------------------------------------- materials

def test_a_material_override_equals_the_same_scene_written_out():
    text = DEFAULT_SCENE.read_text()
    scene = vkrt.Scene.from_toml(text, base_dir=DEFAULT_SCENE.parent)
    assert "floor" in scene.materials
    before = vkrt.render(scene, spp=2, seed=4, **SMALL)
    scene.set_material("floor", type="phong", diffuse=[0.9, 0.2, 0.1], specular=0.08, shininess=20)
    after = vkrt.render(scene, spp=2, seed=4, **SMALL)
    assert not np.array_equal(before.image, after.image)

    start = text.index("[materials.floor]")
    end = text.index("\n[", start + 1)
    rewritten = (text[:start] + '[materials.floor]\ntype = "phong"\ndiffuse = [0.9, 0.2, 0.1]\nspecular = 0.08\n'
                 "shininess = 20\n" + text[end:])
    written = vkrt.Scene.from_toml(rewritten, base_dir=DEFAULT_SCENE.parent)
    assert np.array_equal(vkrt.render(written, spp=2, seed=4, **SMALL).image, after.image)


def test_a_material_the_parser_refuses_changes_nothing(scene):
    copy = scene.copy()
    reference = vkrt.render(copy, spp=1, seed=9, **SMALL).image
    with pytest.raises(vkrt.SceneError) as caught:
        copy.set_material("green_matte", type="lambert", albedo=[2.0, 0.0, 0.0])
    assert caught.value.file == "<material green_matte>"
    assert caught.value.line == 2 and caught.value.column is not None
    assert "albedo" in caught.value.message
    with pytest.raises(vkrt.SceneError, match="unknown"):
        copy.set_material("green_matte", type="lambert", colour=[0.5, 0.5, 0.5])
    with pytest.raises(vkrt.SceneError, match="textures"):
        copy.set_material("green_matte", type="lambert", albedo={"texture": "validation/textures/floor.png"})
    with pytest.raises(KeyError, match="no material"):
        copy.set_material("no_such_material", type="lambert")
    assert np.array_equal(vkrt.render(copy, spp=1, seed=9, **SMALL).image, reference)


# ---------------------------------------------------------------- stop rules and the example

def test_stop_rules_and_the_error_estimate(scene):
    by_error = vkrt.render(scene, target_error=0.05, spp=4096, **SMALL)
    assert by_error.stopped_by == "target-error"
    # It stops on the estimate's upper confidence bound (docs/convergence.md).
    assert by_error.error_estimate["rel_mse"] < by_error.error_estimate["rel_mse_upper"] < 0.05
    assert by_error.spp < 4096
    by_time = vkrt.render(scene, time_budget=0.5, **SMALL)
    assert by_time.stopped_by == "time-budget"
    assert by_time.render_seconds >= 0.5 and by_time.spp > 0
    assert vkrt.render(scene, spp=2, **SMALL).error_estimate is None


def test_the_convergence_example_follows_one_over_root_n(tmp_path):
    import importlib.util
    spec = importlib.util.spec_from_file_location("convergence", REPO / "examples" / "convergence.py")
    example = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(example)
    rows, last = example.convergence(vkrt.Scene.load(DEFAULT_SCENE), batches=4, spp_per_batch=8, width=48,
                                     height=36, device=DEVICE)
    assert [spp for spp, _, _ in rows] == [8, 16, 24, 32]
    rmse = [e for _, _, e in rows]
    # An estimate of n samples has RMSE ~ 1 / sqrt(n): 32 spp against 8, half the error (give or take the
    # estimate's own noise over 48 x 36 x 3 values).
    assert 0.4 < rmse[-1] / rmse[0] < 0.6
    out = tmp_path / "convergence.png"
    example.plot(rows, "default", out)
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_session_alive_at_exit_ends_cleanly():
    # A progressive render left half done in a global: its session outlives
    # the module's exit handler and goes during the interpreter's shutdown.
    script = (
        "import vkrt\n"
        f"scene = vkrt.Scene.load({str(DEFAULT_SCENE)!r})\n"
        f"frames = vkrt.progressive(scene, batches=4, width=32, height=24, device={DEVICE!r})\n"
        "first = next(frames)\n"
        "print(first.spp)\n"
    )
    import sys
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300,
                          env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)})
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "1"

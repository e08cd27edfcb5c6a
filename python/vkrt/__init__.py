"""vkrt: a Vulkan compute ray tracer, from Python.

Load a scene, render it on a Vulkan device (lavapipe on any machine), and get
NumPy arrays back::

    import vkrt
    scene = vkrt.Scene.load("scenes/default.toml")
    result = vkrt.render(scene, spp=64, seed=1)
    result.image            # float32, shape (height, width, 3), linear RGB
    result.save("out.exr")  # the EXR `vkrt render` writes for the same arguments

    for frame in vkrt.progressive(scene, batches=8, spp_per_batch=4):
        print(frame.spp, frame.image.mean())

Every render runs the same render session as the command line (one C++ core;
docs/python.md), so an image equals `vkrt render`'s at the same seed and
lavapipe vector width, bit for bit (`vkrt render --vector-width auto` may run
512 bits where this process runs 256: docs/python.md). The GIL is released while the device renders; Ctrl-C stops a render
between submissions.
"""

import json as _json
import numbers as _numbers
import os as _os
import signal as _signal
import threading as _threading
from pathlib import Path as _Path

# An installed wheel carries the kernels' GLSL beside the module; a build tree
# uses the source tree's (compiled into the module), as the vkrt executable does.
_PACKAGED_SHADERS = _Path(__file__).resolve().parent / "shaders"
if (_PACKAGED_SHADERS / "kernels").is_dir():
    _os.environ.setdefault("VKRT_SHADER_DIR", str(_PACKAGED_SHADERS))

from . import _vkrt  # noqa: E402

__all__ = ["Scene", "Result", "SceneError", "VkrtError", "render", "progressive", "devices", "read_exr", "measure_error", "AOVS"]

SceneError = _vkrt.SceneError
SceneError.__doc__ = """A scene that vkrt refuses.

Attributes: ``file`` (the scene file, or the name given to text),
``line`` and ``column`` (1-based; None when the error has no position, such as
an unreadable file) and ``message`` (the reason, without the position).
``str(error)`` is the command line's message: ``file:line:column: message``."""

VkrtError = _vkrt.VkrtError
VkrtError.__doc__ = "A failure of the Vulkan device, the driver or the shader compiler."

AOVS = ("albedo", "normal", "depth", "position")
"""The arbitrary output values a render can add (``aovs=[...]``)."""


class Scene:
    """A parsed and validated scene (docs/scene-format.md).

    Make one with :meth:`Scene.load` or :meth:`Scene.from_toml`. The camera
    can be changed between renders (:meth:`set_camera`) without parsing the
    file again; a render whose kernel variant is unchanged re-uses the
    compiled kernel (vkrt's SPIR-V cache and the driver's shader cache).
    """

    def __init__(self, native):
        self._native = native

    @classmethod
    def load(cls, path):
        """Read a scene file: TOML (docs/scene-format.md) or a glTF .gltf/.glb.

        Raises SceneError (with file, line, column and message) for a file vkrt
        refuses or cannot read.
        """
        return cls(_vkrt.Scene.load(_os.fspath(path)))

    @classmethod
    def from_toml(cls, text, base_dir="."):
        """Parse a scene from TOML text.

        ``base_dir`` is where the scene's relative paths (meshes, textures,
        environment maps) are resolved; errors name the text as
        ``<base_dir>/<string>``.
        """
        return cls(_vkrt.Scene.from_toml(text, _os.fspath(base_dir)))

    @property
    def source(self):
        """The file the scene came from (or ``<base_dir>/<string>``)."""
        return self._native.source

    def info(self):
        """What the scene uses, as a dict: ``integrator``, ``kernel`` (the
        kernel variant in words) and its ``defines``, ``width`` and ``height``,
        ``shapes`` and ``lights`` (counts by kind), ``triangles``,
        ``emissive_triangles`` and ``materials``.

        The variant is the scene's own; render options (sampler, variance,
        AOVs) add defines, listed in a result's ``metadata``.
        """
        return self._native.info()

    @property
    def camera(self):
        """The camera as a dict: ``eye``, ``target``, ``up``, ``fov``
        (vertical, degrees), ``aperture`` (lens radius; 0 for a pinhole),
        ``focus_distance``, ``width``, ``height``."""
        return self._native.camera()

    def set_camera(self, eye=None, target=None, up=None, fov=None, aperture=None, focus_distance=None):
        """Change the camera: any of ``eye``, ``target``, ``up`` (3 numbers
        each), ``fov`` (vertical, degrees, strictly between 0 and 180),
        ``aperture`` (lens radius >= 0) and ``focus_distance`` (> 0).

        Checked with the scene parser's rules; raises ValueError (and changes
        nothing) for a camera the parser would refuse.
        """
        self._native.set_camera(eye, target, up, fov, aperture, focus_distance)

    @property
    def materials(self):
        """The names of the scene's materials, in file order."""
        return self._native.materials()

    def set_material(self, name, **table):
        """Replace material ``name`` by the one ``table`` describes: the keys
        of a ``[materials.NAME]`` table of the scene format, ``type``
        included (docs/scene-format.md), for example
        ``scene.set_material("red", type="lambert", albedo=[0.9, 0.1, 0.1])``.

        Read by the scene parser, so the same values are accepted and refused
        (SceneError, located in the table written out as TOML); textures are
        not accepted here. Raises KeyError for a name the scene lacks.
        """
        if "type" not in table:
            raise ValueError("set_material: give the material's type (and its parameters), as in the scene file")
        self._native.set_material(name, "".join(f"{key} = {_toml_value(value)}\n" for key, value in table.items()))

    def copy(self):
        """An independent copy (meshes and textures are shared, read-only)."""
        return Scene(self._native.copy())

    def __repr__(self):
        return f"vkrt.Scene({self.source!r})"


def _toml_value(value):
    """A Python value as a TOML value (numbers, strings, booleans, sequences, mappings)."""
    if hasattr(value, "tolist"):  # NumPy arrays and scalars
        value = value.tolist()
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return repr(value)  # TOML spells the non-finite ones as Python does: inf, -inf, nan
    if isinstance(value, str):
        return _json.dumps(value)  # a TOML basic string: the same escapes
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k} = {_toml_value(v)}" for k, v in value.items()) + "}"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    raise TypeError(f"cannot write a {type(value).__name__} as a scene value")


class Result:
    """A finished (or interrupted) render.

    ``image`` is the mean radiance, float32 of shape (height, width, 3).
    ``variance`` (the variance of each pixel's mean, same shape) is there
    when the render asked for it. AOVs: ``albedo``, ``normal``, ``position``
    (height, width, 3) and ``depth`` (height, width), each when asked for.
    Absent arrays are None. ``metadata`` holds what the EXR's header gets.
    ``error_estimate`` is the image's estimated error, ``{"rmse": ...,
    "rel_mse": ..., "rel_mse_upper": ...}`` (the last a 95 % upper
    confidence bound on rel_mse, the value ``target_error`` stops on), when
    the render estimated variance (``variance=True`` or ``target_error``),
    else None. ``spp``, ``render_seconds`` (rendering
    only: no start-up or kernel compile), ``stopped_by`` ("spp",
    "time-budget", "target-error", "interrupted") and ``interrupted``
    describe the run.
    """

    def __init__(self, native, interrupted=None):
        self._native = native
        arrays = native.arrays
        self.image = arrays["image"]
        self.variance = arrays.get("variance")
        self.albedo = arrays.get("albedo")
        self.normal = arrays.get("normal")
        self.position = arrays.get("position")
        self.depth = arrays.get("depth")
        self.metadata = dict(native.metadata)
        self.spp = native.spp
        self.render_seconds = native.render_seconds
        self.stopped_by = native.stopped_by
        self.interrupted = native.interrupted if interrupted is None else interrupted
        self.error_estimate = native.error_estimate

    def save(self, path, exposure=0.0, filmic=False):
        """Write the image `vkrt render -o PATH` writes for the same render,
        atomically, in the format of path's extension: .exr (mean, variance
        and AOV layers, metadata) or .png (the mean, 8-bit sRGB, scaled by
        2**exposure and clamped, or through the ACES filmic curve with
        filmic=True; a result with variance or AOV layers must go to an .exr).
        Any other extension raises ValueError naming the formats."""
        exposure = _real("exposure", exposure)
        if exposure is None or not -64.0 <= exposure <= 64.0:
            raise ValueError(f"exposure: must be between -64 and 64 stops, got {exposure}")
        if not isinstance(filmic, bool):
            raise TypeError(f"filmic: must be True or False, got {filmic!r}")
        self._native.save(_os.fspath(path), exposure, filmic)

    def __repr__(self):
        h, w = self.image.shape[:2]
        return f"vkrt.Result({w}x{h}, spp={self.spp}, render_seconds={self.render_seconds:.3f})"


# The command line's limits (docs/cli.md): --spp up to 2^30, image sides up
# to 16384 pixels, 32-bit seeds.
_MAX_SPP = 1 << 30
_MAX_SIDE = 16384
_MAX_SEED = (1 << 32) - 1


def _integer(name, value, low, high):
    """`value` as an int in [low, high]: TypeError for a non-integer (bools
    included), ValueError naming the argument and the range otherwise."""
    if isinstance(value, bool) or not isinstance(value, _numbers.Integral):
        raise TypeError(f"{name}: expected an integer, got {type(value).__name__} {value!r}")
    if not low <= value <= high:
        raise ValueError(f"{name}: must be between {low} and {high}, got {value}")
    return int(value)


def _real(name, value):
    """`value` as a float, or None: TypeError for anything but a real number."""
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, _numbers.Real):
        raise TypeError(f"{name}: expected a number or None, got {type(value).__name__} {value!r}")
    return float(value)


def _flag(name, value):
    """`value` as a bool: TypeError for anything else. bool() would take any
    object, so variance='no' (a non-empty string) would mean True."""
    if isinstance(value, bool) or type(value).__name__ == "bool_":  # NumPy's bool too
        return bool(value)
    raise TypeError(f"{name}: expected True or False, got {type(value).__name__} {value!r}")


def _text(name, value, allowed=None):
    if not isinstance(value, str):
        what = f"one of {', '.join(repr(a) for a in allowed)}" if allowed else "a string"
        raise TypeError(f"{name}: expected {what}, got {type(value).__name__} {value!r}")
    return value


def _aov_list(aovs):
    """The AOV names: one name, or an iterable of names."""
    if isinstance(aovs, str):
        return [aovs]
    try:
        names = list(aovs)
    except TypeError:
        names = None
    if names is None or not all(isinstance(name, str) for name in names):
        raise TypeError('aovs: expected a name or a list of names ("albedo", "normal", "depth", "position"), '
                        f"got {aovs!r}")
    return names


def _session(scene, spp, width, height, seed, sampler, integrator, device, time_budget, target_error, variance,
             aovs, accel):
    """The native session, every argument checked here first: a wrong type or
    range names the argument, as the command line names its option."""
    if not isinstance(scene, Scene):
        raise TypeError(f"scene: expected a vkrt.Scene, got {type(scene).__name__}")
    spp = None if spp is None else _integer("spp", spp, 1, _MAX_SPP)
    width = None if width is None else _integer("width", width, 1, _MAX_SIDE)
    height = None if height is None else _integer("height", height, 1, _MAX_SIDE)
    seed = _integer("seed", seed, 0, _MAX_SEED)
    sampler = _text("sampler", sampler, ("auto", "sobol", "independent"))
    integrator = None if integrator is None else _text("integrator", integrator, ("path", "whitted"))
    if isinstance(device, _numbers.Integral) and not isinstance(device, bool):
        device = str(_integer("device", device, 0, 1 << 16))  # an index, as `--device 1`
    device = _text("device", device)
    accel = _text("accel", accel, ("auto", "own", "driver"))
    return _vkrt.Session(scene._native, spp, width, height, seed, sampler, integrator, device,
                         _real("time_budget", time_budget), _real("target_error", target_error), _flag("variance", variance),
                         _aov_list(aovs), accel)


def render(scene, spp=None, width=None, height=None, seed=0, sampler="auto", integrator=None, device="",
           time_budget=None, target_error=None, variance=False, aovs=(), accel="auto"):
    """Render ``scene`` and return a :class:`Result`.

    Arguments (each as `vkrt render`'s option of the same name; docs/cli.md):

    - ``spp``: samples per pixel (default 64; with ``time_budget`` or
      ``target_error`` alone, no cap).
    - ``width``, ``height``: image size (default: the scene's).
    - ``seed``: the random seed; the same seed gives the same image, bit
      for bit, as `vkrt render --seed`.
    - ``sampler``: "auto", "sobol" or "independent".
    - ``integrator``: "path" or "whitted" (default: the scene's).
    - ``device``: a device index or a case-insensitive part of its name
      (as listed by :func:`devices`); "" picks the default.
    - ``time_budget``: stop after this many seconds of rendering.
    - ``target_error``: stop once the 95 % upper confidence bound on the
      estimated relative MSE is below this (docs/convergence.md: the true
      relMSE then meets it in at least 95 % of runs).
    - ``variance``: also estimate each pixel's variance (``result.variance``).
    - ``aovs``: any of "albedo", "normal", "depth", "position".
    - ``accel``: the traversal backend, "auto", "own" or "driver".

    The GIL is released while rendering; another thread may render on the
    same device meanwhile, and waits for it. Ctrl-C stops the render between
    submissions and raises KeyboardInterrupt.
    """
    session = _session(scene, spp, width, height, seed, sampler, integrator, device, time_budget, target_error,
                       variance, aovs, accel)
    session.run()
    return Result(session.result())


class _FirstCtrlCStops:
    """While active (in the main thread), the first SIGINT asks the session to
    stop after its current submission instead of raising, and a second one
    raises KeyboardInterrupt as usual: the command line's Ctrl-C."""

    def __init__(self, session):
        self._session = session
        self._previous = None
        self.requested = False

    def _handle(self, signum, frame):
        self.requested = True
        self._session.interrupt()
        _signal.signal(_signal.SIGINT, self._previous)  # the second Ctrl-C: the usual KeyboardInterrupt

    def __enter__(self):
        if _threading.current_thread() is _threading.main_thread():
            self._previous = _signal.signal(_signal.SIGINT, self._handle)
        return self

    def __exit__(self, *exc):
        if self._previous is not None and _signal.getsignal(_signal.SIGINT) == self._handle:
            _signal.signal(_signal.SIGINT, self._previous)
        return False


def progressive(scene, batches=8, spp_per_batch=1, width=None, height=None, seed=0, sampler="auto",
                integrator=None, device="", variance=False, aovs=(), accel="auto"):
    """Render ``scene`` in ``batches`` batches of ``spp_per_batch`` samples
    per pixel, yielding a :class:`Result` with the running mean after each.

    The samples are the same as one render of ``batches * spp_per_batch``
    spp (the last result equals :func:`render`'s at that spp and seed).

    Ctrl-C (in the main thread) stops cleanly, whether it comes while a batch
    renders or while the loop's body runs: the render stops after its
    current submission, the generator yields a last result holding the
    samples finished so far with ``interrupted`` set, and ends. A second
    Ctrl-C raises KeyboardInterrupt.
    """
    batches = _integer("batches", batches, 1, _MAX_SPP)
    spp_per_batch = _integer("spp_per_batch", spp_per_batch, 1, _MAX_SPP)
    if batches * spp_per_batch > _MAX_SPP:
        raise ValueError(f"batches * spp_per_batch: at most {_MAX_SPP} samples per pixel, got {batches * spp_per_batch}")
    session = _session(scene, batches * spp_per_batch, width, height, seed, sampler, integrator, device, None, None,
                       variance, aovs, accel)
    with _FirstCtrlCStops(session) as ctrl_c:
        for _ in range(batches):
            try:
                if not ctrl_c.requested:
                    session.run_frames(spp_per_batch)
            except KeyboardInterrupt:  # outside the main thread: Python's own handler raised it
                ctrl_c.requested = True
            if ctrl_c.requested:
                if session.spp > 0:
                    yield Result(session.result(), interrupted=True)
                return
            yield Result(session.result())


def devices():
    """The Vulkan devices, as `vkrt devices` lists them: a list of dicts with
    ``index``, ``name``, ``type``, ``api``, ``driver``, ``default`` (the one
    vkrt picks), ``suitable`` and ``unsuitable_reason``, ``ray_query`` (the
    driver's traversal is available)."""
    return _vkrt.devices()


def read_exr(path):
    """Read an EXR with R, G, B channels (vkrt's or any tool's): returns
    ``(arrays, metadata)``, where ``arrays["image"]`` is float32 of shape
    (height, width, 3), any further RGB layers (``variance``, ``albedo``)
    are under their names, and every other channel is there too, grouped by
    its layer: the AOVs `vkrt render --aov` writes as ``normal`` (N.X/Y/Z,
    shape (height, width, 3)), ``position`` (P.X/Y/Z) and ``depth`` (Z,
    shape (height, width)), as :func:`render` names them; other groups under
    their layer's name, with one entry per channel along the last axis (a
    lone channel of no layer, of shape (height, width)). ``metadata`` holds
    vkrt's header attributes. Raises ValueError naming the file when it is
    missing or damaged."""
    return _vkrt.read_exr(_os.fspath(path))


def measure_error(image, reference):
    """The error of ``image`` against ``reference`` (arrays of shape (height,
    width, 3)) as `vkrt compare` measures it, over the values finite in both:
    a dict with ``rmse``, ``mse``, ``rel_mse`` (squared difference over
    reference squared plus a small epsilon), ``mape``, ``max_abs``,
    ``compared`` and the counts of non-finite values in each. Raises
    ValueError when no value is finite in both (nothing to compare)."""
    return _vkrt.measure_error(image, reference)

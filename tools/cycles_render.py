"""Cycles half of tools/compare_cycles.py: renders one glTF file with Blender's
Cycles (bpy from PyPI, .venv-cycles/) as vkrt would see it. Run by
compare_cycles.py in a child process, one per model:

    .venv-cycles/bin/python tools/cycles_render.py SPEC.json

SPEC.json (written by compare_cycles.py): gltf, output (.exr), width, height,
spp, seed, bounces, threads (0: all), camera {eye, target, up, and fov_y
(vertical, degrees) or ortho_height (orthographic: the view's height)} and
lights [{type, position, direction, power, inner, outer}] in glTF's Y-up
world, white_world (a constant white environment of radiance 1, else black).

The scene: Blender's glTF importer (default options) loads the file; the
lights it made are deleted and the spec's lights made instead (delta lights:
point and spot power 4 pi I W, sun strength E W/m^2, vkrt's radiometric
reading of KHR_lights_punctual); the camera is the spec's, converted to
Blender's Z-up world as the importer converts the scene ((x, y, z) glTF ->
(x, -z, y) Blender), its vertical field of view fixed (sensor fit VERTICAL).
Every Principled BSDF uses single-scatter GGX. Cycles: CPU path tracing, the
given bounces for every kind, no clamping, no glossy filter, no light
threshold, no adaptive sampling, no denoising, box pixel filter 1 pixel wide,
view transform Standard, output a 32-bit float RGB OpenEXR (scene linear).
Prints one line "CYCLES_RENDER_RESULT {json}" with the Blender version and times.
"""
from __future__ import annotations

import json
import math
import sys
import time

import bpy
from mathutils import Matrix, Vector


def to_blender(v) -> Vector:
    """A glTF (Y-up) point or direction in Blender's Z-up world, as the importer converts it."""
    return Vector((v[0], -v[2], v[1]))


def clear_scene() -> None:
    bpy.ops.wm.read_factory_settings(use_empty=True)


def make_camera(scene, camera: dict, size: float) -> None:
    eye = Vector(camera["eye"])
    forward = (Vector(camera["target"]) - eye).normalized()
    right = forward.cross(Vector(camera["up"])).normalized()
    up = right.cross(forward)
    r, u, b, e = to_blender(right), to_blender(up), to_blender(-forward), to_blender(eye)
    matrix = Matrix(((r.x, u.x, b.x, e.x), (r.y, u.y, b.y, e.y), (r.z, u.z, b.z, e.z), (0, 0, 0, 1)))
    data = bpy.data.cameras.new("compare_cycles")
    data.sensor_fit = "VERTICAL"
    if "ortho_height" in camera:  # the view's height in scene units; the width follows the image
        data.type = "ORTHO"
        data.ortho_scale = camera["ortho_height"]
    else:
        data.type = "PERSP"
        data.angle_y = math.radians(camera["fov_y"])
    data.shift_x = data.shift_y = 0.0
    data.clip_start = max(1e-6, 1e-6 * size)
    data.clip_end = 1e6 * max(size, 1.0)
    obj = bpy.data.objects.new("compare_cycles", data)
    scene.collection.objects.link(obj)
    obj.matrix_world = matrix
    scene.camera = obj


def make_lights(scene, lights: list) -> list:
    made = []
    for i, light in enumerate(lights):
        power = [max(0.0, float(c)) for c in light["power"]]
        peak = max(power)
        colour = [c / peak for c in power] if peak > 0 else [1.0, 1.0, 1.0]
        kind = {"point": "POINT", "spot": "SPOT", "directional": "SUN"}[light["type"]]
        data = bpy.data.lights.new(f"compare_cycles_{i}", kind)
        data.color = colour
        if kind == "SUN":
            data.energy = peak  # W/m^2
            data.angle = 0.0
        else:
            data.energy = 4.0 * math.pi * peak  # W, for a radiant intensity of `peak` W/sr
            data.shadow_soft_size = 0.0
        if kind == "SPOT":
            outer, inner = light["outer"], light["inner"]
            data.spot_size = min(2.0 * outer, math.pi)
            data.spot_blend = (outer - inner) / outer if outer > 0 else 0.0
        obj = bpy.data.objects.new(f"compare_cycles_{i}", data)
        scene.collection.objects.link(obj)
        direction = to_blender(light["direction"]).normalized()
        rotation = direction.to_track_quat("-Z", "Y").to_matrix().to_4x4()
        obj.matrix_world = Matrix.Translation(to_blender(light["position"])) @ rotation
        made.append({"type": kind, "energy": data.energy, "color": colour})
    return made


def set_world(scene, white: bool) -> None:
    world = bpy.data.worlds.new("compare_cycles")
    world.use_nodes = True
    background = next(n for n in world.node_tree.nodes if n.type == "BACKGROUND")
    background.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    background.inputs["Strength"].default_value = 1.0 if white else 0.0
    scene.world = world


def single_scatter_ggx() -> int:
    count = 0
    for material in bpy.data.materials:
        if not material.node_tree:
            continue
        for node in material.node_tree.nodes:
            if node.type == "BSDF_PRINCIPLED" and node.distribution != "GGX":
                node.distribution = "GGX"
                count += 1
    return count


def configure(scene, spec: dict) -> None:
    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device = "CPU"
    c.samples = spec["spp"]
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.seed = spec["seed"]
    c.use_animated_seed = False
    b = spec["bounces"]
    c.max_bounces = b
    c.diffuse_bounces = b
    c.glossy_bounces = b
    c.transmission_bounces = b
    c.volume_bounces = b
    c.transparent_max_bounces = max(b, 64)
    c.sample_clamp_direct = 0.0
    c.sample_clamp_indirect = 0.0
    c.blur_glossy = 0.0
    c.caustics_reflective = True
    c.caustics_refractive = True
    c.light_sampling_threshold = 0.0
    c.pixel_filter_type = "BOX"
    c.filter_width = 1.0
    r = scene.render
    r.resolution_x, r.resolution_y = spec["width"], spec["height"]
    r.resolution_percentage = 100
    r.pixel_aspect_x = r.pixel_aspect_y = 1.0
    r.film_transparent = False
    r.use_border = False
    if spec.get("threads"):
        r.threads_mode = "FIXED"
        r.threads = spec["threads"]
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    settings = r.image_settings
    settings.file_format = "OPEN_EXR"
    settings.color_mode = "RGB"
    settings.color_depth = "32"
    settings.exr_codec = "ZIP"
    r.filepath = spec["output"]
    r.use_file_extension = False


def main() -> int:
    spec = json.loads(open(sys.argv[1]).read())
    started = time.perf_counter()
    clear_scene()
    bpy.ops.import_scene.gltf(filepath=spec["gltf"])
    scene = bpy.context.scene
    for obj in list(scene.objects):
        if obj.type in ("LIGHT", "CAMERA"):
            bpy.data.objects.remove(obj, do_unlink=True)
    loaded = time.perf_counter()
    size = max((max(o.dimensions) for o in scene.objects if o.type == "MESH"), default=1.0)
    make_camera(scene, spec["camera"], size)
    lights = make_lights(scene, spec["lights"])
    set_world(scene, spec["white_world"])
    switched = single_scatter_ggx()
    configure(scene, spec)
    bpy.ops.render.render(write_still=True)
    done = time.perf_counter()
    print("CYCLES_RENDER_RESULT " + json.dumps({
        "blender": bpy.app.version_string, "load_seconds": loaded - started, "render_seconds": done - loaded,
        "principled_switched_to_ggx": switched, "lights": lights,
        "materials": len(bpy.data.materials)}), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())

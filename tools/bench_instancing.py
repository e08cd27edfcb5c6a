#!/usr/bin/env python3
"""Instancing at scale: a generated glTF of INSTANCES copies of a mesh of
TRIANGLES triangles (a finely tessellated sphere), placed by one node's
EXT_mesh_gpu_instancing, or with --nodes by one node each. Renders it with
vkrt and prints the whole process's wall time and peak resident memory, as
measured by the kernel (wait4's ru_maxrss), and vkrt's own timing line.

    tools/bench_instancing.py [--instances 10000] [--triangles 100000] [--nodes]
                              [--spp 1] [--size 320x240] [--accel own|driver]
                              [--vkrt build/vkrt] [--keep DIR]

Standard library only. The file goes to a temporary folder (or --keep DIR).
"""
import argparse
import base64
import json
import math
import os
import resource
import struct
import subprocess
import sys
import tempfile
import time


def sphere(triangles: int):
    """A UV sphere of about `triangles` triangles: positions, normals, indices."""
    rings = max(2, int(math.sqrt(triangles / 2)))
    segments = max(3, triangles // (2 * rings))
    positions, normals, indices = [], [], []
    for r in range(rings + 1):
        theta = math.pi * r / rings
        for s in range(segments + 1):
            phi = 2 * math.pi * s / segments
            n = (math.sin(theta) * math.cos(phi), math.cos(theta), math.sin(theta) * math.sin(phi))
            normals.extend(n)
            positions.extend(0.4 * c for c in n)
    for r in range(rings):
        for s in range(segments):
            a = r * (segments + 1) + s
            b = a + segments + 1
            indices.extend((a, b, a + 1, a + 1, b, b + 1))
    return positions, normals, indices


def gltf(instances: int, triangles: int, per_node: bool) -> dict:
    positions, normals, indices = sphere(triangles)
    side = math.ceil(instances ** (1 / 3))
    offsets = []
    for i in range(instances):
        offsets.extend((i % side, (i // side) % side, i // (side * side)))
    blobs = [struct.pack(f"<{len(positions)}f", *positions), struct.pack(f"<{len(normals)}f", *normals),
             struct.pack(f"<{len(indices)}I", *indices)]
    if not per_node:
        blobs.append(struct.pack(f"<{len(offsets)}f", *offsets))
    views, data = [], b""
    for blob in blobs:
        views.append({"buffer": 0, "byteOffset": len(data), "byteLength": len(blob)})
        data += blob
    count = len(positions) // 3
    accessors = [
        {"bufferView": 0, "componentType": 5126, "count": count, "type": "VEC3",
         "min": [-0.4, -0.4, -0.4], "max": [0.4, 0.4, 0.4]},
        {"bufferView": 1, "componentType": 5126, "count": count, "type": "VEC3"},
        {"bufferView": 2, "componentType": 5125, "count": len(indices), "type": "SCALAR"},
    ]
    doc = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2}]}],
        "bufferViews": views,
        "accessors": accessors,
        "buffers": [{"byteLength": len(data),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
    }
    if per_node:
        doc["nodes"] = [{"mesh": 0, "translation": offsets[3 * i:3 * i + 3]} for i in range(instances)]
        doc["scenes"] = [{"nodes": list(range(instances))}]
    else:
        accessors.append({"bufferView": 3, "componentType": 5126, "count": instances, "type": "VEC3"})
        doc["extensionsUsed"] = ["EXT_mesh_gpu_instancing"]
        doc["nodes"] = [{"mesh": 0, "extensions": {"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": 3}}}}]
        doc["scenes"] = [{"nodes": [0]}]
    return doc, len(indices) // 3


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--instances", type=int, default=10000)
    parser.add_argument("--triangles", type=int, default=100000)
    parser.add_argument("--nodes", action="store_true", help="one node per instance instead of EXT_mesh_gpu_instancing")
    parser.add_argument("--spp", type=int, default=1)
    parser.add_argument("--size", default="320x240")
    parser.add_argument("--accel", default="own", choices=["own", "driver", "auto"])
    parser.add_argument("--vkrt", default=os.environ.get("VKRT", "build/vkrt"))
    parser.add_argument("--keep", help="write the glTF and the image into this folder and keep them")
    args = parser.parse_args()
    width, height = (int(v) for v in args.size.split("x"))
    folder = args.keep or tempfile.mkdtemp(prefix="vkrt-instancing-")
    os.makedirs(folder, exist_ok=True)
    doc, made = gltf(args.instances, args.triangles, args.nodes)
    path = os.path.join(folder, "instances.gltf")
    with open(path, "w") as out:
        json.dump(doc, out)
    command = [args.vkrt, "render", path, "--spp", str(args.spp), "--width", str(width), "--height", str(height),
               "--accel", args.accel, "-o", os.path.join(folder, "instances.exr")]
    start = time.monotonic()
    result = subprocess.run(command, capture_output=True, text=True)
    seconds = time.monotonic() - start
    peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss * 1024
    print(f"instances {args.instances} x {made} triangles = {args.instances * made:,} triangles "
          f"({'nodes' if args.nodes else 'EXT_mesh_gpu_instancing'}), file {os.path.getsize(path) / 2**20:.1f} MiB")
    print(f"vkrt exit {result.returncode}: wall {seconds:.2f} s, peak resident {peak / 2**20:.0f} MiB")
    tail = (result.stdout + result.stderr).strip().splitlines()
    for line in tail[-3:]:
        print("  " + line)
    if not args.keep:
        for name in os.listdir(folder):
            os.remove(os.path.join(folder, name))
        os.rmdir(folder)
    return result.returncode


if __name__ == "__main__":
    sys.exit(main())

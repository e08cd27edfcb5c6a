#!/usr/bin/env bash
# Builds the libFuzzer targets (tests/fuzz) with the release's clang (clang-14 on
# Debian 12, clang-19 on Debian 13; VKRT_FUZZ_CXX for another) in build-fuzz/ and
# runs each for SECONDS (default 60) from a seed corpus: the small meshes of
# assets/, a small OBJ written here and the scenes of scenes/. Exits non-zero if either finds a
# crash, a sanitizer report, a leak, a hang or an exception other than
# InputError; the input that did it is kept in build-fuzz/artifacts/.
# The mutation seed is fixed (VKRT_FUZZ_SEED, default 1) so that a CI run
# explores the same inputs each time; set another to search further.
#   tools/fuzz.sh [SECONDS]   environment: JOBS (build jobs, default 2), VKRT_FUZZ_SEED
set -euo pipefail

seconds=${1:-60}
root=$(cd "$(dirname "$0")/.." && pwd)
build=$root/build-fuzz
assets=$root/assets
compiler=${VKRT_FUZZ_CXX:-clang++}

started=$(date +%s)
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER="$compiler" \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" -DVKRT_FUZZ=ON >/dev/null
cmake --build "$build" -j"${JOBS:-2}" --target fuzz_mesh_loader fuzz_scene_parser fuzz_run_inputs
echo "fuzz: build took $(($(date +%s) - started)) s"

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/mesh" "$work/scene" "$work/run" "$build/artifacts"

# A mesh seed is one byte choosing the format (tests/fuzz/fuzz_mesh_loader.cpp:
# 0 OBJ, 1 PLY, 2 glTF, 3 GLB) and then the file. Files over 64 KiB would only
# slow every execution down, so the large assets stay out.
seed() { # SELECTOR FILE
  { printf "\\$(printf '%03o' "$1")"; cat "$2"; } >"$work/mesh/$(basename "$2").seed"
}
for file in "$assets"/*.obj "$assets"/*.ply; do
  [[ -f $file && $(stat -c %s "$file") -le 65536 ]] || continue
  case $file in *.obj) seed 0 "$file" ;; *.ply) seed 1 "$file" ;; esac
done
# The OBJ assets are all over 64 KiB: an OBJ with every statement kind the
# loader reads (positions, uvs, normals, a quad and a pentagon, groups).
cat >"$work/polygons.obj" <<'OBJ'
o polygons
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0.5 1.5 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vt 0.5 1
vn 0 0 1
g quad
f 1/1/1 2/2/1 3/3/1 4/4/1
g pentagon
s 1
f 1//1 2//1 3//1 5//1 4//1
f -5/-5 -4/-4 -3/-3
OBJ
seed 0 "$work/polygons.obj"
seed 3 "$assets/gltf/box01.glb"
# The Cube's .bin as a data: URI, since the fuzzer's file has no neighbours.
sed "s|\"uri\" *: *\"Cube.bin\"|\"uri\": \"data:application/octet-stream;base64,$(base64 -w0 "$assets/gltf/Cube/Cube.bin")\"|" \
  "$assets/gltf/Cube/Cube.gltf" >"$work/Cube.gltf"
seed 2 "$work/Cube.gltf"
for file in "$assets"/gltf/bad/*.gltf; do seed 2 "$file"; done
# glTF scenes with cameras, KHR_lights_punctual lights, material extensions
# and texture transforms (read as whole scenes: scene/GltfScene.h).
for file in "$root"/scenes/gltf/*.gltf; do
  [[ $(stat -c %s "$file") -le 65536 ]] && seed 2 "$file"
done
# Node hierarchies at the bound (kMaxGltfNodeDepth, 1024 levels) and one past
# it, a cycle, and JSON nesting at kMaxGltfJsonNesting (1024) and past it
# (src/mesh/FileMaterials.h): 1024 '[' inside the top-level object are 1025 levels.
gltf_chain() { # DEPTH
  local i nodes=""
  for ((i = 0; i + 1 < $1; i++)); do nodes+="{\"children\": [$((i + 1))]}, "; done
  printf '{"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [%s{}]}' "$nodes"
}
for n in 1024 1025; do gltf_chain $n >"$work/chain-$n.gltf"; seed 2 "$work/chain-$n.gltf"; done
printf '{"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "nodes": [{}, {"children": [2]}, {"children": [1]}]}' \
  >"$work/cycle.gltf"
seed 2 "$work/cycle.gltf"
for n in 1023 1024; do
  { printf '{"asset": {"version": "2.0"}, "extras": '; printf '[%.0s' $(seq $n); printf ']%.0s' $(seq $n); printf '}'; } \
    >"$work/nested-$n.gltf"
  seed 2 "$work/nested-$n.gltf"
done
# Instancing past kMaxGltfTriangles (8 Mi after instancing): 4,096 triangles
# listed as the scene's root 16 and 2,049 times.
gltf_instanced() { # ROOT_LISTINGS
  local bin roots i
  bin=$( { head -c 36 /dev/zero; for ((i = 0; i < 4096; i++)); do printf '\000\000\001\000\002\000'; done; } | base64 -w0)
  roots=0
  for ((i = 1; i < $1; i++)); do roots+=",0"; done
  printf '{"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [%s]}], "nodes": [{"mesh": 0}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
  "buffers": [{"uri": "data:application/octet-stream;base64,%s", "byteLength": 24612}],
  "bufferViews": [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 24576}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
                {"bufferView": 1, "componentType": 5123, "count": 12288, "type": "SCALAR"}]}' "$roots" "$bin"
}
for n in 16 2049; do gltf_instanced $n >"$work/instanced-$n.gltf"; seed 2 "$work/instanced-$n.gltf"; done
# What the glTF reader maps beyond the Cube (src/mesh/GltfReader.h): a sparse
# accessor without a bufferView, an interleaved view, a strip and a fan, a
# primitive without normals beside one with them, COLOR_0 as normalized bytes,
# TEXCOORD_1, EXT_mesh_gpu_instancing, a mirrored node, two scenes and an
# orthographic camera.
python3 - "$work/features.gltf" <<'PY'
import base64, json, struct, sys
b = bytearray()
def view(data, stride=None):
    while len(b) % 4: b.append(0)
    v = {"buffer": 0, "byteOffset": len(b), "byteLength": len(data)}
    if stride: v["byteStride"] = stride
    b.extend(data); views.append(v); return len(views) - 1
views, accessors = [], []
def acc(**a): accessors.append(a); return len(accessors) - 1
inter = view(struct.pack("<18f", 0,0,0, 0,0,1, 1,0,0, 0,0,1, 0,1,0, 0,0,1), 24)
pos = acc(bufferView=inter, componentType=5126, count=3, type="VEC3", min=[0,0,0], max=[1,1,0])
nrm = acc(bufferView=inter, byteOffset=12, componentType=5126, count=3, type="VEC3")
uv = acc(bufferView=view(struct.pack("<6f", 0,0, 1,0, 0,1)), componentType=5126, count=3, type="VEC2")
col = acc(bufferView=view(bytes([255,0,0,255, 0,255,0,128, 0,0,255,0])), componentType=5121, normalized=True, count=3, type="VEC4")
si = view(struct.pack("<2H", 1, 2)); sv = view(struct.pack("<6f", 1,0,0, 0,1,0))
sparse = acc(componentType=5126, count=4, type="VEC3", sparse={"count": 2, "indices": {"bufferView": si, "componentType": 5123}, "values": {"bufferView": sv}})
trs = view(struct.pack("<9f", 0,0,0, 2,0,0, 0,2,0))
tr = acc(bufferView=trs, componentType=5126, count=3, type="VEC3")
doc = {"asset": {"version": "2.0"}, "scene": 1,
  "extensionsUsed": ["EXT_mesh_gpu_instancing", "KHR_materials_variants"],
  "scenes": [{"name": "one", "nodes": [0]}, {"name": "all", "nodes": [0, 1, 2, 3, 4]}],
  "nodes": [{"mesh": 0}, {"mesh": 1, "scale": [-1, 1, 1]}, {"mesh": 2, "translation": [0.001, 0, 0]},
            {"mesh": 0, "extensions": {"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": tr}}}},
            {"camera": 0, "translation": [0, 0, 5]}],
  "cameras": [{"type": "orthographic", "orthographic": {"xmag": 2, "ymag": 1.5, "znear": 0.1, "zfar": 10}}],
  "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [1, 0.5, 0.5, 1]}}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": pos, "NORMAL": nrm, "COLOR_0": col, "TEXCOORD_1": uv}, "material": 0},
                             {"attributes": {"POSITION": pos}, "mode": 5}]},
             {"primitives": [{"attributes": {"POSITION": sparse}, "mode": 6}]},
             {"primitives": [{"attributes": {"POSITION": pos, "TEXCOORD_0": uv}, "mode": 4}]}],
  "accessors": accessors, "bufferViews": views,
  "buffers": [{"byteLength": len(b), "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(b)).decode()}]}
open(sys.argv[1], "w").write(json.dumps(doc))
PY
seed 2 "$work/features.gltf"
# What the third sweep found (issue 58, tests/mesh/gltf_input_rules_test.cpp):
# integer properties written as floats, strings and negatives; sparse indices
# repeated and decreasing; a byteStride under the element; 15,000 nodes (the
# JSON pass was quadratic in a list's length); 70 materials whose 15 texture
# slots each name one embedded PNG; 4,096 instancing copies in one place.
python3 - "$work" <<'PY'
import base64, json, struct, sys, zlib
out = sys.argv[1]
tri = struct.pack("<9f", 0,0,0, 1,0,0, 0,1,0)
def doc(extra_bin=b"", **more):
    b = tri + extra_bin
    d = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
         "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
         "buffers": [{"uri": "data:application/octet-stream;base64," + base64.b64encode(b).decode(), "byteLength": len(b)}],
         "bufferViews": [{"buffer": 0, "byteLength": 36}],
         "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"}]}
    d.update(more)
    return d
def write(name, d):
    open(f"{out}/{name}.gltf", "w").write(json.dumps(d))
for i, (path, value) in enumerate([(("accessors", 0, "byteOffset"), 0.0), (("accessors", 0, "bufferView"), "0"),
                                   (("nodes", 0, "mesh"), -1), (("scene",), 0.0)]):
    d = doc()
    target = d
    for key in path[:-1]: target = target[key]
    target[path[-1]] = value
    write(f"integer-{i}", d)
d = doc(); d["nodes"] = [{"children": [1.0]}, {"mesh": 0, "extensions": {"KHR_lights_punctual": {"light": 0.0}}}]
write("integer-children", d)
for name, targets in [("sparse-repeated", (1, 1)), ("sparse-decreasing", (2, 0))]:
    extra = struct.pack("<2H", *targets) + struct.pack("<6f", 1,0,0, 0,1,0)
    d = doc(extra)
    d["bufferViews"] += [{"buffer": 0, "byteOffset": 36, "byteLength": 4}, {"buffer": 0, "byteOffset": 40, "byteLength": 24}]
    d["accessors"].append({"componentType": 5126, "count": 3, "type": "VEC3", "sparse": {"count": 2,
        "indices": {"bufferView": 1, "componentType": 5123}, "values": {"bufferView": 2}}})
    d["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 1
    write(name, d)
d = doc(); d["bufferViews"][0]["byteStride"] = 4; write("stride", d)
d = doc(); d["nodes"] += [{} for _ in range(15000)]; write("many-nodes", d)
raw = b"".join(b"\0" + bytes(range(i, i + 12)) for i in range(4))
def chunk(kind, data): return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 4, 4, 8, 2, 0, 0, 0)) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")
slot = {"index": 0}
material = {"pbrMetallicRoughness": {"baseColorTexture": slot, "metallicRoughnessTexture": slot},
            "normalTexture": slot, "emissiveTexture": slot, "extensions": {
            "KHR_materials_sheen": {"sheenColorTexture": slot, "sheenRoughnessTexture": slot},
            "KHR_materials_clearcoat": {"clearcoatTexture": slot, "clearcoatRoughnessTexture": slot, "clearcoatNormalTexture": slot},
            "KHR_materials_specular": {"specularTexture": slot, "specularColorTexture": slot},
            "KHR_materials_transmission": {"transmissionTexture": slot},
            "KHR_materials_iridescence": {"iridescenceTexture": slot, "iridescenceThicknessTexture": slot},
            "KHR_materials_anisotropy": {"anisotropyTexture": slot}}}
d = doc(images=[{"uri": "data:image/png;base64," + base64.b64encode(png).decode()}], textures=[{"source": 0}],
        materials=[material] * 70)
d["accessors"].append({"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC2"})
d["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = 1
d["meshes"][0]["primitives"][0]["material"] = 0
write("one-image-many-slots", d)
d = doc(); d["accessors"].append({"componentType": 5126, "count": 4096, "type": "VEC3"})
d["nodes"][0]["extensions"] = {"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": 1}}}
write("copies", d)
PY
for file in "$work"/integer-*.gltf "$work"/sparse-*.gltf "$work"/stride.gltf "$work"/many-nodes.gltf \
  "$work"/one-image-many-slots.gltf "$work"/copies.gltf; do
  seed 2 "$file"
done
find "$root/scenes" -name '*.toml' -exec cp {} "$work/scene/" \;
# Nesting at the parser's bound (kMaxTomlNesting, 128 levels) and one past it,
# as a header, a dotted key and inline tables, so mutations explore both sides.
nested() { # COUNT SEPARATOR
  local text=a i
  for ((i = 1; i < $1; i++)); do text+="$2a"; done
  printf '%s' "$text"
}
for n in 127 129; do
  printf '[%s]\nx = 1\n' "$(nested $n .)" >"$work/scene/header-$n.toml"
  printf '%s = 1\n' "$(nested $n .)" >"$work/scene/dotted-$n.toml"
  { printf 'x = '; for ((i = 1; i < n; i++)); do printf '{a = '; done
    printf 1; for ((i = 1; i < n; i++)); do printf '}'; done; echo; } >"$work/scene/inline-$n.toml"
done

# fuzz_run_inputs: a selector byte (tests/fuzz/fuzz_run_inputs.cpp: 0 an
# image, 1 a baseline, 2 a pattern list, 3 a suite manifest), then the file.
run_seed() { # SELECTOR NAME
  { printf "\\$(printf '%03o' "$1")"; cat; } >"$work/run/$2.seed"
}
# Radiance .hdr: a flat 4x2 image, an RLE 16x2 one (a repeated and a literal run per channel), the
# sweep's zero-run file and a header claiming 8192x8192.
{ printf '#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 4\n'; printf '\200\100\040\201%.0s' 1 2 3 4 5 6 7 8; } | run_seed 0 hdr-flat
{ printf '#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 16\n'
  for row in 1 2; do printf '\002\002\000\020'; for c in 1 2 3; do printf '\210\200\010ABCDEFGH'; done
    printf '\220\201'; done; } | run_seed 0 hdr-rle
printf '#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 64\n\002\002\000\100' | run_seed 0 hdr-zero-run
printf '#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 8192 +X 8192\n' | run_seed 0 hdr-claim
for file in "$root"/scenes/validation/textures/*.png; do
  if [[ -f $file && $(stat -c %s "$file") -le 65536 ]]; then run_seed 0 "$(basename "$file")" <"$file"; fi
done
# An 8x8 JPEG's headers (quantization, frame, Huffman and scan headers) and
# no scan data: stb_image decoded it as black (issue 58).
python3 -c '
import struct, sys
def segment(marker, body): return b"\xff" + bytes([marker]) + struct.pack(">H", len(body) + 2) + body
jpeg = (b"\xff\xd8" + segment(0xDB, b"\x00" + b"\x01" * 64)
        + segment(0xC0, b"\x08\x00\x08\x00\x08\x01\x01\x11\x00")
        + segment(0xC4, b"\x00" + b"\x01" + b"\x00" * 15 + b"\x00")
        + segment(0xC4, b"\x10" + b"\x01" + b"\x00" * 15 + b"\x00")
        + segment(0xDA, b"\x01\x01\x00\x00\x3f\x00") + b"\xff\xd9")
sys.stdout.buffer.write(jpeg)' | run_seed 0 jpeg-headers-only
printf '# known failures\nextreme/tir,Fail\nseed/glass,Crash,1.5\nvalidation/x,Timeout\n' | run_seed 1 baseline
printf 'kappa-\n^seed/glass$\nvalidation/.*texture\n^(.*.*.*.*.*.*.*.*.*.*)*Q$\n' | run_seed 2 patterns
run_seed 3 suite <"$root/tests/regress/suite.toml"

status=0
run() { # TARGET CORPUS
  echo "fuzz: running $1 for $seconds s on $(find "$2" -type f | wc -l) seeds"
  if ! "$build/tests/fuzz/$1" -max_total_time="$seconds" -seed="${VKRT_FUZZ_SEED:-1}" -max_len=65536 -timeout=10 -rss_limit_mb=2048 \
    -print_final_stats=1 -artifact_prefix="$build/artifacts/$1-" "$2" >"$work/$1.log" 2>&1; then
    status=1
    tail -n 60 "$work/$1.log"
    echo "fuzz: $1 FAILED; the input is in $build/artifacts/" >&2
  fi
  grep -E '^stat::(number_of_executed_units|average_exec_per_sec|new_units_added|peak_rss_mb)' "$work/$1.log" |
    sed "s/^/fuzz: $1 /" || true
}
run fuzz_mesh_loader "$work/mesh"
run fuzz_scene_parser "$work/scene"
run fuzz_run_inputs "$work/run"
exit $status

// Descriptor binding indices, workgroup shape and per-invocation limits: the
// single definition used by the kernel builder (C++) and the kernels (GLSL).
#ifndef VKRT_SHARED_BINDINGS_H
#define VKRT_SHARED_BINDINGS_H
#include "Interop.h"
#include "Kinds.h"

VKRT_BEGIN_NAMESPACE

// All kernels use descriptor set 0.
VKRT_CONSTANT(uint, BINDING_UNIFORMS, 0)     // SceneUniforms (uniform buffer)
VKRT_CONSTANT(uint, BINDING_ACCUMULATION, 1) // AccumPixel[width*height]
VKRT_CONSTANT(uint, BINDING_STATS, 2)        // RenderStats
VKRT_CONSTANT(uint, BINDING_MATERIALS, 3)    // Material[]
// Then one array per shape and light kind of the registry (shared/Kinds.h), in
// its order: BINDING_SPHERES = 4 (Sphere[]), ..., BINDING_TRIANGLE_LIGHTS = 9.
#define VKRT_SHAPE_BINDING(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    VKRT_CONSTANT(uint, BINDING_##ARRAY, 4 + value)
#define VKRT_LIGHT_BINDING(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    VKRT_CONSTANT(uint, BINDING_##ARRAY, 4 + SHAPE_KIND_COUNT + value)
VKRT_SHAPE_KINDS(VKRT_SHAPE_BINDING)
VKRT_LIGHT_KINDS(VKRT_LIGHT_BINDING)
VKRT_CONSTANT(uint, BINDING_ENVIRONMENT, 4 + SHAPE_KIND_COUNT + LIGHT_KIND_COUNT) // samplerCube of environment radiance
// Variance estimation: MomentPixel[width*height], or under the Sobol' sampler
// AccumPixel[width*height*VARIANCE_BATCHES].
VKRT_CONSTANT(uint, BINDING_MOMENTS, BINDING_ENVIRONMENT + 1)
// float[6 N^2 + 1]: cumulative texel probabilities.
VKRT_CONSTANT(uint, BINDING_ENVIRONMENT_CDF, BINDING_ENVIRONMENT + 2)
// Meshes (always storage buffers): every geometry's BVH nodes, triangles
// in leaf order and shading normals; the top-level BVH over every bounded
// record and its leaf references (uint TOP_REF); emissive mesh triangles.
VKRT_CONSTANT(uint, BINDING_MESH_NODES, BINDING_ENVIRONMENT + 3)
VKRT_CONSTANT(uint, BINDING_MESH_TRIANGLES, BINDING_ENVIRONMENT + 4)
VKRT_CONSTANT(uint, BINDING_MESH_NORMALS, BINDING_ENVIRONMENT + 5)
VKRT_CONSTANT(uint, BINDING_TOP_NODES, BINDING_ENVIRONMENT + 6)
VKRT_CONSTANT(uint, BINDING_TOP_REFS, BINDING_ENVIRONMENT + 7)
VKRT_CONSTANT(uint, BINDING_EMITTERS, BINDING_ENVIRONMENT + 8)
// float[]: the rough plastics' coating tables (shared/SceneTypes.h: MATERIAL_TABLE_SIZE)
VKRT_CONSTANT(uint, BINDING_MATERIAL_TABLES, BINDING_ENVIRONMENT + 9)
// Image textures (shared/TextureTypes.h, variants with textures only): every
// texel of every texture in one buffer of words (an array of buffers, chunks
// of those words, where they exceed one buffer), the TextureRecord table, and
// per material its MaterialTextures.
VKRT_CONSTANT(uint, BINDING_TEXTURE_TEXELS, BINDING_ENVIRONMENT + 10)
VKRT_CONSTANT(uint, BINDING_TEXTURE_RECORDS, BINDING_ENVIRONMENT + 11)
VKRT_CONSTANT(uint, BINDING_MATERIAL_TEXTURES, BINDING_ENVIRONMENT + 12)
// Per mesh triangle, in leaf order beside meshTriangles: texture coordinates
// (MeshUvs, variants with textures), tangents (MeshTangents, normal maps) and
// the scene material of each triangle (uint, meshes with file materials).
VKRT_CONSTANT(uint, BINDING_MESH_UVS, BINDING_ENVIRONMENT + 13)
VKRT_CONSTANT(uint, BINDING_MESH_TANGENTS, BINDING_ENVIRONMENT + 14)
VKRT_CONSTANT(uint, BINDING_MESH_MATERIALS, BINDING_ENVIRONMENT + 15)
// FrameRun: which frames the dispatches of the current run add.
VKRT_CONSTANT(uint, BINDING_FRAME_RUN, BINDING_ENVIRONMENT + 16)
// AovPixel[width*height]: the arbitrary output values (render --aov).
VKRT_CONSTANT(uint, BINDING_AOVS, BINDING_ENVIRONMENT + 17)
// The driver traversal backend's top-level acceleration structure
// (accelerationStructureEXT; lib/ray_query.glsl, render/DriverAccel.h).
VKRT_CONSTANT(uint, BINDING_TOP_LEVEL, BINDING_ENVIRONMENT + 18)
VKRT_CONSTANT(uint, BINDING_MATERIAL_ALPHA, BINDING_ENVIRONMENT + 19)
// Per mesh triangle, beside meshTriangles: vertex colours (MeshColors, meshes with COLOR_0 and file materials).
VKRT_CONSTANT(uint, BINDING_MESH_COLORS, BINDING_ENVIRONMENT + 20)
// Per mesh triangle, beside meshUvs: the second texture coordinate set (MeshUvs
// of glTF TEXCOORD_1; variants where some texture reads it).
VKRT_CONSTANT(uint, BINDING_MESH_UVS1, BINDING_ENVIRONMENT + 21)
// LightPick[]: the light table of scenes with many lights (VKRT_LIGHT_TABLE).
VKRT_CONSTANT(uint, BINDING_LIGHT_TABLE, BINDING_ENVIRONMENT + 22)
// The render kernels read every read-only scene buffer through its device
// address, SceneUniforms::bufferAddresses[binding] (lib/scene_buffers.glsl),
// not through its descriptor: one slot per binding up to here.
VKRT_CONSTANT(uint, ADDRESSED_BINDING_COUNT, BINDING_ENVIRONMENT + 23)
// The staged kernels' lanes (lib/stages.glsl: StagedLane per pixel, after a
// header of 4 words), in variants with VKRT_STAGE only.
#if defined(__cplusplus) || defined(VKRT_STAGE)
VKRT_CONSTANT(uint, BINDING_STAGED_LANES, BINDING_ENVIRONMENT + 23)
// 16-byte words per lane (lib/stages.glsl lists them), after one word of header.
VKRT_CONSTANT(uint, STAGED_LANE_VEC4S, 18)
#endif
// Host only: a GLSL constant of a new value is emitted into every variant's
// SPIR-V (glslang keeps folded constants), so a binding added for one feature
// would change every kernel; the kernels never need the count.
#ifdef __cplusplus
VKRT_CONSTANT(uint, BINDING_COUNT, BINDING_ENVIRONMENT + 24)
#endif

// BVH traversal keeps a stack of this many nodes per level (top and mesh);
// the host refuses trees deeper than this (src/mesh/MeshGeometry.cpp).
VKRT_CONSTANT(uint, BVH_STACK_SIZE, 64)

// Under the Sobol' sampler the variance comes from this many independently
// scrambled batches (frame f is sample f / K of batch f % K; lib/sobol.glsl):
// 7 degrees of freedom per pixel, at a cost in accuracy that grows with K.
VKRT_CONSTANT(uint, VARIANCE_BATCHES, 8)

// 8x8 workgroups: lavapipe runs 8-wide subgroups and 64 invocations per group
// measured fastest (shared/NUMERICS.md); square tiles keep rays coherent.
VKRT_CONSTANT(uint, WORKGROUP_SIZE_X, 8)
VKRT_CONSTANT(uint, WORKGROUP_SIZE_Y, 8)

// lavapipe silently ends every loop of an invocation after 65,535 iterations in
// total. Kernels count their loop iterations; the host refuses scenes whose
// worst case could exceed this budget and reports any kernel that reaches it.
VKRT_CONSTANT(uint, LOOP_BUDGET, 65535)

// A shadow ray passes through at most this many dielectric interfaces; a ray
// that would cross more is treated as blocked (documented in docs/whitted.md).
VKRT_CONSTANT(uint, MAX_SHADOW_CROSSINGS, 16)

// Dielectrics a ray can be inside at once (nested or overlapping glass); a
// deeper nest is treated as this many levels (docs/robustness.md).
VKRT_CONSTANT(uint, MEDIUM_STACK_DEPTH, 4)

VKRT_END_NAMESPACE

#endif

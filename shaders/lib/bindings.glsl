// Resource declarations of the render kernels. Each scene buffer exists only
// in the variants whose features need it (src/render/KernelVariant.cpp), and the
// host builds the descriptor set layout from the same list.
#ifndef VKRT_BINDINGS_GLSL
#define VKRT_BINDINGS_GLSL

#include "shared/Bindings.h"
#include "shared/SceneTypes.h"

#ifdef VKRT_TEST_NO_ENVIRONMENT_SAMPLING
// Measurement hook: the environment found by BSDF sampling alone, to show
// what importance sampling it gains (tests/render/latlong_environment_test.cpp).
#undef VKRT_ENVIRONMENT_SAMPLING
#endif

layout(scalar, binding = BINDING_UNIFORMS) uniform UniformBlock { SceneUniforms u; };
layout(scalar, binding = BINDING_ACCUMULATION) buffer AccumBlock { AccumPixel accum[]; };
layout(scalar, binding = BINDING_STATS) buffer StatsBlock { RenderStats stats; };
layout(push_constant, scalar) uniform PushBlock { FrameConstants frame; };
layout(scalar, binding = BINDING_FRAME_RUN) readonly buffer FrameRunBlock { FrameRun run; };
#if defined(VKRT_VARIANCE) && defined(VKRT_SAMPLER_SOBOL)
// One compensated sum per pixel and batch (pixel-major), lib/accumulate.glsl.
layout(scalar, binding = BINDING_MOMENTS) buffer BatchBlock { AccumPixel batchSums[]; };
#elif defined(VKRT_VARIANCE)
layout(scalar, binding = BINDING_MOMENTS) buffer MomentBlock { MomentPixel moments[]; };
#endif
#ifdef VKRT_AOV
layout(scalar, binding = BINDING_AOVS) buffer AovBlock { AovPixel aovs[]; };
#endif

// Scene arrays: fixed-size uniform blocks in the uniform-scene variant,
// read buffers otherwise (shared/SceneTypes.h, lib/scene_buffers.glsl). Each
// shape and light kind declares its own array in its file (lib/shapes/*.glsl,
// lib/lights/*.glsl); the top-level BVH is declared by lib/scene.glsl and the
// emitters by lib/emitters.glsl.
#include "lib/scene_buffers.glsl"

#ifdef VKRT_HAS_MATERIALS
VKRT_SCENE_ARRAY(BINDING_MATERIALS, MaterialBlock, Material, materials, UNIFORM_MATERIALS)
#define materials VKRT_SCENE_ITEMS(BINDING_MATERIALS, MaterialBlock, materials)
#endif
#ifdef VKRT_HAS_MESHES
#ifndef VKRT_ACCEL_DRIVER // the driver backend walks its own structures instead
VKRT_READ_BUFFER(BINDING_MESH_NODES, MeshNodeBlock, BvhNode, meshNodes)
#define meshNodes VKRT_READ_ITEMS(BINDING_MESH_NODES, MeshNodeBlock, meshNodes)
#endif
VKRT_READ_BUFFER(BINDING_MESH_TRIANGLES, MeshTriangleBlock, MeshTriangle, meshTriangles)
#define meshTriangles VKRT_READ_ITEMS(BINDING_MESH_TRIANGLES, MeshTriangleBlock, meshTriangles)
#endif
#ifdef VKRT_HAS_MESH_NORMALS
VKRT_READ_BUFFER(BINDING_MESH_NORMALS, MeshNormalBlock, MeshNormals, meshNormals)
#define meshNormals VKRT_READ_ITEMS(BINDING_MESH_NORMALS, MeshNormalBlock, meshNormals)
#endif
#ifdef VKRT_HAS_MATERIAL_TABLES
VKRT_READ_BUFFER(BINDING_MATERIAL_TABLES, MaterialTableBlock, float, materialTables)
#define materialTables VKRT_READ_ITEMS(BINDING_MATERIAL_TABLES, MaterialTableBlock, materialTables)
#endif
#ifdef VKRT_HAS_TEXTURES
// The texel and record buffers are declared by lib/texture_bindings.glsl.
#include "shared/TextureTypes.h"
VKRT_READ_BUFFER(BINDING_MATERIAL_TEXTURES, MaterialTextureBlock, MaterialTextures, materialTextures)
#define materialTextures VKRT_READ_ITEMS(BINDING_MATERIAL_TEXTURES, MaterialTextureBlock, materialTextures)
#endif
#ifdef VKRT_HAS_MESH_UVS
VKRT_READ_BUFFER(BINDING_MESH_UVS, MeshUvBlock, MeshUvs, meshUvs)
#define meshUvs VKRT_READ_ITEMS(BINDING_MESH_UVS, MeshUvBlock, meshUvs)
#endif
#ifdef VKRT_HAS_MESH_UVS1
VKRT_READ_BUFFER(BINDING_MESH_UVS1, MeshUv1Block, MeshUvs, meshUvs1)
#define meshUvs1 VKRT_READ_ITEMS(BINDING_MESH_UVS1, MeshUv1Block, meshUvs1)
#endif
#ifdef VKRT_HAS_MESH_UVS
// Mesh triangle `index`'s uv of set `set` (TextureSlot::texCoord) at
// barycentrics b. Both buffers hold every triangle, zeros where its mesh
// lacks the set; set 1 reads set 0 in variants without a second set.
vec2 meshTriangleUv(uint index, uint set, vec3 b)
{
#ifdef VKRT_HAS_MESH_UVS1
    if (set == 1u)
        return b.x * meshUvs1[index].uv0 + b.y * meshUvs1[index].uv1 + b.z * meshUvs1[index].uv2;
#endif
    return b.x * meshUvs[index].uv0 + b.y * meshUvs[index].uv1 + b.z * meshUvs[index].uv2;
}
#endif
#ifdef VKRT_HAS_MESH_TANGENTS
VKRT_READ_BUFFER(BINDING_MESH_TANGENTS, MeshTangentBlock, MeshTangents, meshTangents)
#define meshTangents VKRT_READ_ITEMS(BINDING_MESH_TANGENTS, MeshTangentBlock, meshTangents)
#endif
#ifdef VKRT_HAS_MESH_MATERIALS
VKRT_READ_BUFFER(BINDING_MESH_MATERIALS, MeshMaterialBlock, uint, meshMaterials)
#define meshMaterials VKRT_READ_ITEMS(BINDING_MESH_MATERIALS, MeshMaterialBlock, meshMaterials)
#endif
#ifdef VKRT_HAS_MESH_COLORS
VKRT_READ_BUFFER(BINDING_MESH_COLORS, MeshColorBlock, MeshColors, meshColors)
#define meshColors VKRT_READ_ITEMS(BINDING_MESH_COLORS, MeshColorBlock, meshColors)
#endif
// Shading normals differ from geometric ones with meshes' vertex normals or normal maps.
#if defined(VKRT_HAS_MESH_NORMALS) || defined(VKRT_HAS_NORMAL_MAPS)
#define VKRT_HAS_SHADING_NORMALS
#endif
#if defined(VKRT_HAS_LATLONG)
layout(binding = BINDING_ENVIRONMENT) uniform sampler2D environmentLatLong;
#elif defined(VKRT_HAS_CUBEMAP)
layout(binding = BINDING_ENVIRONMENT) uniform samplerCube environmentMap;
#endif
#ifdef VKRT_ENVIRONMENT_SAMPLING
VKRT_READ_BUFFER(BINDING_ENVIRONMENT_CDF, EnvironmentCdfBlock, float, environmentCdf)
#define environmentCdf VKRT_READ_ITEMS(BINDING_ENVIRONMENT_CDF, EnvironmentCdfBlock, environmentCdf)
#endif

#endif

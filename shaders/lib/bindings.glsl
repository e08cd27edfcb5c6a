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
// runtime-sized storage buffers otherwise (shared/SceneTypes.h). Each shape
// and light kind declares its own array in its file (lib/shapes/*.glsl,
// lib/lights/*.glsl); the top-level BVH is declared by lib/scene.glsl and the
// emitters by lib/emitters.glsl.
#ifdef VKRT_UNIFORM_SCENE
#define VKRT_SCENE_ARRAY(binding_, Block, Type, name, capacity) \
    layout(scalar, binding = binding_) uniform Block { Type name[capacity]; };
#else
#define VKRT_SCENE_ARRAY(binding_, Block, Type, name, capacity) \
    layout(scalar, binding = binding_) readonly buffer Block { Type name[]; };
#endif

#ifdef VKRT_HAS_MATERIALS
VKRT_SCENE_ARRAY(BINDING_MATERIALS, MaterialBlock, Material, materials, UNIFORM_MATERIALS)
#endif
#ifdef VKRT_HAS_MESHES
#ifndef VKRT_ACCEL_DRIVER // the driver backend walks its own structures instead
layout(scalar, binding = BINDING_MESH_NODES) readonly buffer MeshNodeBlock { BvhNode meshNodes[]; };
#endif
layout(scalar, binding = BINDING_MESH_TRIANGLES) readonly buffer MeshTriangleBlock { MeshTriangle meshTriangles[]; };
#endif
#ifdef VKRT_HAS_MESH_NORMALS
layout(scalar, binding = BINDING_MESH_NORMALS) readonly buffer MeshNormalBlock { MeshNormals meshNormals[]; };
#endif
#ifdef VKRT_HAS_MATERIAL_TABLES
layout(scalar, binding = BINDING_MATERIAL_TABLES) readonly buffer MaterialTableBlock { float materialTables[]; };
#endif
#ifdef VKRT_HAS_TEXTURES
// The texel and record buffers are declared by lib/texture_bindings.glsl.
#include "shared/TextureTypes.h"
layout(scalar, binding = BINDING_MATERIAL_TEXTURES) readonly buffer MaterialTextureBlock
{
    MaterialTextures materialTextures[];
};
#endif
#ifdef VKRT_HAS_MESH_UVS
layout(scalar, binding = BINDING_MESH_UVS) readonly buffer MeshUvBlock { MeshUvs meshUvs[]; };
#endif
#ifdef VKRT_HAS_MESH_UVS1
layout(scalar, binding = BINDING_MESH_UVS1) readonly buffer MeshUv1Block { MeshUvs meshUvs1[]; };
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
layout(scalar, binding = BINDING_MESH_TANGENTS) readonly buffer MeshTangentBlock { MeshTangents meshTangents[]; };
#endif
#ifdef VKRT_HAS_MESH_MATERIALS
layout(scalar, binding = BINDING_MESH_MATERIALS) readonly buffer MeshMaterialBlock { uint meshMaterials[]; };
#endif
#ifdef VKRT_HAS_MESH_COLORS
layout(scalar, binding = BINDING_MESH_COLORS) readonly buffer MeshColorBlock { MeshColors meshColors[]; };
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
layout(scalar, binding = BINDING_ENVIRONMENT_CDF) readonly buffer EnvironmentCdfBlock { float environmentCdf[]; };
#endif

#endif

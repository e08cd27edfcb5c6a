// Host-side checks of the GPU record layouts in shaders/shared. The kernels use
// the GLSL scalar block layout, in which every member here is aligned to 4
// bytes; C++ lays the same members out identically as long as no padding
// appears, which these asserts guarantee. tests/gpu/shared_layout_test.cpp
// compares every member offset with glslang's reflection.
#include "shared/Bindings.h"
#include "shared/SceneTypes.h"

#include <cstddef>

namespace vkrt::gpu {

static_assert(alignof(vec3) == 4 && sizeof(vec3) == 12, "GLM vec3 must be three packed floats");
static_assert(sizeof(Material) == 176);
// The shape and light records' sizes are pinned by their registry capacities
// below: 16384 / (capacity + 1) < size <= 16384 / capacity admits one size.
// Each uniform scene array fills at most the 16 KiB every Vulkan device allows.
constexpr uint32_t kUniformArrayBytes = 16384;
static_assert(UNIFORM_MATERIALS * sizeof(Material) <= kUniformArrayBytes &&
              (UNIFORM_MATERIALS + 1) * sizeof(Material) > kUniformArrayBytes);
// The registry's capacities (shared/Kinds.h) are exactly what 16 KiB holds.
#define VKRT_CHECK_CAPACITY(KIND, Type, name, value, field, array, ARRAY, capacity, bounded)             \
    static_assert(capacity == UNIFORM_##ARRAY && UNIFORM_##ARRAY * sizeof(Type) <= kUniformArrayBytes && \
                      (UNIFORM_##ARRAY + 1) * sizeof(Type) > kUniformArrayBytes,                         \
                  "shared/Kinds.h: the capacity of " #array " must be 16384 / sizeof(" #Type ")");
VKRT_SHAPE_KINDS(VKRT_CHECK_CAPACITY)
VKRT_LIGHT_KINDS(VKRT_CHECK_CAPACITY)
#undef VKRT_CHECK_CAPACITY

// Every scene array has a binding of its own, distinct from the fixed ones.
#define VKRT_BINDING_OF(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) BINDING_##ARRAY,
constexpr uint kSceneArrayBindings[] = {BINDING_MATERIALS,
                                        VKRT_SHAPE_KINDS(VKRT_BINDING_OF) VKRT_LIGHT_KINDS(VKRT_BINDING_OF)};
#undef VKRT_BINDING_OF
constexpr bool bindingsDistinct()
{
    constexpr uint fixed[] = {BINDING_UNIFORMS,          BINDING_ACCUMULATION,   BINDING_STATS,
                              BINDING_ENVIRONMENT,       BINDING_MOMENTS,        BINDING_ENVIRONMENT_CDF,
                              BINDING_MESH_NODES,        BINDING_MESH_TRIANGLES, BINDING_MESH_NORMALS,
                              BINDING_TOP_NODES,         BINDING_TOP_REFS,       BINDING_EMITTERS,
                              BINDING_MATERIAL_TABLES,   BINDING_TEXTURE_TEXELS, BINDING_TEXTURE_RECORDS,
                              BINDING_MATERIAL_TEXTURES, BINDING_MESH_UVS,       BINDING_MESH_TANGENTS,
                              BINDING_MESH_MATERIALS,    BINDING_FRAME_RUN,      BINDING_AOVS,
                              BINDING_TOP_LEVEL,         BINDING_MESH_COLORS,    BINDING_MATERIAL_ALPHA,
                              BINDING_MESH_UVS1,         BINDING_LIGHT_TABLE};
    for (uint a : kSceneArrayBindings) {
        if (a >= BINDING_COUNT) return false;
        for (uint f : fixed)
            if (a == f) return false;
        int seen = 0;
        for (uint b : kSceneArrayBindings) seen += a == b;
        if (seen != 1) return false;
    }
    return true;
}
static_assert(bindingsDistinct(), "shared/Bindings.h: every scene array needs its own binding below BINDING_COUNT");
static_assert(sizeof(SceneUniforms) == 180 + 4 * (SHAPE_KIND_COUNT + LIGHT_KIND_COUNT) + 8 * ADDRESSED_BINDING_COUNT,
              "SceneUniforms holds one count per shape and light kind and one address per read-only binding");
// The read-only scene buffers' addresses sit at their bindings (lib/scene_buffers.glsl).
static_assert(BINDING_LIGHT_TABLE < ADDRESSED_BINDING_COUNT && BINDING_MESH_UVS1 < ADDRESSED_BINDING_COUNT &&
              BINDING_MATERIAL_ALPHA < ADDRESSED_BINDING_COUNT && ADDRESSED_BINDING_COUNT <= BINDING_COUNT);
static_assert(MEDIUM_STACK_DEPTH == 4, "lib/media.glsl stores the stack in one uvec4");
static_assert(sizeof(FrameConstants) == 8);
static_assert(sizeof(LightPick) == 12);
static_assert(sizeof(FrameRun) == 8);
static_assert(sizeof(BvhNode) == 32);
static_assert(sizeof(MeshTriangle) == 36);
static_assert(sizeof(MeshNormals) == 36);
static_assert(sizeof(Emitter) == 76);
static_assert(sizeof(MeshUvs) == 24);
static_assert(sizeof(MeshColors) == 48);
static_assert(sizeof(MeshTangents) == 48);
static_assert(sizeof(MaterialAlpha) == 12);
static_assert(offsetof(Mesh, emission) == 96 && offsetof(Mesh, firstEmitter) == 128);
static_assert(sizeof(AccumPixel) == 28);
static_assert(sizeof(RenderStats) == 8);
static_assert(sizeof(MomentPixel) == 36);
static_assert(sizeof(AovPixel) == 44 && offsetof(AovPixel, hits) == 40);
// The per-kind counts sit before tileStride, so a new kind moves it (and needs no edit here).
static_assert(offsetof(SceneUniforms, tileStride) == 68 + 4 * (SHAPE_KIND_COUNT + LIGHT_KIND_COUNT));
static_assert(offsetof(Material, fresnel) == 48 && offsetof(Material, eta) == 64 && offsetof(Material, k) == 80);
static_assert(sizeof(TriangleLight) == 40 && offsetof(TriangleLight, emitter) == 12);
static_assert(sizeof(DirectionalLight) == 32 && offsetof(DirectionalLight, sin2Alpha) == 28);
static_assert(sizeof(SpotLight) == 44 && offsetof(SpotLight, axis) == 32);

} // namespace vkrt::gpu

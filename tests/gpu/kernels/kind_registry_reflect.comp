// The registry's constants (shared/Kinds.h) as glslang evaluates them. Each
// constant C becomes an array of C + 1 words followed by a marker word, so
// the reflected offset of every marker encodes every constant before it:
// tests/gpu/kind_registry_test.cpp recomputes those offsets from the C++
// constants. Compiled and reflected only, never dispatched.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_scalar_block_layout : require
#include "shared/Kinds.h"

#define VKRT_PROBE_MATERIAL(KIND, Type, name, value, delta) uint material_##KIND[MATERIAL_##KIND + 1]; uint end_material_##KIND;
#define VKRT_PROBE_SHAPE(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    uint shape_##KIND[SHAPE_##KIND + 1];                                         \
    uint end_shape_##KIND;                                                       \
    uint capacity_##ARRAY[UNIFORM_##ARRAY + 1];                                  \
    uint end_capacity_##ARRAY;
#define VKRT_PROBE_LIGHT(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    uint light_##KIND[LIGHT_##KIND + 1];                                         \
    uint end_light_##KIND;                                                       \
    uint capacity_##ARRAY[UNIFORM_##ARRAY + 1];                                  \
    uint end_capacity_##ARRAY;

layout(scalar, binding = 0) buffer RegistryBlock {
    VKRT_MATERIAL_KINDS(VKRT_PROBE_MATERIAL)
    VKRT_SHAPE_KINDS(VKRT_PROBE_SHAPE)
    VKRT_LIGHT_KINDS(VKRT_PROBE_LIGHT)
    uint materialCount[MATERIAL_KIND_COUNT + 1];
    uint end_materialCount;
    uint shapeCount[SHAPE_KIND_COUNT + 1];
    uint end_shapeCount;
    uint lightCount[LIGHT_KIND_COUNT + 1];
    uint end_lightCount;
} registry;

layout(local_size_x = 1) in;

void main() { registry.end_lightCount = 0u; }

#pragma once
// Every shape and light kind's own functions, declared once from the registry
// (shared/Kinds.h) and defined in the kind's file (scene/kinds/Sphere.cpp,
// ...), so that a kind in the registry without one of them fails to build:
//   KeyList fieldKeys()                      the keys its table accepts
//   void readType(table, [material,] ParseContext&)
//                                            validates one [[objects]] or
//                                            [[lights]] table and appends
//                                            the record to the scene
//   Aabb boundsOf(const Type&)               its world-space bounds (kinds
//                                            with bounded = 1: the leaves of
//                                            the top-level BVH)
//   gpu::Type toGpu(const Type&, const Relativizer&, uint32_t index)
//                                            its GPU record (index: its
//                                            place among the uploaded ones)
// A mesh instance's GPU record needs the scene's geometry pool, so
// render/GpuScene.cpp makes it; Mesh.cpp has no toGpu.
#include "accel/Bvh.h"
#include "scene/ParseContext.h"
#include "scene/TomlReader.h"
#include "shared/SceneTypes.h"

#include <cstdint>

namespace vkrt {

/// World -> camera-relative float32: positions reach the GPU relative to the
/// eye, subtracted in double, so their precision does not depend on where the
/// scene sits in space.
struct Relativizer {
    glm::dvec3 eye;
    glm::vec3 operator()(const glm::dvec3& p) const { return glm::vec3(p - eye); }
};

#define VKRT_DECLARE_KIND_FUNCTIONS(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    KeyList field##Keys();                                                                           \
    Aabb boundsOf(const Type& record);                                                               \
    gpu::Type toGpu(const Type& record, const Relativizer& rel, uint32_t index);
#define VKRT_DECLARE_SHAPE_READER(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    void read##Type(const TableField& table, uint32_t material, ParseContext& context);
#define VKRT_DECLARE_LIGHT_READER(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    void read##Type(const TableField& table, ParseContext& context);

VKRT_SHAPE_KINDS(VKRT_DECLARE_KIND_FUNCTIONS)
VKRT_LIGHT_KINDS(VKRT_DECLARE_KIND_FUNCTIONS)
VKRT_SHAPE_KINDS(VKRT_DECLARE_SHAPE_READER)
VKRT_LIGHT_KINDS(VKRT_DECLARE_LIGHT_READER)

#undef VKRT_DECLARE_KIND_FUNCTIONS
#undef VKRT_DECLARE_SHAPE_READER
#undef VKRT_DECLARE_LIGHT_READER

/// A mesh's `material = "file"`: readMesh then takes the file's own materials.
inline constexpr uint32_t kFileMaterialIndex = UINT32_MAX;

/// Area of a triangle, in double.
double triangleArea(const std::array<glm::dvec3, 3>& v);

/// Whether a triangle light can emit: its area is positive and finite in
/// float. The others are dropped before the GPU (they would be invisible).
bool emits(const TriangleLight& light);

/// A triangle light's Emitter (its alias-table entry is filled in later) and
/// its emitted power, the weight of its choice among all emitters.
gpu::Emitter emitterOf(const TriangleLight& light, const Relativizer& rel);
double emittedPower(const TriangleLight& light);

} // namespace vkrt

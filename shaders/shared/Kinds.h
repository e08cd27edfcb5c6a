// The registry of kinds: every material, shape and light kind vkrt knows,
// listed once. C++ (the scene parser, FeatureSet, the kernel variant, the
// upload) and GLSL (constants, the dispatch of lib/scene.glsl and lib/bsdf.glsl) expand
// these lists, so a new kind is one line here plus the code that only that
// kind can have (its record, reader, intersection and shading functions).
// docs/architecture.md lists every place a new kind touches.
//
// Each list calls X once per kind, in the order of its value (0, 1, ...):
//   VKRT_MATERIAL_KINDS: X(KIND, Type, name, value, delta)
//   VKRT_SHAPE_KINDS, VKRT_LIGHT_KINDS:
//       X(KIND, Type, name, value, field, array, ARRAY, capacity, bounded)
// KIND: constant suffix (MATERIAL_KIND, SHAPE_KIND, LIGHT_KIND) and the
//       VKRT_MATERIAL_KIND define of the variants that use the material;
// Type: the C++ enumerator, the GPU record (shared/SceneTypes.h) and the
//       suffix of per-kind functions (readType, closestType, ...);
// delta: 1 for a material that scatters into single directions (mirror,
//        glass): lights cannot be sampled for it;
// name: the scene file's spelling (`type = "name"`, `shape = "name"`);
// field: SceneUniforms::fieldCount holds the number of records;
// array: the member of Scene and GpuSceneData and the GLSL array;
// ARRAY: VKRT_HAS_ARRAY define, BINDING_ARRAY (shared/Bindings.h) and
//        UNIFORM_ARRAY, the records a 16 KiB uniform block holds (capacity:
//        16384 / sizeof(Type), checked in src/gpu/SharedTypes.cpp);
// bounded: 1 for a kind with a finite bounding box (the host's Aabb
//          boundsOf(record)): with meshes its records are leaves of the
//          top-level BVH (render/GpuScene.cpp, lib/scene.glsl); 0 for a kind
//          tested in a loop in every variant (planes) or never hit (points).
// GLSL's preprocessor has no stringizing: names stay bare words.
#ifndef VKRT_SHARED_KINDS_H
#define VKRT_SHARED_KINDS_H
#include "Interop.h"

#define VKRT_MATERIAL_KINDS(X)                                  \
    X(LAMBERT, Lambert, lambert, 0, 0)                          \
    X(PHONG, Phong, phong, 1, 0)                                \
    X(MIRROR, Mirror, mirror, 2, 1)                             \
    X(GLOSSY, Glossy, glossy, 3, 0)                             \
    X(DIELECTRIC, Dielectric, dielectric, 4, 1)                 \
    X(CONDUCTOR, Conductor, conductor, 5, 0)                    \
    X(ROUGH_DIELECTRIC, RoughDielectric, rough_dielectric, 6, 0) \
    X(PLASTIC, Plastic, plastic, 7, 0)                          \
    X(PBR, Pbr, pbr, 8, 0)

#define VKRT_SHAPE_KINDS(X)                                                    \
    X(SPHERE, Sphere, sphere, 0, sphere, spheres, SPHERES, 819, 1)             \
    X(BOX, Box, box, 1, box, boxes, BOXES, 585, 1)                             \
    X(TRIANGLE, Triangle, triangle, 2, triangle, triangles, TRIANGLES, 409, 1) \
    X(PLANE, Plane, plane, 3, plane, planes, PLANES, 585, 0)                   \
    X(MESH, Mesh, mesh, 4, mesh, meshes, MESHES, 124, 1)

#define VKRT_LIGHT_KINDS(X)                                                       \
    X(POINT, PointLight, point, 0, pointLight, pointLights, POINT_LIGHTS, 682, 0) \
    X(TRIANGLE, TriangleLight, triangle, 1, triangleLight, triangleLights, TRIANGLE_LIGHTS, 409, 1) \
    X(DIRECTIONAL, DirectionalLight, directional, 2, directionalLight, directionalLights, DIRECTIONAL_LIGHTS, 512, 0) \
    X(SPOT, SpotLight, spot, 3, spotLight, spotLights, SPOT_LIGHTS, 372, 0)

// The pbr material's glTF extension lobes that a kernel compiles only where
// some pbr material of the scene has one: X(LOBE, Lobe, name, value). Each is
// the define VKRT_PBR_LOBE of the variants that use it (lib/bsdf.glsl guards
// the lobe's code with it), the feature "pbr-name" of `vkrt info`, bit
// `value` of FeatureSet::pbrLobes, and a case of PbrLayers::has
// (src/scene/Scene.h), which the compiler requires for every lobe. The other
// layers (KHR_materials_specular, _ior) are a few multiplications: they come
// with VKRT_PBR_LAYERS.
#define VKRT_PBR_LOBES(X)                          \
    X(TRANSMISSION, Transmission, transmission, 0) \
    X(IRIDESCENCE, Iridescence, iridescence, 1)    \
    X(ANISOTROPY, Anisotropy, anisotropy, 2)       \
    X(SHEEN, Sheen, sheen, 3)                      \
    X(CLEARCOAT, Clearcoat, clearcoat, 4)

// ------------------------------------------------------ derived constants

#define VKRT_PLUS_ONE_MATERIAL(KIND, Type, name, value, delta) +1
#define VKRT_PLUS_ONE_ARRAY(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) +1
#define VKRT_MATERIAL_CONSTANT(KIND, Type, name, value, delta) VKRT_CONSTANT(uint, MATERIAL_##KIND, value)
#define VKRT_SHAPE_CONSTANT(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    VKRT_CONSTANT(int, SHAPE_##KIND, value)
#define VKRT_LIGHT_CONSTANT(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    VKRT_CONSTANT(int, LIGHT_##KIND, value)
#define VKRT_SHAPE_HIT_CODE(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    VKRT_CONSTANT(int, HIT_##Type, value)
#define VKRT_LIGHT_HIT_CODE(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    VKRT_CONSTANT(int, HIT_##Type, 0 VKRT_SHAPE_KINDS(VKRT_PLUS_ONE_ARRAY) + value)
#define VKRT_CAPACITY_CONSTANT(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    VKRT_CONSTANT(uint, UNIFORM_##ARRAY, capacity)

VKRT_BEGIN_NAMESPACE

// Material::type
VKRT_MATERIAL_KINDS(VKRT_MATERIAL_CONSTANT)
VKRT_CONSTANT(uint, MATERIAL_KIND_COUNT, 0 VKRT_MATERIAL_KINDS(VKRT_PLUS_ONE_MATERIAL))

// Shape kinds, as lib/scene.glsl's HitId::shape.
VKRT_SHAPE_KINDS(VKRT_SHAPE_CONSTANT)
VKRT_CONSTANT(int, SHAPE_KIND_COUNT, 0 VKRT_SHAPE_KINDS(VKRT_PLUS_ONE_ARRAY))

VKRT_LIGHT_KINDS(VKRT_LIGHT_CONSTANT)
VKRT_CONSTANT(int, LIGHT_KIND_COUNT, 0 VKRT_LIGHT_KINDS(VKRT_PLUS_ONE_ARRAY))

// Every shape and light kind's code in a hit and a top-level BVH reference
// (HIT_Sphere, ..., HIT_TriangleLight): shapes by value, then lights after
// the last shape.
VKRT_SHAPE_KINDS(VKRT_SHAPE_HIT_CODE)
VKRT_LIGHT_KINDS(VKRT_LIGHT_HIT_CODE)

// Uniform-block capacities of the shape and light arrays (UNIFORM_SPHERES, ...).
VKRT_SHAPE_KINDS(VKRT_CAPACITY_CONSTANT)
VKRT_LIGHT_KINDS(VKRT_CAPACITY_CONSTANT)

VKRT_END_NAMESPACE

#endif

#pragma once
// Scene -> the GPU records of shaders/shared/SceneTypes.h. Positions are made
// camera-relative in double precision before rounding to float32, so a scene
// far from the world origin keeps full float precision near the camera.
#include "accel/Bvh.h"
#include "scene/Scene.h"
#include "scene/kinds/Kinds.h"
#include "shared/SceneTypes.h"
#include "shared/TextureTypes.h"
#include "texture/TextureAtlas.h"

#include <map>
#include <optional>
#include <vector>

namespace vkrt {

/// Where one geometry's records start in the concatenated mesh buffers.
struct GeometryOffsets {
    uint32_t root = 0;
    uint32_t firstTriangle = 0;
    uint32_t firstNormals = 0;
    bool normals = false;
};

/// The top-level BVH over the records of every kind with bounded = 1 in the
/// registry (shared/Kinds.h), in a scene with meshes (the unbounded kinds,
/// planes, stay a list). Built once in world space; only its boxes
/// depend on the camera (refitted, never rebuilt, when the camera moves).
struct TopLevel {
    Bvh bvh;
    std::vector<uint32_t> refs; ///< leaf slot -> gpu::TOP_REF
    std::vector<Aabb> boxes;    ///< leaf slot -> world box (double)
};

/// Every emitter (triangle lights, then emissive mesh triangles) chosen in
/// proportion to power (Walker's alias method).
struct EmitterTable {
    std::vector<double> pdf; ///< per emitter: triangle lights, then mesh instances' leaves in order
    std::vector<float> threshold;
    std::vector<uint32_t> alias;
    double totalPower = 0.0;
};

/// Walker's alias table (Vose's construction) over non-negative weights: the
/// emitters' and the light table's (render/LightTable.h).
EmitterTable aliasTable(const std::vector<double>& power);

/// Everything about a scene's meshes that no camera move changes: the
/// geometries concatenated (each once, however many instances share it),
/// the top-level BVH's topology and the emitters' alias table.
struct GpuSceneStatic {
    /// The rough plastics' coating tables (gpu::MATERIAL_TABLE_SIZE floats each;
    /// never empty, so that the buffer can always be bound), and per material
    /// where its table starts (gpu::NO_MATERIAL_TABLE for none) and its
    /// coating's internal diffuse reflectance.
    std::vector<float> materialTables{0.0f};
    std::vector<uint32_t> materialTableStart;
    std::vector<float> internalReflectance;
    std::vector<gpu::BvhNode> meshNodes;
    std::vector<gpu::MeshTriangle> meshTriangles;
    std::vector<gpu::MeshNormals> meshNormals;
    /// Beside meshTriangles (same index), filled only when the scene's
    /// features need them (textures, normal maps, file materials); each has
    /// at least one record so the buffer can always be bound.
    std::vector<gpu::MeshUvs> meshUvs{gpu::MeshUvs{}};
    std::vector<gpu::MeshUvs> meshUvs1{gpu::MeshUvs{}}; ///< the second set, beside meshUvs
    std::vector<gpu::MeshTangents> meshTangents{gpu::MeshTangents{}};
    std::vector<uint32_t> meshMaterials{0u};
    std::vector<gpu::MeshColors> meshColors{gpu::MeshColors{}};
    /// Every texture's texels (in one or more buffers) and records (one zero
    /// record and word without textures), and per material its texture slots.
    TextureBuffers textures;
    std::vector<gpu::MaterialTextures> materialTextures;
    /// Per material its coverage (glTF alphaMode; read by variants with alpha only).
    std::vector<gpu::MaterialAlpha> materialAlpha;
    std::map<const MeshGeometry*, GeometryOffsets> offsets;
    std::optional<TopLevel> top; ///< only for scenes with meshes
    EmitterTable emitters;
    double topBuildSeconds = 0.0;
};

/// The driver backend's box geometry (render/DriverAccel.h): one kind of the
/// registry with bounded = 1, other than meshes (which are instances of
/// triangle geometry), with its records' boxes in upload order, the index the
/// kernel's arrays use. Boxes are camera-relative, rounded outwards and
/// widened by a few float steps, since the kernel tests float records whose
/// rounding the double bounds do not see; an empty box is NaN (inactive).
struct RecordBoxes {
    int hitCode = 0; ///< gpu::HIT_Type
    std::vector<glm::vec3> lower, upper;
};
/// Every such kind that has records.
std::vector<RecordBoxes> recordBoxes(const Scene& scene);

/// Fails (InputError naming the mesh and the limit) if a mesh buffer would
/// exceed `maxBytes` (the device's maxStorageBufferRange). The texels are
/// split as `textureChunking` says (TextureAtlas::chunking checked it
/// against the device).
GpuSceneStatic prepareStaticScene(const Scene& scene, uint64_t maxBytes = ~0ull,
                                  const TextureChunking& textureChunking = {});

struct GpuSceneData {
    gpu::SceneUniforms uniforms{};
    std::vector<gpu::BvhNode> topNodes;
    std::vector<uint32_t> topRefs;
    std::vector<gpu::Emitter> emitters;
    std::vector<gpu::LightPick> lightTable; ///< only for scenes with many lights (render/LightTable.h)
    std::vector<gpu::Material> materials;
    // One array per shape and light kind (shared/Kinds.h), named as in Scene.
#define VKRT_GPU_ARRAY_MEMBER(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    std::vector<gpu::Type> array;
    VKRT_SHAPE_KINDS(VKRT_GPU_ARRAY_MEMBER)
    VKRT_LIGHT_KINDS(VKRT_GPU_ARRAY_MEMBER)
#undef VKRT_GPU_ARRAY_MEMBER
};

struct FrameSettings {
    bool jitter = true;    ///< random point in each pixel; off = pixel centres
    uint32_t bandRows = 0; ///< rows of one band of the image (render/ImageBands.h); 0: the whole image
};

GpuSceneData convertScene(const Scene& scene, const FrameSettings& settings, const GpuSceneStatic& fixed);

/// Mesh triangles (all instances) and emissive ones.
uint64_t meshTriangleCount(const Scene& scene);
uint64_t emissiveTriangleCount(const Scene& scene);

/// Materials of the dielectric spheres and boxes that contain the camera's
/// eye, outermost first (the medium stack a camera ray starts with).
std::vector<uint32_t> mediaAroundCamera(const Scene& scene);

/// Triangle lights that can emit: zero-area (degenerate) ones are dropped.
std::vector<TriangleLight> emittingTriangleLights(const Scene& scene);

/// Workgroup tiles covering a width x height image (or one band of it).
uint32_t tileCountFor(uint32_t width, uint32_t height);
/// A stride coprime to tileCount that spreads consecutive workgroups over the image.
uint32_t tileStrideFor(uint32_t tileCount);

} // namespace vkrt

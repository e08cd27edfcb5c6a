#pragma once
// The driver traversal backend (`--accel driver`): the scene as the device's
// own acceleration structures (VK_KHR_acceleration_structure), which the
// kernel walks with VK_KHR_ray_query (shaders/lib/ray_query.glsl says what
// each structure holds and how the kernel reads it).
//
// Mesh geometries never change: their bottom-level structures are built
// once. Everything the camera moves (the records are camera-relative,
// render/GpuScene.h) is rebuilt by moveCamera: the box structures of the
// other bounded kinds and the top level.
#include "gpu/Buffer.h"
#include "render/GpuScene.h"

#include <optional>
#include <vector>

namespace vkrt {

class DriverAccel {
public:
    /// Usage a buffer needs to be read by a build (the mesh triangles' buffer).
    static constexpr vk::BufferUsageFlags kBuildInputUsage =
        vk::BufferUsageFlagBits::eAccelerationStructureBuildInputReadOnlyKHR |
        vk::BufferUsageFlagBits::eShaderDeviceAddress;

    /// `meshTriangles`: the kernel's buffer of GpuSceneStatic::meshTriangles,
    /// made with kBuildInputUsage (null for a scene without meshes).
    DriverAccel(const VulkanContext& context, const GpuSceneStatic& fixed, const Buffer* meshTriangles,
                const Scene& scene, const GpuSceneData& data);

    /// Rebuilds the camera-relative structures for the scene's new camera
    /// (`data` converted for it). The caller makes sure no dispatch still reads
    /// the old ones, and binds topLevel() again.
    void moveCamera(const Scene& scene, const GpuSceneData& data);

    vk::AccelerationStructureKHR topLevel() const { return *m_topLevel->handle; }
    /// Seconds the construction took (every structure, meshes included).
    double buildSeconds() const { return m_buildSeconds; }
    /// Seconds the last moveCamera took (0 before any).
    double rebuildSeconds() const { return m_rebuildSeconds; }
    /// Bytes of every structure's storage (what the driver asked for).
    uint64_t storageBytes() const;

private:
    struct Structure {
        Buffer storage;
        vk::raii::AccelerationStructureKHR handle = nullptr;
        vk::DeviceAddress address = 0;
    };
    /// One structure's build, before it is recorded.
    struct PendingBuild {
        vk::AccelerationStructureGeometryKHR geometry;
        vk::AccelerationStructureBuildGeometryInfoKHR info;
        uint32_t primitives = 0;
        std::optional<Buffer> scratch;
    };

    const VulkanContext& m_context;
    std::vector<Structure> m_geometries;          ///< per geometry, as GpuSceneStatic::offsets orders them
    std::vector<uint32_t> m_geometryOfMesh;       ///< mesh record -> m_geometries index
    std::vector<Buffer> m_boxInputs;              ///< per bounded kind: its records' boxes
    std::vector<Structure> m_kinds;               ///< per bounded kind: its box structure
    std::vector<int> m_kindCodes;                 ///< per bounded kind: its HIT_Type code
    std::optional<Buffer> m_instances;
    std::optional<Structure> m_topLevel;
    double m_buildSeconds = 0.0;
    double m_rebuildSeconds = 0.0;

    Structure create(vk::AccelerationStructureTypeKHR type, PendingBuild& build);
    void buildGeometries(const GpuSceneStatic& fixed, const Buffer* meshTriangles, const Scene& scene);
    void buildCameraRelative(const Scene& scene, const GpuSceneData& data);
    void submit(std::vector<PendingBuild>& bottoms, std::vector<PendingBuild>& tops) const;
};

} // namespace vkrt

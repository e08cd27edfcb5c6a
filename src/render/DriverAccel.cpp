#include "render/DriverAccel.h"

#include "mesh/MeshGeometry.h"
#include "shared/Kinds.h"
#include "util/Error.h"

#include <chrono>
#include <cstring>
#include <map>

namespace vkrt {

namespace {

using Clock = std::chrono::steady_clock;

constexpr vk::BufferUsageFlags kBuildInput = DriverAccel::kBuildInputUsage;
/// Instance custom indices and shader-binding-table offsets have 24 bits.
constexpr uint32_t kMaxInstanceField = (1u << 24) - 1;

vk::AccelerationStructureBuildGeometryInfoKHR buildInfo(vk::AccelerationStructureTypeKHR type)
{
    vk::AccelerationStructureBuildGeometryInfoKHR info;
    info.type = type;
    info.flags = vk::BuildAccelerationStructureFlagBitsKHR::ePreferFastTrace;
    info.mode = vk::BuildAccelerationStructureModeKHR::eBuild;
    return info;
}

/// A mesh record's toWorld rows: Vulkan's 3x4 row-major instance transform.
vk::TransformMatrixKHR transformOf(const gpu::Mesh& mesh)
{
    vk::TransformMatrixKHR t;
    const glm::vec4 rows[3] = {mesh.toWorld0, mesh.toWorld1, mesh.toWorld2};
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) t.matrix[r][c] = rows[r][c];
    return t;
}

vk::TransformMatrixKHR identity()
{
    vk::TransformMatrixKHR t;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) t.matrix[r][c] = r == c ? 1.0f : 0.0f;
    return t;
}

vk::AccelerationStructureInstanceKHR instance(const vk::TransformMatrixKHR& transform, uint32_t customIndex,
                                              int hitCode, vk::DeviceAddress structure, vk::GeometryInstanceFlagsKHR flags)
{
    // Both faces of a triangle are hit, as by the own backend's test.
    flags |= vk::GeometryInstanceFlagBitsKHR::eTriangleFacingCullDisable;
    return vk::AccelerationStructureInstanceKHR(transform, customIndex, 0xff, uint32_t(hitCode),
                                                flags, structure);
}

} // namespace

DriverAccel::DriverAccel(const VulkanContext& context, const GpuSceneStatic& fixed, const Buffer* meshTriangles,
                         const Scene& scene, const GpuSceneData& data)
    : m_context(context)
{
    if (!context.deviceInfo().rayQuery())
        throw InternalError("the driver backend needs VK_KHR_ray_query: " + context.deviceInfo().rayQueryMissing);
    if (data.meshes.size() > kMaxInstanceField)
        throw InputError(scene.path + ": the driver backend (--accel driver) takes at most " +
                         std::to_string(kMaxInstanceField + 1) + " mesh instances");
    const auto start = Clock::now();
    buildGeometries(fixed, meshTriangles, scene);
    buildCameraRelative(scene, data);
    m_buildSeconds = std::chrono::duration<double>(Clock::now() - start).count();
}

void DriverAccel::moveCamera(const Scene& scene, const GpuSceneData& data)
{
    const auto start = Clock::now();
    buildCameraRelative(scene, data);
    m_rebuildSeconds = std::chrono::duration<double>(Clock::now() - start).count();
}

uint64_t DriverAccel::storageBytes() const
{
    uint64_t bytes = m_topLevel ? m_topLevel->storage.size() : 0;
    for (const Structure& s : m_geometries) bytes += s.storage.size();
    for (const Structure& s : m_kinds) bytes += s.storage.size();
    return bytes;
}

DriverAccel::Structure DriverAccel::create(vk::AccelerationStructureTypeKHR type, PendingBuild& build)
{
    build.info.setGeometries(build.geometry);
    const auto sizes = m_context.device().getAccelerationStructureBuildSizesKHR(
        vk::AccelerationStructureBuildTypeKHR::eDevice, build.info, build.primitives);
    Structure s{Buffer(m_context, std::max<vk::DeviceSize>(sizes.accelerationStructureSize, 256),
                       vk::BufferUsageFlagBits::eAccelerationStructureStorageKHR |
                           vk::BufferUsageFlagBits::eShaderDeviceAddress,
                       MemoryUse::Device)};
    s.handle = vk::raii::AccelerationStructureKHR(
        m_context.device(),
        vk::AccelerationStructureCreateInfoKHR({}, s.storage.handle(), 0, sizes.accelerationStructureSize, type));
    s.address = m_context.device().getAccelerationStructureAddressKHR({*s.handle});
    build.scratch.emplace(m_context, std::max<vk::DeviceSize>(sizes.buildScratchSize, 256),
                           vk::BufferUsageFlagBits::eStorageBuffer | vk::BufferUsageFlagBits::eShaderDeviceAddress,
                           MemoryUse::Device);
    build.info.setDstAccelerationStructure(*s.handle);
    return s;
}

// One structure per geometry, from its run of meshTriangles (three vertices
// each, not indexed), so the driver's primitive index is the leaf slot.
void DriverAccel::buildGeometries(const GpuSceneStatic& fixed, const Buffer* meshTriangles, const Scene& scene)
{
    if (scene.meshes.empty()) return;
    VKRT_CHECK(meshTriangles);
    const vk::DeviceAddress base = meshTriangles->address(m_context);
    std::map<const MeshGeometry*, uint32_t> structureOf;
    std::vector<PendingBuild> builds;
    for (const auto& [geometry, offsets] : fixed.offsets) {
        const auto triangles = uint32_t(geometry->data.triangles.size());
        VKRT_CHECK(triangles > 0);
        vk::AccelerationStructureGeometryTrianglesDataKHR data;
        data.vertexFormat = vk::Format::eR32G32B32Sfloat;
        data.vertexData.deviceAddress = base + vk::DeviceAddress(offsets.firstTriangle) * sizeof(gpu::MeshTriangle);
        data.vertexStride = sizeof(glm::vec3);
        data.maxVertex = 3 * triangles - 1;
        data.indexType = vk::IndexType::eNoneKHR;
        PendingBuild build{vk::AccelerationStructureGeometryKHR(vk::GeometryTypeKHR::eTriangles, data,
                                                                vk::GeometryFlagBitsKHR::eOpaque),
                           buildInfo(vk::AccelerationStructureTypeKHR::eBottomLevel), triangles};
        structureOf[geometry] = uint32_t(m_geometries.size());
        m_geometries.push_back(create(vk::AccelerationStructureTypeKHR::eBottomLevel, build));
        builds.push_back(std::move(build));
    }
    for (const Mesh& mesh : scene.meshes) m_geometryOfMesh.push_back(structureOf.at(mesh.geometry.get()));
    std::vector<PendingBuild> none;
    submit(builds, none);
}

// The box structures of the bounded kinds and the top level over them and
// every mesh instance.
void DriverAccel::buildCameraRelative(const Scene& scene, const GpuSceneData& data)
{
    m_kinds.clear();
    m_boxInputs.clear();
    m_kindCodes.clear();
    std::vector<PendingBuild> bottoms;
    for (const RecordBoxes& kind : recordBoxes(scene)) {
        std::vector<vk::AabbPositionsKHR> boxes;
        for (size_t i = 0; i < kind.lower.size(); ++i)
            boxes.emplace_back(kind.lower[i].x, kind.lower[i].y, kind.lower[i].z, kind.upper[i].x, kind.upper[i].y,
                               kind.upper[i].z);
        m_boxInputs.push_back(makeBufferFrom(m_context, boxes, kBuildInput));
        vk::AccelerationStructureGeometryAabbsDataKHR aabbs(m_boxInputs.back().address(m_context),
                                                            sizeof(vk::AabbPositionsKHR));
        PendingBuild build{vk::AccelerationStructureGeometryKHR(vk::GeometryTypeKHR::eAabbs, aabbs),
                           buildInfo(vk::AccelerationStructureTypeKHR::eBottomLevel), uint32_t(boxes.size())};
        m_kinds.push_back(create(vk::AccelerationStructureTypeKHR::eBottomLevel, build));
        m_kindCodes.push_back(kind.hitCode);
        bottoms.push_back(std::move(build));
    }

    std::vector<vk::AccelerationStructureInstanceKHR> instances;
    // An instance with alpha-tested materials is not opaque: its candidate
    // triangles come back to the kernel, which confirms those its alpha test
    // keeps (lib/ray_query.glsl); every other instance is forced opaque.
    for (size_t i = 0; i < data.meshes.size(); ++i) {
        const bool alpha = (data.meshes[i].flags & gpu::MESH_FLAG_ALPHA) != 0u;
        instances.push_back(instance(transformOf(data.meshes[i]), uint32_t(i), gpu::HIT_Mesh,
                                     m_geometries[m_geometryOfMesh[i]].address,
                                     alpha ? vk::GeometryInstanceFlagBitsKHR::eForceNoOpaque
                                           : vk::GeometryInstanceFlagBitsKHR::eForceOpaque));
    }
    for (size_t k = 0; k < m_kinds.size(); ++k)
        instances.push_back(instance(identity(), 0, m_kindCodes[k], m_kinds[k].address, {}));
    m_instances.reset();
    m_instances.emplace(makeBufferFrom(m_context, instances, kBuildInput));
    vk::AccelerationStructureGeometryInstancesDataKHR instanceData(false, m_instances->address(m_context));
    std::vector<PendingBuild> tops;
    tops.push_back(PendingBuild{vk::AccelerationStructureGeometryKHR(vk::GeometryTypeKHR::eInstances, instanceData),
                                buildInfo(vk::AccelerationStructureTypeKHR::eTopLevel), uint32_t(instances.size())});
    m_topLevel.reset();
    m_topLevel.emplace(create(vk::AccelerationStructureTypeKHR::eTopLevel, tops.back()));
    submit(bottoms, tops);
}

// The bottom levels in one command, then (after a barrier) the top levels,
// in one submission.
void DriverAccel::submit(std::vector<PendingBuild>& bottoms, std::vector<PendingBuild>& tops) const
{
    auto record = [&](vk::CommandBuffer cmd, std::vector<PendingBuild>& builds) {
        if (builds.empty()) return;
        std::vector<vk::AccelerationStructureBuildGeometryInfoKHR> infos;
        std::vector<vk::AccelerationStructureBuildRangeInfoKHR> ranges;
        for (PendingBuild& b : builds) {
            b.info.setGeometries(b.geometry);
            b.info.scratchData.deviceAddress = b.scratch->address(m_context);
            infos.push_back(b.info);
            ranges.emplace_back(b.primitives, 0, 0, 0);
        }
        std::vector<const vk::AccelerationStructureBuildRangeInfoKHR*> rangePointers;
        for (const auto& range : ranges) rangePointers.push_back(&range);
        cmd.buildAccelerationStructuresKHR(infos, rangePointers, *m_context.device().getDispatcher());
    };
    m_context.submitAndWait([&](vk::CommandBuffer cmd) {
        record(cmd, bottoms);
        vk::MemoryBarrier built(vk::AccessFlagBits::eAccelerationStructureWriteKHR,
                                vk::AccessFlagBits::eAccelerationStructureReadKHR);
        cmd.pipelineBarrier(vk::PipelineStageFlagBits::eAccelerationStructureBuildKHR,
                            vk::PipelineStageFlagBits::eAccelerationStructureBuildKHR |
                                vk::PipelineStageFlagBits::eComputeShader,
                            {}, built, nullptr, nullptr);
        record(cmd, tops);
        cmd.pipelineBarrier(vk::PipelineStageFlagBits::eAccelerationStructureBuildKHR,
                            vk::PipelineStageFlagBits::eComputeShader, {}, built, nullptr, nullptr);
    });
}

} // namespace vkrt

// vkrt-rayquery-bench: closest-hit throughput of the device's own ray
// traversal (VK_KHR_ray_query, acceleration structures built by the driver;
// kernel tools/rayquery/closest_hits.comp) on a scene's meshes, to weigh
// against vkrt's own BVH traversal (tools/bench_rays.py measures both on the
// same scenes and rays). An
// optional target: `cmake --build build --target vkrt-rayquery-bench`.
//   vkrt-rayquery-bench SCENE.toml [SPP [RUNS [WIDTH HEIGHT]]]
// Only the scene's meshes are built (one bottom-level structure per mesh,
// one instance each with its transform); analytic shapes and lights are left
// out. Prints Mrays/s (median of RUNS timed dispatches after one untimed
// one), the build time, and the share of rays that hit with their mean
// distance, to compare with the other traversal.
#include "gpu/ShaderCompiler.h"
#include "mesh/MeshGeometry.h"
#include "scene/SceneParser.h"
#include "util/Error.h"

#include <glm/glm.hpp>
#include <vulkan/vulkan_raii.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;

struct CameraConstants {
    glm::vec3 eye;
    uint32_t width;
    glm::vec3 right;
    uint32_t height;
    glm::vec3 up;
    uint32_t spp;
    glm::vec3 forward;
};

struct PixelResult {
    uint32_t hits;
    float distanceSum;
};

const std::vector<const char*> kDeviceExtensions = {VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME,
                                                    VK_KHR_RAY_QUERY_EXTENSION_NAME,
                                                    VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME};

bool hasExtensions(const vk::raii::PhysicalDevice& device)
{
    auto available = device.enumerateDeviceExtensionProperties();
    return std::all_of(kDeviceExtensions.begin(), kDeviceExtensions.end(), [&](const char* name) {
        return std::any_of(available.begin(), available.end(),
                           [&](const vk::ExtensionProperties& p) { return std::strcmp(p.extensionName, name) == 0; });
    });
}

/// A buffer with its memory, host-visible so that uploads are a memcpy.
struct HostBuffer {
    vk::raii::Buffer buffer = nullptr;
    vk::raii::DeviceMemory memory = nullptr;
    void* mapped = nullptr;
    vk::DeviceAddress address = 0;
};

// Its own instance and device rather than gpu/VulkanContext: ray queries
// need extensions and features (acceleration structures, buffer device
// addresses) that the renderer never enables, and this probe alone uses.
class Gpu {
public:
    Gpu()
    {
        vk::ApplicationInfo app("vkrt-rayquery-bench", 1, "vkrt", 1, VK_API_VERSION_1_2);
        m_instance = vk::raii::Instance(m_context, vk::InstanceCreateInfo({}, &app));
        for (auto& candidate : m_instance.enumeratePhysicalDevices())
            if (hasExtensions(candidate)) {
                m_physical = std::move(candidate);
                break;
            }
        if (!*m_physical) throw vkrt::InputError("no Vulkan device offers VK_KHR_ray_query and acceleration structures");
        auto families = m_physical.getQueueFamilyProperties();
        for (uint32_t i = 0; i < families.size(); ++i)
            if (families[i].queueFlags & vk::QueueFlagBits::eCompute) m_family = i;
        float priority = 1.0f;
        vk::DeviceQueueCreateInfo queueInfo({}, m_family, 1, &priority);
        vk::StructureChain<vk::DeviceCreateInfo, vk::PhysicalDeviceVulkan12Features,
                           vk::PhysicalDeviceAccelerationStructureFeaturesKHR, vk::PhysicalDeviceRayQueryFeaturesKHR>
            chain;
        chain.get<vk::DeviceCreateInfo>().setQueueCreateInfos(queueInfo).setPEnabledExtensionNames(kDeviceExtensions);
        chain.get<vk::PhysicalDeviceVulkan12Features>().setBufferDeviceAddress(true).setScalarBlockLayout(true);
        chain.get<vk::PhysicalDeviceAccelerationStructureFeaturesKHR>().setAccelerationStructure(true);
        chain.get<vk::PhysicalDeviceRayQueryFeaturesKHR>().setRayQuery(true);
        m_device = vk::raii::Device(m_physical, chain.get<vk::DeviceCreateInfo>());
        m_queue = m_device.getQueue(m_family, 0);
        m_pool = vk::raii::CommandPool(m_device, {vk::CommandPoolCreateFlagBits::eResetCommandBuffer, m_family});
    }

    std::string name() const { return m_physical.getProperties().deviceName.data(); }
    const vk::raii::Device& device() const { return m_device; }

    HostBuffer buffer(vk::DeviceSize size, vk::BufferUsageFlags usage) const
    {
        HostBuffer b;
        usage |= vk::BufferUsageFlagBits::eShaderDeviceAddress;
        b.buffer = vk::raii::Buffer(m_device, vk::BufferCreateInfo({}, std::max<vk::DeviceSize>(size, 16), usage));
        vk::MemoryRequirements needs = b.buffer.getMemoryRequirements();
        auto props = m_physical.getMemoryProperties();
        uint32_t type = 0;
        auto wanted = vk::MemoryPropertyFlagBits::eHostVisible | vk::MemoryPropertyFlagBits::eHostCoherent;
        while (type < props.memoryTypeCount &&
               !((needs.memoryTypeBits & (1u << type)) && (props.memoryTypes[type].propertyFlags & wanted) == wanted))
            ++type;
        vk::MemoryAllocateFlagsInfo flags(vk::MemoryAllocateFlagBits::eDeviceAddress);
        b.memory = vk::raii::DeviceMemory(m_device, vk::MemoryAllocateInfo(needs.size, type, &flags));
        b.buffer.bindMemory(*b.memory, 0);
        b.mapped = b.memory.mapMemory(0, VK_WHOLE_SIZE);
        b.address = m_device.getBufferAddress(vk::BufferDeviceAddressInfo(*b.buffer));
        return b;
    }

    template <typename Record>
    void submitAndWait(Record&& record) const
    {
        vk::raii::CommandBuffers cmds(m_device, {*m_pool, vk::CommandBufferLevel::ePrimary, 1});
        cmds[0].begin({vk::CommandBufferUsageFlagBits::eOneTimeSubmit});
        record(cmds[0]);
        cmds[0].end();
        vk::raii::Fence fence(m_device, vk::FenceCreateInfo());
        vk::CommandBuffer cmd = *cmds[0];
        m_queue.submit(vk::SubmitInfo({}, {}, cmd), *fence);
        if (m_device.waitForFences(*fence, VK_TRUE, UINT64_MAX) != vk::Result::eSuccess)
            throw vkrt::GpuError("vkWaitForFences failed");
    }

private:
    vk::raii::Context m_context;
    vk::raii::Instance m_instance = nullptr;
    vk::raii::PhysicalDevice m_physical = nullptr;
    vk::raii::Device m_device = nullptr;
    vk::raii::Queue m_queue = nullptr;
    vk::raii::CommandPool m_pool = nullptr;
    uint32_t m_family = 0;
};

struct AccelerationStructure {
    HostBuffer storage;
    vk::raii::AccelerationStructureKHR handle = nullptr;
    vk::DeviceAddress address = 0;
};

/// Builds one acceleration structure of `type` from `geometry` (`count` primitives).
AccelerationStructure build(const Gpu& gpu, vk::AccelerationStructureTypeKHR type,
                            const vk::AccelerationStructureGeometryKHR& geometry, uint32_t count)
{
    vk::AccelerationStructureBuildGeometryInfoKHR info(type, vk::BuildAccelerationStructureFlagBitsKHR::ePreferFastTrace,
                                                       vk::BuildAccelerationStructureModeKHR::eBuild, {}, {}, geometry);
    auto sizes = gpu.device().getAccelerationStructureBuildSizesKHR(vk::AccelerationStructureBuildTypeKHR::eDevice, info,
                                                                     count);
    AccelerationStructure as;
    as.storage = gpu.buffer(sizes.accelerationStructureSize, vk::BufferUsageFlagBits::eAccelerationStructureStorageKHR);
    as.handle = vk::raii::AccelerationStructureKHR(
        gpu.device(), vk::AccelerationStructureCreateInfoKHR({}, *as.storage.buffer, 0, sizes.accelerationStructureSize, type));
    HostBuffer scratch = gpu.buffer(sizes.buildScratchSize, vk::BufferUsageFlagBits::eStorageBuffer);
    info.setDstAccelerationStructure(*as.handle).setScratchData(scratch.address);
    vk::AccelerationStructureBuildRangeInfoKHR range(count, 0, 0, 0);
    gpu.submitAndWait([&](const vk::raii::CommandBuffer& cmd) { cmd.buildAccelerationStructuresKHR(info, &range); });
    as.address = gpu.device().getAccelerationStructureAddressKHR({*as.handle});
    return as;
}

vk::TransformMatrixKHR transformOf(const glm::dmat4& m)
{
    vk::TransformMatrixKHR t;
    for (int row = 0; row < 3; ++row)
        for (int col = 0; col < 4; ++col) t.matrix[row][col] = float(m[col][row]);
    return t;
}

double median(std::vector<double> v)
{
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

int run(int argc, char** argv)
{
    if (argc < 2 || argc > 6 || argc == 5) {
        std::fprintf(stderr, "usage: vkrt-rayquery-bench SCENE.toml [SPP [RUNS [WIDTH HEIGHT]]]\n");
        return 2;
    }
    vkrt::Scene scene = vkrt::parseSceneFile(argv[1]);
    auto number = [&](int i, const char* what, unsigned long fallback) {
        if (argc <= i) return fallback;
        char* end = nullptr;
        unsigned long value = std::strtoul(argv[i], &end, 10);
        if (*argv[i] == '\0' || *end != '\0' || value < 1 || value > 65536)
            throw vkrt::InputError(std::string(what) + " " + argv[i] + ": expected a whole number from 1 to 65536");
        return value;
    };
    uint32_t spp = uint32_t(number(2, "SPP", 16));
    int runs = int(number(3, "RUNS", 3));
    scene.camera.width = uint32_t(number(4, "WIDTH", scene.camera.width));
    scene.camera.height = uint32_t(number(5, "HEIGHT", scene.camera.height));
    if (scene.meshes.empty()) throw vkrt::InputError(std::string(argv[1]) + ": the scene has no meshes");
    Gpu gpu;

    auto buildStart = Clock::now();
    std::vector<HostBuffer> meshBuffers;
    std::vector<AccelerationStructure> bottoms;
    std::vector<vk::AccelerationStructureInstanceKHR> instances;
    for (const vkrt::Mesh& mesh : scene.meshes) {
        const auto& data = mesh.geometry->data;
        HostBuffer vertices = gpu.buffer(data.positions.size() * sizeof(glm::vec3),
                                         vk::BufferUsageFlagBits::eAccelerationStructureBuildInputReadOnlyKHR);
        std::memcpy(vertices.mapped, data.positions.data(), data.positions.size() * sizeof(glm::vec3));
        HostBuffer indices = gpu.buffer(data.triangles.size() * sizeof(glm::uvec3),
                                        vk::BufferUsageFlagBits::eAccelerationStructureBuildInputReadOnlyKHR);
        std::memcpy(indices.mapped, data.triangles.data(), data.triangles.size() * sizeof(glm::uvec3));
        vk::AccelerationStructureGeometryTrianglesDataKHR triangles(
            vk::Format::eR32G32B32Sfloat, vertices.address, sizeof(glm::vec3), uint32_t(data.positions.size() - 1),
            vk::IndexType::eUint32, indices.address);
        vk::AccelerationStructureGeometryKHR geometry(vk::GeometryTypeKHR::eTriangles, triangles,
                                                      vk::GeometryFlagBitsKHR::eOpaque);
        bottoms.push_back(build(gpu, vk::AccelerationStructureTypeKHR::eBottomLevel, geometry,
                                uint32_t(data.triangles.size())));
        instances.push_back(vk::AccelerationStructureInstanceKHR(transformOf(mesh.objectToWorld), 0, 0xff, 0, {},
                                                                 bottoms.back().address));
        meshBuffers.push_back(std::move(vertices));
        meshBuffers.push_back(std::move(indices));
    }
    HostBuffer instanceBuffer = gpu.buffer(instances.size() * sizeof(instances[0]),
                                           vk::BufferUsageFlagBits::eAccelerationStructureBuildInputReadOnlyKHR);
    std::memcpy(instanceBuffer.mapped, instances.data(), instances.size() * sizeof(instances[0]));
    vk::AccelerationStructureGeometryKHR top(vk::GeometryTypeKHR::eInstances,
                                             vk::AccelerationStructureGeometryInstancesDataKHR(false, instanceBuffer.address));
    AccelerationStructure tlas = build(gpu, vk::AccelerationStructureTypeKHR::eTopLevel, top, uint32_t(instances.size()));
    double buildSeconds = std::chrono::duration<double>(Clock::now() - buildStart).count();

    const uint32_t width = scene.camera.width, height = scene.camera.height;
    HostBuffer results = gpu.buffer(sizeof(PixelResult) * width * height, vk::BufferUsageFlagBits::eStorageBuffer);

    const char* source = std::getenv("VKRT_RAYQUERY_SHADER_DIR");
    vkrt::KernelSource kernelSource{source ? source : VKRT_RAYQUERY_SHADER_DIR, "closest_hits.comp", {}};
    std::vector<uint32_t> spirv = vkrt::compileGlsl(kernelSource);
    vk::raii::ShaderModule module(gpu.device(), vk::ShaderModuleCreateInfo({}, spirv));
    std::array<vk::DescriptorSetLayoutBinding, 2> bindings = {
        vk::DescriptorSetLayoutBinding(0, vk::DescriptorType::eAccelerationStructureKHR, 1, vk::ShaderStageFlagBits::eCompute),
        vk::DescriptorSetLayoutBinding(1, vk::DescriptorType::eStorageBuffer, 1, vk::ShaderStageFlagBits::eCompute)};
    vk::raii::DescriptorSetLayout setLayout(gpu.device(), vk::DescriptorSetLayoutCreateInfo({}, bindings));
    vk::PushConstantRange push(vk::ShaderStageFlagBits::eCompute, 0, sizeof(CameraConstants));
    vk::raii::PipelineLayout layout(gpu.device(), vk::PipelineLayoutCreateInfo({}, *setLayout, push));
    vk::raii::Pipeline pipeline(gpu.device(), nullptr,
                                vk::ComputePipelineCreateInfo(
                                    {}, vk::PipelineShaderStageCreateInfo({}, vk::ShaderStageFlagBits::eCompute, *module, "main"),
                                    *layout));
    std::array<vk::DescriptorPoolSize, 2> sizes = {vk::DescriptorPoolSize(vk::DescriptorType::eAccelerationStructureKHR, 1),
                                                   vk::DescriptorPoolSize(vk::DescriptorType::eStorageBuffer, 1)};
    vk::raii::DescriptorPool pool(gpu.device(),
                                  vk::DescriptorPoolCreateInfo(vk::DescriptorPoolCreateFlagBits::eFreeDescriptorSet, 1, sizes));
    vk::raii::DescriptorSets sets(gpu.device(), vk::DescriptorSetAllocateInfo(*pool, *setLayout));
    vk::AccelerationStructureKHR tlasHandle = *tlas.handle;
    vk::WriteDescriptorSetAccelerationStructureKHR asWrite(tlasHandle);
    vk::DescriptorBufferInfo resultInfo(*results.buffer, 0, VK_WHOLE_SIZE);
    std::array<vk::WriteDescriptorSet, 2> writes = {
        vk::WriteDescriptorSet(*sets[0], 0, 0, 1, vk::DescriptorType::eAccelerationStructureKHR, nullptr, nullptr, nullptr, &asWrite),
        vk::WriteDescriptorSet(*sets[0], 1, 0, vk::DescriptorType::eStorageBuffer, {}, resultInfo)};
    gpu.device().updateDescriptorSets(writes, {});

    const vkrt::Camera& c = scene.camera;
    glm::dvec3 forward = glm::normalize(c.target - c.eye);
    glm::dvec3 right = glm::normalize(glm::cross(forward, c.up));
    glm::dvec3 up = glm::cross(right, forward);
    double halfHeight = std::tan(glm::radians(c.fovY) / 2.0), halfWidth = halfHeight * width / height;
    CameraConstants camera{glm::vec3(c.eye), width, glm::vec3(right * halfWidth), height, glm::vec3(up * halfHeight),
                           spp, glm::vec3(forward)};

    std::vector<double> seconds;
    for (int i = 0; i <= runs; ++i) {
        auto start = Clock::now();
        gpu.submitAndWait([&](const vk::raii::CommandBuffer& cmd) {
            cmd.bindPipeline(vk::PipelineBindPoint::eCompute, *pipeline);
            cmd.bindDescriptorSets(vk::PipelineBindPoint::eCompute, *layout, 0, *sets[0], {});
            cmd.pushConstants<CameraConstants>(*layout, vk::ShaderStageFlagBits::eCompute, 0, camera);
            cmd.dispatch((width + 7) / 8, (height + 7) / 8, 1);
        });
        if (i > 0) seconds.push_back(std::chrono::duration<double>(Clock::now() - start).count());
    }
    const auto* pixels = static_cast<const PixelResult*>(results.mapped);
    uint64_t hits = 0;
    double distance = 0.0;
    for (uint32_t i = 0; i < width * height; ++i) {
        hits += pixels[i].hits;
        distance += pixels[i].distanceSum;
    }
    double rays = double(width) * height * spp;
    std::printf("%s: %s, %zu meshes, %ux%u x %u rays: %.2f Mrays/s (median of %d), build %.3f s, "
                "%.1f %% hit, mean distance %.4f\n",
                argv[1], gpu.name().c_str(), scene.meshes.size(), width, height, spp, rays / median(seconds) / 1e6, runs,
                buildSeconds, 100.0 * double(hits) / rays, hits ? distance / double(hits) : 0.0);
    return 0;
}

} // namespace

int main(int argc, char** argv)
{
    try {
        return run(argc, argv);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "vkrt-rayquery-bench: error: %s\n", e.what());
        return 2;
    }
}

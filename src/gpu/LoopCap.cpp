#include "gpu/LoopCap.h"

#include "gpu/Buffer.h"
#include "gpu/ComputeKernel.h"
#include "gpu/ShaderCompiler.h"
#include "gpu/VulkanContext.h"
#include "shared/Bindings.h"

#include <algorithm>
#include <regex>

namespace vkrt {

namespace {

constexpr uint32_t kProbePasses = 100000; // well past the 65,535 of Mesa < 25
constexpr int kFirstUncappedMesa = 25;    // measured: 1,000,000-pass loops complete (shared/NUMERICS.md)

bool isLavapipe(const DeviceInfo& device) { return device.driverId == vk::DriverId::eMesaLlvmpipe; }

} // namespace

std::string LoopCap::describe() const
{
    if (!budget) return "none (" + evidence + ")";
    return std::to_string(*budget) + " loop passes per invocation (" + evidence + ")";
}

std::optional<int> mesaMajorVersion(const std::string& driver)
{
    std::smatch match;
    static const std::regex mesa(R"(\bMesa (\d+)\.)");
    if (!std::regex_search(driver, match, mesa)) return std::nullopt;
    return std::stoi(match[1].str());
}

uint32_t probeCompletedLoopPasses(const VulkanContext& context)
{
    KernelSource source{defaultShaderRoot(), "kernels/loop_probe.comp", {}};
    CompiledKernel compiled = compileKernelCached(source, SpirvCache(SpirvCache::defaultDirectory()));
    ComputeKernel kernel(context, compiled.spirv, {{0, vk::DescriptorType::eStorageBuffer}}, sizeof(uint32_t));
    Buffer completed(context, 8 * sizeof(uint32_t),
                     vk::BufferUsageFlagBits::eStorageBuffer | vk::BufferUsageFlagBits::eTransferDst |
                         vk::BufferUsageFlagBits::eTransferSrc,
                     MemoryUse::Device);
    completed.clear(context);
    kernel.bind(0, completed);
    uint32_t passes = kProbePasses;
    context.submitAndWait([&](vk::CommandBuffer cmd) {
        kernel.recordDispatch(cmd, std::as_bytes(std::span(&passes, 1)), vk::Extent2D(1, 1));
    });
    std::vector<std::byte> bytes = completed.download(context);
    const auto* counts = reinterpret_cast<const uint32_t*>(bytes.data());
    return *std::min_element(counts, counts + 8);
}

LoopCap detectLoopCap(const VulkanContext& context, bool alwaysProbe)
{
    const DeviceInfo& device = context.deviceInfo();
    if (!isLavapipe(device)) return {std::nullopt, "not lavapipe: loops run to completion"};
    std::optional<int> mesa = mesaMajorVersion(device.driver);
    if (!alwaysProbe && mesa && *mesa >= kFirstUncappedMesa)
        return {std::nullopt, "Mesa " + std::to_string(*mesa) + " lavapipe runs loops to completion"};
    uint32_t completed = probeCompletedLoopPasses(context);
    std::string probe = "probe: " + std::to_string(completed) + " of " + std::to_string(kProbePasses) +
                        " loop passes ran on " + device.driver;
    if (completed >= kProbePasses) return {std::nullopt, probe};
    // The kernels count their passes against the documented budget, which the
    // probe measures on Mesa 22 (65,535 per group of 8, shared by all loops).
    return {std::min<uint32_t>(completed, gpu::LOOP_BUDGET), probe};
}

} // namespace vkrt

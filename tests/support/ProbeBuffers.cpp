#include "support/ProbeBuffers.h"

#include "gpu/Buffer.h"
#include "gpu/ComputeKernel.h"
#include "support/TestSupport.h"

#include <algorithm>
#include <cstring>
#include <span>

namespace vkrt::test {

std::vector<float> runProbeWithBuffers(const std::string& kernel, const std::vector<float>& input,
                                       size_t outputFloats, uint32_t invocations,
                                       const std::vector<ProbeBuffer>& buffers, const std::vector<Define>& defines)
{
    const VulkanContext& context = gpu();
    KernelSource source{defaultShaderRoot(), "../tests/gpu/kernels/" + kernel + ".comp", defines};
    std::vector<uint32_t> spirv = compileGlsl(source);
    constexpr vk::BufferUsageFlags kUsage = vk::BufferUsageFlagBits::eStorageBuffer;
    Buffer in = makeBufferFrom(context, input.empty() ? std::vector<float>{0.0f} : input, kUsage);
    Buffer out(context, std::max<size_t>(1, outputFloats) * sizeof(float),
               kUsage | vk::BufferUsageFlagBits::eTransferSrc | vk::BufferUsageFlagBits::eTransferDst,
               MemoryUse::Device);
    out.clear(context);
    std::vector<KernelBinding> bindings{{0, vk::DescriptorType::eStorageBuffer},
                                        {1, vk::DescriptorType::eStorageBuffer}};
    std::vector<Buffer> extra;
    for (const ProbeBuffer& buffer : buffers) {
        bindings.push_back({buffer.binding, vk::DescriptorType::eStorageBuffer});
        std::vector<std::byte> bytes = buffer.bytes.empty() ? std::vector<std::byte>(4) : buffer.bytes;
        extra.push_back(makeBufferFrom(context, bytes, kUsage));
    }
    ComputeKernel probe(context, spirv, bindings, sizeof(uint32_t));
    probe.bind(0, in);
    probe.bind(1, out);
    for (size_t i = 0; i < buffers.size(); ++i) probe.bind(buffers[i].binding, extra[i]);
    context.submitAndWait([&](vk::CommandBuffer cmd) {
        probe.recordDispatch(cmd, std::as_bytes(std::span(&invocations, 1)), vk::Extent2D((invocations + 63) / 64, 1));
    });
    auto bytes = out.download(context);
    std::vector<float> result(outputFloats);
    std::memcpy(result.data(), bytes.data(), outputFloats * sizeof(float));
    return result;
}

} // namespace vkrt::test

#include "gpu/Buffer.h"

#include "util/Error.h"

namespace vkrt {

Buffer::Buffer(const VulkanContext& context, vk::DeviceSize size, vk::BufferUsageFlags usage, MemoryUse use)
    : m_size(size)
{
    VKRT_CHECK(size > 0);
    const auto& device = context.device();
    vk::raii::Buffer buffer(device, vk::BufferCreateInfo({}, size, usage, vk::SharingMode::eExclusive));
    auto requirements = buffer.getMemoryRequirements();
    using Mem = vk::MemoryPropertyFlagBits;
    uint32_t type = use == MemoryUse::Device
                        ? context.findMemoryType(requirements.memoryTypeBits, Mem::eDeviceLocal)
                        : context.findMemoryType(requirements.memoryTypeBits, Mem::eHostVisible, Mem::eHostCached);
    vk::MemoryAllocateInfo allocation(requirements.size, type);
    vk::MemoryAllocateFlagsInfo addressable(vk::MemoryAllocateFlagBits::eDeviceAddress);
    if (usage & vk::BufferUsageFlagBits::eShaderDeviceAddress) allocation.setPNext(&addressable);
    m_memory = vk::raii::DeviceMemory(device, allocation);
    m_buffer = std::move(buffer);
    m_buffer.bindMemory(*m_memory, 0);
    auto flags = context.physicalDevice().getMemoryProperties().memoryTypes[type].propertyFlags;
    m_hostCoherent = bool(flags & Mem::eHostCoherent);
    if (flags & Mem::eHostVisible) m_mapped = m_memory.mapMemory(0, VK_WHOLE_SIZE);
}

vk::DeviceAddress Buffer::address(const VulkanContext& context) const
{
    return context.device().getBufferAddress(vk::BufferDeviceAddressInfo(*m_buffer));
}

void Buffer::upload(const VulkanContext& context, std::span<const std::byte> bytes)
{
    VKRT_CHECK(bytes.size() <= m_size);
    if (bytes.empty()) return;
    if (m_mapped) {
        std::memcpy(m_mapped, bytes.data(), bytes.size());
        if (!m_hostCoherent)
            context.device().flushMappedMemoryRanges(vk::MappedMemoryRange(*m_memory, 0, VK_WHOLE_SIZE));
        return;
    }
    Buffer staging(context, bytes.size(), vk::BufferUsageFlagBits::eTransferSrc, MemoryUse::Readback);
    staging.upload(context, bytes);
    context.submitAndWait(
        [&](vk::CommandBuffer cmd) { cmd.copyBuffer(staging.handle(), handle(), vk::BufferCopy(0, 0, bytes.size())); });
}

void Buffer::clear(const VulkanContext& context)
{
    context.submitAndWait([&](vk::CommandBuffer cmd) { cmd.fillBuffer(handle(), 0, VK_WHOLE_SIZE, 0); });
}

std::vector<std::byte> Buffer::download(const VulkanContext& context) const
{
    std::vector<std::byte> bytes(m_size);
    if (m_mapped) {
        if (!m_hostCoherent)
            context.device().invalidateMappedMemoryRanges(vk::MappedMemoryRange(*m_memory, 0, VK_WHOLE_SIZE));
        std::memcpy(bytes.data(), m_mapped, m_size);
        return bytes;
    }
    Buffer staging(context, m_size, vk::BufferUsageFlagBits::eTransferDst, MemoryUse::Readback);
    context.submitAndWait(
        [&](vk::CommandBuffer cmd) { cmd.copyBuffer(handle(), staging.handle(), vk::BufferCopy(0, 0, m_size)); });
    return staging.download(context);
}

} // namespace vkrt

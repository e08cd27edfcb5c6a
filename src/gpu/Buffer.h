#pragma once
// A VkBuffer with its own memory. Memory is declared first so the buffer is
// destroyed before the memory it is bound to.
#include "gpu/VulkanContext.h"

#include <cstring>
#include <span>
#include <vector>

namespace vkrt {

enum class MemoryUse {
    Device,   ///< GPU-local; host access through staging copies
    Readback, ///< host-visible, host-cached when possible
};

class Buffer {
public:
    Buffer(const VulkanContext& context, vk::DeviceSize size, vk::BufferUsageFlags usage, MemoryUse use);

    vk::Buffer handle() const { return *m_buffer; }
    vk::DeviceSize size() const { return m_size; }
    /// The buffer's device address; it needs eShaderDeviceAddress usage
    /// (acceleration-structure inputs, storage and scratch).
    vk::DeviceAddress address(const VulkanContext& context) const;
    /// Host pointer when the memory is host-visible (always on lavapipe), else null.
    void* mapped() const { return m_mapped; }

    /// Copies `bytes` to offset 0, directly when mapped, else through a staging buffer.
    void upload(const VulkanContext& context, std::span<const std::byte> bytes);
    /// Fills the whole buffer with zeros (vkCmdFillBuffer).
    void clear(const VulkanContext& context);
    /// Copies the whole buffer to host memory.
    std::vector<std::byte> download(const VulkanContext& context) const;

private:
    vk::DeviceSize m_size = 0;
    bool m_hostCoherent = false;
    vk::raii::DeviceMemory m_memory = nullptr;
    vk::raii::Buffer m_buffer = nullptr;
    void* m_mapped = nullptr;
};

/// A storage or uniform buffer initialised from GPU records.
template <typename T>
Buffer makeBufferFrom(const VulkanContext& context, std::span<const T> records, vk::BufferUsageFlags usage)
{
    // Vulkan forbids zero-sized buffers; an empty array still gets one record.
    vk::DeviceSize size = std::max<vk::DeviceSize>(sizeof(T), records.size() * sizeof(T));
    Buffer buffer(context, size, usage | vk::BufferUsageFlagBits::eTransferDst, MemoryUse::Device);
    buffer.upload(context, std::as_bytes(records));
    return buffer;
}

template <typename T>
Buffer makeBufferFrom(const VulkanContext& context, const std::vector<T>& records, vk::BufferUsageFlags usage)
{
    return makeBufferFrom(context, std::span<const T>(records), usage);
}

} // namespace vkrt

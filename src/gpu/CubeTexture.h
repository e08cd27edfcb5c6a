#pragma once
// A float32 RGBA cube image with a linear sampler, for the environment.
// Members are declared in dependency order (memory before image before view).
#include "gpu/VulkanContext.h"
#include "io/Image.h"

#include <array>

namespace vkrt {

class CubeTexture {
public:
    /// `faces` in Vulkan order +x, -x, +y, -y, +z, -z; all square and the same size.
    CubeTexture(const VulkanContext& context, const std::array<Image, 6>& faces);

    vk::ImageView view() const { return *m_view; }
    vk::Sampler sampler() const { return *m_sampler; }

private:
    vk::raii::DeviceMemory m_memory = nullptr;
    vk::raii::Image m_image = nullptr;
    vk::raii::ImageView m_view = nullptr;
    vk::raii::Sampler m_sampler = nullptr;

    void upload(const VulkanContext& context, const std::array<Image, 6>& faces, uint32_t size);
};

} // namespace vkrt

#pragma once
// A float32 RGBA image of the environment: six cube faces with a linear
// sampler, or one lat-long map read texel by texel (lib/environment.glsl
// filters it itself, as Mitsuba's envmap does). Members are declared in
// dependency order (memory before image before view).
#include "gpu/VulkanContext.h"
#include "io/Image.h"

#include <array>
#include <span>

namespace vkrt {

class EnvironmentTexture {
public:
    /// `faces` in Vulkan order +x, -x, +y, -y, +z, -z; all square and the same size.
    EnvironmentTexture(const VulkanContext& context, const std::array<Image, 6>& faces);
    /// One 2D image (a lat-long map), nearest texels.
    EnvironmentTexture(const VulkanContext& context, const Image& latLong);

    vk::ImageView view() const { return *m_view; }
    vk::Sampler sampler() const { return *m_sampler; }

private:
    vk::raii::DeviceMemory m_memory = nullptr;
    vk::raii::Image m_image = nullptr;
    vk::raii::ImageView m_view = nullptr;
    vk::raii::Sampler m_sampler = nullptr;

    /// The image of `layers` layers of one size, filled from them, and its view and sampler.
    void create(const VulkanContext& context, std::span<const Image> layers, bool cube);
    void upload(const VulkanContext& context, std::span<const Image> layers);
};

} // namespace vkrt

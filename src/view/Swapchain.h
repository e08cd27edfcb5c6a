#pragma once
// The window's swapchain: images we blit the displayed frame into. Recreated
// whenever the window changes size or the surface reports it out of date.
#include "gpu/VulkanContext.h"

#include <vector>

namespace vkrt {

class Swapchain {
public:
    Swapchain(const VulkanContext& context, vk::Extent2D windowExtent);

    vk::SwapchainKHR handle() const { return *m_swapchain; }
    const vk::raii::SwapchainKHR& raii() const { return m_swapchain; }
    vk::Extent2D extent() const { return m_extent; }
    vk::Image image(uint32_t index) const { return m_images[index]; }
    uint32_t imageCount() const { return uint32_t(m_images.size()); }

private:
    vk::Extent2D m_extent;
    vk::raii::SwapchainKHR m_swapchain = nullptr;
    std::vector<vk::Image> m_images;
};

} // namespace vkrt

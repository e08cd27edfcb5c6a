#include "view/Swapchain.h"

#include "util/Error.h"

#include <algorithm>

namespace vkrt {

namespace {

/// An 8-bit UNORM format: the displayed image is already sRGB-encoded, so an
/// _SRGB swapchain would encode it twice.
vk::SurfaceFormatKHR chooseFormat(const std::vector<vk::SurfaceFormatKHR>& formats)
{
    for (vk::Format preferred : {vk::Format::eB8G8R8A8Unorm, vk::Format::eR8G8B8A8Unorm})
        for (const auto& f : formats)
            if (f.format == preferred) return f;
    if (formats.empty()) throw GpuError("the window surface offers no image formats");
    return formats.front();
}

vk::Extent2D chooseExtent(const vk::SurfaceCapabilitiesKHR& caps, vk::Extent2D window)
{
    if (caps.currentExtent.width != UINT32_MAX) return caps.currentExtent;
    return {std::clamp(window.width, caps.minImageExtent.width, caps.maxImageExtent.width),
            std::clamp(window.height, caps.minImageExtent.height, caps.maxImageExtent.height)};
}

} // namespace

Swapchain::Swapchain(const VulkanContext& context, vk::Extent2D windowExtent)
{
    const auto& physical = context.physicalDevice();
    vk::SurfaceKHR surface = *context.surface();
    auto caps = physical.getSurfaceCapabilitiesKHR(surface);
    if (!(caps.supportedUsageFlags & vk::ImageUsageFlagBits::eTransferDst))
        throw GpuError("the window surface cannot be a transfer destination (vkrt blits into it)");
    vk::SurfaceFormatKHR format = chooseFormat(physical.getSurfaceFormatsKHR(surface));
    m_extent = chooseExtent(caps, windowExtent);
    uint32_t count = std::max(caps.minImageCount, 2u);
    if (caps.maxImageCount) count = std::min(count, caps.maxImageCount);
    vk::SwapchainCreateInfoKHR info({}, surface, count, format.format, format.colorSpace, m_extent, 1,
                                    vk::ImageUsageFlagBits::eTransferDst, vk::SharingMode::eExclusive, {},
                                    caps.currentTransform, vk::CompositeAlphaFlagBitsKHR::eOpaque,
                                    vk::PresentModeKHR::eFifo, VK_TRUE);
    if (!(caps.supportedCompositeAlpha & vk::CompositeAlphaFlagBitsKHR::eOpaque))
        info.compositeAlpha = vk::CompositeAlphaFlagBitsKHR::eInherit;
    m_swapchain = vk::raii::SwapchainKHR(context.device(), info);
    m_images = m_swapchain.getImages();
}

} // namespace vkrt

#pragma once
// Turns the accumulation buffer into the displayed 8-bit image (display.comp)
// and blits it, aspect preserved, into a swapchain image.
#include "gpu/Buffer.h"
#include "gpu/ComputeKernel.h"
#include "render/ImageBands.h"
#include "shared/Display.h"

#include <vector>

namespace vkrt {

class DisplayPass {
public:
    /// `accumulation` in the renderer's `bands`, whose size is the image's.
    DisplayPass(const VulkanContext& context, const BandedBuffer& accumulation, const ImageBands& bands);

    /// Tone-maps the current accumulation into the display image.
    void recordToneMap(vk::CommandBuffer cmd, const gpu::DisplayConstants& constants) const;
    /// Clears `target` and blits the display image into it, letterboxed;
    /// leaves `target` ready to present.
    void recordBlit(vk::CommandBuffer cmd, vk::Image target, vk::Extent2D targetExtent) const;
    /// The displayed pixels, RGBA8, rows top to bottom (as of the last tone map).
    std::vector<uint8_t> readPixels() const;

private:
    const VulkanContext& m_context;
    ImageBands m_bands;
    uint32_t m_width, m_height;
    vk::raii::DeviceMemory m_memory = nullptr;
    vk::raii::Image m_image = nullptr;
    vk::raii::ImageView m_view = nullptr;
    ComputeKernel m_kernel;
};

} // namespace vkrt

#include "view/DisplayPass.h"

#include "gpu/ShaderCompiler.h"
#include "shared/Bindings.h"
#include "util/Error.h"

#include <cstring>

namespace vkrt {

namespace {

constexpr vk::Format kDisplayFormat = vk::Format::eR8G8B8A8Unorm;
const vk::ImageSubresourceRange kColorRange(vk::ImageAspectFlagBits::eColor, 0, 1, 0, 1);

std::vector<uint32_t> displayKernelSpirv()
{
    KernelSource source{defaultShaderRoot(), "kernels/display.comp", {}};
    return compileKernelCached(source, SpirvCache(SpirvCache::defaultDirectory())).spirv;
}

void imageBarrier(vk::CommandBuffer cmd, vk::Image image, vk::ImageLayout from, vk::ImageLayout to,
                  vk::AccessFlags srcAccess, vk::AccessFlags dstAccess, vk::PipelineStageFlags srcStage,
                  vk::PipelineStageFlags dstStage)
{
    vk::ImageMemoryBarrier barrier(srcAccess, dstAccess, from, to, VK_QUEUE_FAMILY_IGNORED, VK_QUEUE_FAMILY_IGNORED,
                                   image, kColorRange);
    cmd.pipelineBarrier(srcStage, dstStage, {}, nullptr, nullptr, barrier);
}

/// The largest rectangle of the image's aspect ratio centred in the target.
std::array<vk::Offset3D, 2> letterbox(uint32_t width, uint32_t height, vk::Extent2D target)
{
    double scale = std::min(double(target.width) / width, double(target.height) / height);
    int32_t w = std::max(1, int32_t(width * scale)), h = std::max(1, int32_t(height * scale));
    int32_t x = (int32_t(target.width) - w) / 2, y = (int32_t(target.height) - h) / 2;
    return {vk::Offset3D(x, y, 0), vk::Offset3D(x + w, y + h, 1)};
}

} // namespace

DisplayPass::DisplayPass(const VulkanContext& context, const BandedBuffer& accumulation, const ImageBands& bands)
    : m_context(context),
      m_bands(bands),
      m_width(bands.width),
      m_height(bands.height),
      m_kernel(context, displayKernelSpirv(),
               {{gpu::DISPLAY_BINDING_ACCUMULATION, vk::DescriptorType::eStorageBuffer},
                {gpu::DISPLAY_BINDING_OUTPUT, vk::DescriptorType::eStorageImage}},
               sizeof(gpu::DisplayConstants), bands.count)
{
    const uint32_t width = m_width, height = m_height;
    const auto& device = context.device();
    vk::ImageCreateInfo info({}, vk::ImageType::e2D, kDisplayFormat, vk::Extent3D(width, height, 1), 1, 1,
                             vk::SampleCountFlagBits::e1, vk::ImageTiling::eOptimal,
                             vk::ImageUsageFlagBits::eStorage | vk::ImageUsageFlagBits::eTransferSrc);
    vk::raii::Image image(device, info);
    auto requirements = image.getMemoryRequirements();
    m_memory = vk::raii::DeviceMemory(
        device,
        vk::MemoryAllocateInfo(requirements.size, context.findMemoryType(requirements.memoryTypeBits,
                                                                         vk::MemoryPropertyFlagBits::eDeviceLocal)));
    m_image = std::move(image);
    m_image.bindMemory(*m_memory, 0);
    m_view = vk::raii::ImageView(device, vk::ImageViewCreateInfo({}, *m_image, vk::ImageViewType::e2D, kDisplayFormat,
                                                                 {}, kColorRange));
    // Between tone maps the image rests in TRANSFER_SRC (read by blits and
    // copies); the kernel writes it in GENERAL.
    context.submitAndWait([&](vk::CommandBuffer cmd) {
        imageBarrier(cmd, *m_image, vk::ImageLayout::eUndefined, vk::ImageLayout::eTransferSrcOptimal, {},
                     vk::AccessFlagBits::eTransferRead, vk::PipelineStageFlagBits::eTopOfPipe,
                     vk::PipelineStageFlagBits::eTransfer);
    });
    for (uint32_t b = 0; b < bands.count; ++b)
        m_kernel.bindInSet(b, gpu::DISPLAY_BINDING_ACCUMULATION, accumulation.band(b));
    m_kernel.bindStorageImage(gpu::DISPLAY_BINDING_OUTPUT, *m_view);
}

void DisplayPass::recordToneMap(vk::CommandBuffer cmd, const gpu::DisplayConstants& constants) const
{
    // Accumulation writes finish first; every pixel is rewritten, so the old
    // contents may be discarded (UNDEFINED) once earlier reads are done.
    vk::MemoryBarrier accumulated(vk::AccessFlagBits::eShaderWrite, vk::AccessFlagBits::eShaderRead);
    cmd.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader, vk::PipelineStageFlagBits::eComputeShader, {},
                        accumulated, nullptr, nullptr);
    imageBarrier(cmd, *m_image, vk::ImageLayout::eUndefined, vk::ImageLayout::eGeneral,
                 vk::AccessFlagBits::eTransferRead, vk::AccessFlagBits::eShaderWrite,
                 vk::PipelineStageFlagBits::eTransfer, vk::PipelineStageFlagBits::eComputeShader);
    // One dispatch per band, at base workgroup y = band * its workgroup rows
    // (display.comp reads the band's own buffer).
    vk::Extent2D groups((m_width + gpu::WORKGROUP_SIZE_X - 1) / gpu::WORKGROUP_SIZE_X, m_bands.tileRowsPerBand());
    for (uint32_t b = 0; b < m_bands.count; ++b) {
        m_kernel.recordBind(cmd, std::as_bytes(std::span(&constants, 1)), b);
        m_kernel.recordDispatchAt(cmd, vk::Offset2D(0, int32_t(b * groups.height)), 0, groups);
    }
    imageBarrier(cmd, *m_image, vk::ImageLayout::eGeneral, vk::ImageLayout::eTransferSrcOptimal,
                 vk::AccessFlagBits::eShaderWrite, vk::AccessFlagBits::eTransferRead,
                 vk::PipelineStageFlagBits::eComputeShader, vk::PipelineStageFlagBits::eTransfer);
}

void DisplayPass::recordBlit(vk::CommandBuffer cmd, vk::Image target, vk::Extent2D targetExtent) const
{
    using Layout = vk::ImageLayout;
    using Stage = vk::PipelineStageFlagBits;
    // The submission waits for the swapchain image at the transfer stage, so
    // the layout transition starts there too: from TOP_OF_PIPE it would not be
    // chained to that wait and could run before the presentation engine has
    // let go of the image (a WRITE_AFTER_READ hazard that Debian 13's
    // synchronization validation reports).
    imageBarrier(cmd, target, Layout::eUndefined, Layout::eTransferDstOptimal, {}, vk::AccessFlagBits::eTransferWrite,
                 Stage::eTransfer, Stage::eTransfer);
    cmd.clearColorImage(target, Layout::eTransferDstOptimal, vk::ClearColorValue(std::array<float, 4>{0, 0, 0, 1}),
                        kColorRange);
    imageBarrier(cmd, target, Layout::eTransferDstOptimal, Layout::eTransferDstOptimal,
                 vk::AccessFlagBits::eTransferWrite, vk::AccessFlagBits::eTransferWrite, Stage::eTransfer,
                 Stage::eTransfer);
    vk::ImageSubresourceLayers layers(vk::ImageAspectFlagBits::eColor, 0, 0, 1);
    vk::ImageBlit region(layers, {vk::Offset3D(0, 0, 0), vk::Offset3D(int32_t(m_width), int32_t(m_height), 1)}, layers,
                         letterbox(m_width, m_height, targetExtent));
    cmd.blitImage(*m_image, Layout::eTransferSrcOptimal, target, Layout::eTransferDstOptimal, region,
                  vk::Filter::eLinear);
    imageBarrier(cmd, target, Layout::eTransferDstOptimal, Layout::ePresentSrcKHR, vk::AccessFlagBits::eTransferWrite,
                 {}, Stage::eTransfer, Stage::eBottomOfPipe);
}

std::vector<uint8_t> DisplayPass::readPixels() const
{
    Buffer staging(m_context, vk::DeviceSize(m_width) * m_height * 4, vk::BufferUsageFlagBits::eTransferDst,
                   MemoryUse::Readback);
    m_context.submitAndWait([&](vk::CommandBuffer cmd) {
        vk::BufferImageCopy region(0, 0, 0, vk::ImageSubresourceLayers(vk::ImageAspectFlagBits::eColor, 0, 0, 1),
                                   {0, 0, 0}, vk::Extent3D(m_width, m_height, 1));
        cmd.copyImageToBuffer(*m_image, vk::ImageLayout::eTransferSrcOptimal, staging.handle(), region);
    });
    auto bytes = staging.download(m_context);
    std::vector<uint8_t> pixels(bytes.size());
    std::memcpy(pixels.data(), bytes.data(), bytes.size());
    return pixels;
}

} // namespace vkrt

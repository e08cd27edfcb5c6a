#include "gpu/CubeTexture.h"

#include "gpu/Buffer.h"
#include "util/Error.h"

namespace vkrt {

namespace {

constexpr vk::Format kFormat = vk::Format::eR32G32B32A32Sfloat;

std::vector<float> packRgba(const std::array<Image, 6>& faces)
{
    std::vector<float> rgba;
    for (const Image& face : faces) {
        for (size_t i = 0; i < face.pixelCount(); ++i) {
            rgba.insert(rgba.end(), {face.rgb[i * 3], face.rgb[i * 3 + 1], face.rgb[i * 3 + 2], 1.0f});
        }
    }
    return rgba;
}

void transition(vk::CommandBuffer cmd, vk::Image image, vk::ImageLayout from, vk::ImageLayout to,
                vk::AccessFlags srcAccess, vk::AccessFlags dstAccess, vk::PipelineStageFlags srcStage,
                vk::PipelineStageFlags dstStage)
{
    vk::ImageMemoryBarrier barrier(srcAccess, dstAccess, from, to, VK_QUEUE_FAMILY_IGNORED, VK_QUEUE_FAMILY_IGNORED,
                                   image, vk::ImageSubresourceRange(vk::ImageAspectFlagBits::eColor, 0, 1, 0, 6));
    cmd.pipelineBarrier(srcStage, dstStage, {}, nullptr, nullptr, barrier);
}

} // namespace

CubeTexture::CubeTexture(const VulkanContext& context, const std::array<Image, 6>& faces)
{
    uint32_t size = faces[0].width;
    for (const Image& face : faces) VKRT_CHECK(face.width == size && face.height == size);
    const auto& device = context.device();
    vk::ImageCreateInfo info(vk::ImageCreateFlagBits::eCubeCompatible, vk::ImageType::e2D, kFormat,
                             vk::Extent3D(size, size, 1), 1, 6, vk::SampleCountFlagBits::e1, vk::ImageTiling::eOptimal,
                             vk::ImageUsageFlagBits::eSampled | vk::ImageUsageFlagBits::eTransferDst);
    vk::raii::Image image(device, info);
    auto requirements = image.getMemoryRequirements();
    m_memory = vk::raii::DeviceMemory(
        device,
        vk::MemoryAllocateInfo(requirements.size, context.findMemoryType(requirements.memoryTypeBits,
                                                                         vk::MemoryPropertyFlagBits::eDeviceLocal)));
    m_image = std::move(image);
    m_image.bindMemory(*m_memory, 0);
    upload(context, faces, size);

    m_view =
        vk::raii::ImageView(device, vk::ImageViewCreateInfo({}, *m_image, vk::ImageViewType::eCube, kFormat, {},
                                                            vk::ImageSubresourceRange(vk::ImageAspectFlagBits::eColor,
                                                                                      0, 1, 0, 6)));
    // Linear filtering when the device can filter float32, else nearest texels.
    bool linear = bool(context.physicalDevice().getFormatProperties(kFormat).optimalTilingFeatures &
                       vk::FormatFeatureFlagBits::eSampledImageFilterLinear);
    vk::Filter filter = linear ? vk::Filter::eLinear : vk::Filter::eNearest;
    vk::SamplerCreateInfo sampler({}, filter, filter, vk::SamplerMipmapMode::eNearest,
                                  vk::SamplerAddressMode::eClampToEdge, vk::SamplerAddressMode::eClampToEdge,
                                  vk::SamplerAddressMode::eClampToEdge);
    m_sampler = vk::raii::Sampler(device, sampler);
}

void CubeTexture::upload(const VulkanContext& context, const std::array<Image, 6>& faces, uint32_t size)
{
    std::vector<float> rgba = packRgba(faces);
    Buffer staging(context, rgba.size() * sizeof(float), vk::BufferUsageFlagBits::eTransferSrc, MemoryUse::Readback);
    staging.upload(context, std::as_bytes(std::span(rgba)));
    context.submitAndWait([&](vk::CommandBuffer cmd) {
        using Layout = vk::ImageLayout;
        using Stage = vk::PipelineStageFlagBits;
        transition(cmd, *m_image, Layout::eUndefined, Layout::eTransferDstOptimal, {},
                   vk::AccessFlagBits::eTransferWrite, Stage::eTopOfPipe, Stage::eTransfer);
        vk::BufferImageCopy region(0, 0, 0, vk::ImageSubresourceLayers(vk::ImageAspectFlagBits::eColor, 0, 0, 6),
                                   {0, 0, 0}, vk::Extent3D(size, size, 1));
        cmd.copyBufferToImage(staging.handle(), *m_image, Layout::eTransferDstOptimal, region);
        transition(cmd, *m_image, Layout::eTransferDstOptimal, Layout::eShaderReadOnlyOptimal,
                   vk::AccessFlagBits::eTransferWrite, vk::AccessFlagBits::eShaderRead, Stage::eTransfer,
                   Stage::eComputeShader);
    });
}

} // namespace vkrt

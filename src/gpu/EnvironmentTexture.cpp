#include "gpu/EnvironmentTexture.h"

#include "gpu/Buffer.h"
#include "util/Error.h"

namespace vkrt {

namespace {

constexpr vk::Format kFormat = vk::Format::eR32G32B32A32Sfloat;

std::vector<float> packRgba(std::span<const Image> layers)
{
    std::vector<float> rgba;
    rgba.reserve(layers.size() * layers[0].pixelCount() * 4);
    for (const Image& layer : layers) {
        for (size_t i = 0; i < layer.pixelCount(); ++i) {
            rgba.insert(rgba.end(), {layer.rgb[i * 3], layer.rgb[i * 3 + 1], layer.rgb[i * 3 + 2], 1.0f});
        }
    }
    return rgba;
}

void transition(vk::CommandBuffer cmd, vk::Image image, uint32_t layers, vk::ImageLayout from, vk::ImageLayout to,
                vk::AccessFlags srcAccess, vk::AccessFlags dstAccess, vk::PipelineStageFlags srcStage,
                vk::PipelineStageFlags dstStage)
{
    vk::ImageMemoryBarrier barrier(srcAccess, dstAccess, from, to, VK_QUEUE_FAMILY_IGNORED, VK_QUEUE_FAMILY_IGNORED,
                                   image,
                                   vk::ImageSubresourceRange(vk::ImageAspectFlagBits::eColor, 0, 1, 0, layers));
    cmd.pipelineBarrier(srcStage, dstStage, {}, nullptr, nullptr, barrier);
}

} // namespace

EnvironmentTexture::EnvironmentTexture(const VulkanContext& context, const std::array<Image, 6>& faces)
{
    for (const Image& face : faces) VKRT_CHECK(face.width == faces[0].width && face.height == face.width);
    create(context, faces, true);
}

EnvironmentTexture::EnvironmentTexture(const VulkanContext& context, const Image& latLong)
{
    create(context, std::span(&latLong, 1), false);
}

void EnvironmentTexture::create(const VulkanContext& context, std::span<const Image> layers, bool cube)
{
    const uint32_t count = uint32_t(layers.size());
    const vk::Extent3D extent(layers[0].width, layers[0].height, 1);
    const auto& device = context.device();
    vk::ImageCreateInfo info(cube ? vk::ImageCreateFlagBits::eCubeCompatible : vk::ImageCreateFlags{},
                             vk::ImageType::e2D, kFormat, extent, 1, count, vk::SampleCountFlagBits::e1,
                             vk::ImageTiling::eOptimal,
                             vk::ImageUsageFlagBits::eSampled | vk::ImageUsageFlagBits::eTransferDst);
    vk::raii::Image image(device, info);
    auto requirements = image.getMemoryRequirements();
    m_memory = vk::raii::DeviceMemory(
        device,
        vk::MemoryAllocateInfo(requirements.size, context.findMemoryType(requirements.memoryTypeBits,
                                                                         vk::MemoryPropertyFlagBits::eDeviceLocal)));
    m_image = std::move(image);
    m_image.bindMemory(*m_memory, 0);
    upload(context, layers);

    m_view = vk::raii::ImageView(
        device, vk::ImageViewCreateInfo({}, *m_image, cube ? vk::ImageViewType::eCube : vk::ImageViewType::e2D,
                                        kFormat, {},
                                        vk::ImageSubresourceRange(vk::ImageAspectFlagBits::eColor, 0, 1, 0, count)));
    // A cube is filtered linearly when the device can filter float32; a
    // lat-long map is read with texelFetch, so its sampler never filters.
    bool linear = cube && bool(context.physicalDevice().getFormatProperties(kFormat).optimalTilingFeatures &
                               vk::FormatFeatureFlagBits::eSampledImageFilterLinear);
    vk::Filter filter = linear ? vk::Filter::eLinear : vk::Filter::eNearest;
    vk::SamplerCreateInfo sampler({}, filter, filter, vk::SamplerMipmapMode::eNearest,
                                  vk::SamplerAddressMode::eClampToEdge, vk::SamplerAddressMode::eClampToEdge,
                                  vk::SamplerAddressMode::eClampToEdge);
    m_sampler = vk::raii::Sampler(device, sampler);
}

void EnvironmentTexture::upload(const VulkanContext& context, std::span<const Image> layers)
{
    const uint32_t count = uint32_t(layers.size());
    std::vector<float> rgba = packRgba(layers);
    Buffer staging(context, rgba.size() * sizeof(float), vk::BufferUsageFlagBits::eTransferSrc, MemoryUse::Readback);
    staging.upload(context, std::as_bytes(std::span(rgba)));
    context.submitAndWait([&](vk::CommandBuffer cmd) {
        using Layout = vk::ImageLayout;
        using Stage = vk::PipelineStageFlagBits;
        transition(cmd, *m_image, count, Layout::eUndefined, Layout::eTransferDstOptimal, {},
                   vk::AccessFlagBits::eTransferWrite, Stage::eTopOfPipe, Stage::eTransfer);
        vk::BufferImageCopy region(0, 0, 0,
                                   vk::ImageSubresourceLayers(vk::ImageAspectFlagBits::eColor, 0, 0, count),
                                   {0, 0, 0}, vk::Extent3D(layers[0].width, layers[0].height, 1));
        cmd.copyBufferToImage(staging.handle(), *m_image, Layout::eTransferDstOptimal, region);
        transition(cmd, *m_image, count, Layout::eTransferDstOptimal, Layout::eShaderReadOnlyOptimal,
                   vk::AccessFlagBits::eTransferWrite, vk::AccessFlagBits::eShaderRead, Stage::eTransfer,
                   Stage::eComputeShader);
    });
}

} // namespace vkrt

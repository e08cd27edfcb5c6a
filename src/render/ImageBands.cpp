#include "render/ImageBands.h"

#include "shared/Bindings.h"
#include "util/Error.h"

#include <algorithm>
#include <cstdio>

namespace vkrt {

namespace {

std::string gibibytes(double bytes)
{
    char text[32];
    std::snprintf(text, sizeof text, "%.2f GiB", bytes / (1024.0 * 1024.0 * 1024.0));
    return text;
}

std::string sizeOf(const ImageBands& bands) { return std::to_string(bands.width) + "x" + std::to_string(bands.height); }

} // namespace

uint32_t ImageBands::rows(uint32_t band) const
{
    VKRT_CHECK(band < count);
    return std::min(rowsPerBand, height - firstRow(band));
}

uint32_t ImageBands::tileRowsPerBand() const
{
    return (rowsPerBand + gpu::WORKGROUP_SIZE_Y - 1) / gpu::WORKGROUP_SIZE_Y;
}

ImageBands imageBandsFor(uint32_t width, uint32_t height, uint64_t bytesPerPixel, uint64_t maxBytes,
                         const std::string& what)
{
    VKRT_CHECK(width > 0 && height > 0 && bytesPerPixel > 0);
    ImageBands bands{width, height, height, 1};
    uint64_t rowBytes = uint64_t(width) * bytesPerPixel;
    if (rowBytes * height <= maxBytes) return bands; // one band: the whole image
    uint64_t fittingRows = maxBytes / rowBytes;
    uint64_t rows = fittingRows / gpu::WORKGROUP_SIZE_Y * gpu::WORKGROUP_SIZE_Y;
    if (rows == 0)
        throw InputError(what + ": a " + std::to_string(width) + " pixel wide image needs " +
                         std::to_string(rowBytes * gpu::WORKGROUP_SIZE_Y) + " bytes for one band of " +
                         std::to_string(gpu::WORKGROUP_SIZE_Y) + " rows of " + std::to_string(bytesPerPixel) +
                         " bytes per pixel, more than the device's maxStorageBufferRange of " +
                         std::to_string(maxBytes) + " bytes; render a narrower image (--width)");
    bands.rowsPerBand = uint32_t(rows);
    bands.count = (height + bands.rowsPerBand - 1) / bands.rowsPerBand;
    return bands;
}

BandedBuffer::BandedBuffer(const VulkanContext& context, const ImageBands& bands, uint64_t bytesPerPixel,
                           const std::string& origin, const std::string& what, const std::string& hint)
{
    constexpr vk::BufferUsageFlags usage = vk::BufferUsageFlagBits::eStorageBuffer |
                                           vk::BufferUsageFlagBits::eTransferDst |
                                           vk::BufferUsageFlagBits::eTransferSrc;
    uint64_t total = bytesPerPixel * bands.width * bands.height;
    m_bands.reserve(bands.count);
    try {
        for (uint32_t b = 0; b < bands.count; ++b)
            m_bands.emplace_back(context, bytesPerPixel * bands.width * bands.rows(b), usage, MemoryUse::Device);
    } catch (const vk::SystemError& error) {
        throw InputError(origin + ": a " + sizeOf(bands) + " image needs " + gibibytes(double(total)) + " for " + what +
                         ", which " + context.deviceInfo().name + " could not allocate (" + error.what() +
                         "); render a smaller image (--width/--height)" + hint);
    }
}

void BandedBuffer::clear(const VulkanContext& context)
{
    for (Buffer& band : m_bands) band.clear(context);
}

std::vector<std::byte> BandedBuffer::download(const VulkanContext& context) const
{
    if (m_bands.size() == 1) return m_bands.front().download(context);
    size_t total = 0;
    for (const Buffer& band : m_bands) total += size_t(band.size());
    std::vector<std::byte> bytes;
    bytes.reserve(total);
    for (const Buffer& band : m_bands) {
        std::vector<std::byte> part = band.download(context);
        bytes.insert(bytes.end(), part.begin(), part.end());
    }
    return bytes;
}

} // namespace vkrt

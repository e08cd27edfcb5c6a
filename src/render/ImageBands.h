#pragma once
// An image's per-pixel GPU buffers split into bands of whole workgroup rows,
// so that no buffer a kernel binds exceeds the device's
// maxStorageBufferRange (128 MiB on lavapipe: a 3840x2160 accumulation
// buffer needs 0.22 GiB). Band b holds rows [b * rowsPerBand, ...) in the
// same row-major order, so the bands laid end to end are the whole image's
// buffer. A band is dispatched with base workgroup y = b * (band height in
// workgroups) (kernels/render.comp), and its tiles are exactly the whole
// image's: every workgroup sees the same pixels, so the image is the same,
// bit for bit, in any number of bands.
#include "gpu/Buffer.h"

#include <cstdint>
#include <string>
#include <vector>

namespace vkrt {

struct ImageBands {
    uint32_t width = 0;
    uint32_t height = 0;
    uint32_t rowsPerBand = 0; ///< a multiple of WORKGROUP_SIZE_Y, or the whole height
    uint32_t count = 0;

    uint32_t firstRow(uint32_t band) const { return band * rowsPerBand; }
    uint32_t rows(uint32_t band) const;
    /// Workgroup rows of one band's dispatch (the last band's may reach past the image).
    uint32_t tileRowsPerBand() const;
};

/// The fewest bands in which a width x height image's largest per-pixel
/// buffer (`bytesPerPixel`) fits `maxBytes` per band. Throws InputError (with
/// `what`, the image's origin, for the message) if not even one workgroup
/// row of that buffer fits.
ImageBands imageBandsFor(uint32_t width, uint32_t height, uint64_t bytesPerPixel, uint64_t maxBytes,
                         const std::string& what);

/// One per-pixel storage buffer of an image, as one device buffer per band.
class BandedBuffer {
public:
    /// Throws InputError naming `origin` (the scene), `what` and the size if
    /// the device cannot allocate it; `hint` ends the advice.
    BandedBuffer(const VulkanContext& context, const ImageBands& bands, uint64_t bytesPerPixel,
                 const std::string& origin, const std::string& what, const std::string& hint = "");

    const Buffer& band(uint32_t index) const { return m_bands.at(index); }
    uint32_t bandCount() const { return uint32_t(m_bands.size()); }
    /// Fills every band with zeros.
    void clear(const VulkanContext& context);
    /// The whole image's buffer: the bands' bytes end to end.
    std::vector<std::byte> download(const VulkanContext& context) const;

private:
    std::vector<Buffer> m_bands;
};

} // namespace vkrt

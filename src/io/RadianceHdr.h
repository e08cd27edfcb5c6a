#pragma once
// Radiance RGBE (.hdr) images, read by vkrt itself: the header is checked
// against the file's length before any pixel buffer exists, as OpenEXR
// headers are (io/ImageHeader.h), and the scanlines are decoded in time
// linear in the file's bytes and pixels. stb_image's reader, used before,
// looped forever on a run of length 0 and filled a truncated file's missing
// rows with black (docs/robustness.md).
//
// Read: the "#?RADIANCE" or "#?RGBE" signature, header lines up to a blank
// one (FORMAT must be 32-bit_rle_rgbe when given; EXPOSURE and others are
// ignored, as stb_image ignored them), the resolution line "-Y H +X W" (top
// row first: the orientation every writer vkrt knows uses), then H scanlines,
// each flat (W RGBE quadruples) or adaptive run-length encoded (2, 2, W high
// byte, W low byte, then each of the four channels as runs of 128 + n copies
// of one byte or literal runs of n bytes, 1 <= n <= 128 and the scanline's
// width never overrun). The old-style RLE (1, 1, 1, count repeats) and XYZE
// files are refused by name.
#include "io/ImageHeader.h"

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace vkrt {

/// Whether the bytes start with a Radiance signature ("#?").
bool isRadianceHdr(std::span<const uint8_t> bytes);

/// The size the header declares, checked: within ImageLimits, and the file
/// (of `fileBytes` bytes, whose first ones, at least the header, are `bytes`)
/// long enough for that many scanlines at the best compression the format
/// allows. Throws InputError starting with `name`.
ImageExtent radianceHdrExtent(std::span<const uint8_t> bytes, uint64_t fileBytes, const std::string& name);
/// The same for a file, reading no more than its header.
ImageExtent radianceHdrFileExtent(const std::filesystem::path& file);

/// The pixels, linear RGBA floats (alpha 1), rows top to bottom. Throws
/// InputError starting with `name` for anything malformed: a run of length 0
/// or past the scanline's end, a scanline cut short, bytes missing at the end.
struct RadianceHdrImage {
    ImageExtent extent;
    std::vector<float> rgba;
};
RadianceHdrImage decodeRadianceHdr(std::span<const uint8_t> bytes, const std::string& name);

} // namespace vkrt

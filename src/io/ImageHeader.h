#pragma once
// What an image file's header says about its pixels, read and checked before
// any pixel buffer exists: a header is a claim, and a few kilobytes can claim
// gigabytes (docs/robustness.md). OpenEXR headers are checked against the
// file's length; PNG, JPEG and HDR sizes come from stb_image's header parse.
#include <ImfHeader.h>
#include <ImfIO.h>

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

namespace vkrt {

/// An image's size in pixels.
struct ImageExtent {
    uint32_t width = 0;
    uint32_t height = 0;

    uint64_t pixels() const { return uint64_t(width) * height; }
    std::string str() const { return std::to_string(width) + "x" + std::to_string(height); }
};

/// The most decoded bytes a stored byte of each OpenEXR compression can turn
/// into, with margin over what vkrt measured on constant images (a constant
/// image compresses best): NONE 1; RLE 128 (at most 64 by construction);
/// ZIP, ZIPS, PIZ, PXR24, B44(A) 2048 (deflate's ceiling is about 1032,
/// measured ZIP 1014, PXR24 1281, PIZ 332); DWAA, DWAB and any other 2^18
/// (measured DWAB 30040). A file shorter than its pixels divided by this
/// cannot hold them.
uint64_t exrMaxCompressionRatio(Imf::Compression compression);

/// Reads the (first part's) header of the OpenEXR file in `stream`, which
/// holds `streamBytes` bytes and is read from its start, and checks before
/// anything is allocated from it: every attribute fits in the file, the file
/// is not deep, the data window is within ImageLimits::maxSide a side
/// and ImageLimits::maxPixels, tiles are no larger than the image (or
/// 256 a side), and the file is long enough for the chunks and pixels the
/// header declares. Throws InputError starting with `name`.
Imf::Header readCheckedExrHeader(Imf::IStream& stream, uint64_t streamBytes, const std::string& name);

/// The data window's size (of a header readCheckedExrHeader accepted).
ImageExtent extentOf(const Imf::Header& header);

/// OpenEXR's input from bytes in memory (an image embedded in a mesh file).
class MemoryExrStream : public Imf::IStream {
public:
    MemoryExrStream(std::span<const uint8_t> bytes, const std::string& name);
    bool read(char c[], int n) override;
    uint64_t tellg() override { return m_position; }
    void seekg(uint64_t position) override { m_position = position; }

private:
    std::span<const uint8_t> m_bytes;
    uint64_t m_position = 0;
};

/// The size in a PNG, JPEG, HDR (any format stb_image reads) header, from
/// bytes in memory or a file, without decoding; throws InputError starting
/// with `name` (or the file) when there is no header stb_image can read.
ImageExtent stbImageExtent(std::span<const uint8_t> bytes, const std::string& name);
ImageExtent stbImageFileExtent(const std::filesystem::path& file);

/// An image file's size from its header alone: .exr (any case) through
/// readCheckedExrHeader, anything else through stb_image.
ImageExtent imageFileExtent(const std::filesystem::path& file);

} // namespace vkrt

#pragma once
// Test images written by code: 8-bit files through stb_image_write, and PNGs
// stb_image_write cannot make (16-bit, odd bit depths, bare headers) by a
// minimal encoder (stored, uncompressed deflate blocks).
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace vkrt::test {

/// A fresh directory named after the running test.
std::filesystem::path textureTestDir();

/// Writes raw bytes to a file.
std::filesystem::path writeBytes(const std::filesystem::path& path, const std::string& bytes);

/// An 8-bit PNG of `channels` channels (1 grey, 2 grey + alpha, 3 RGB, 4 RGBA), rows top to bottom.
std::filesystem::path write8BitPng(const std::filesystem::path& path, uint32_t width, uint32_t height, int channels,
                                   const std::vector<uint8_t>& samples);

/// A PNG with samples of `bitDepth` bits (stored big-endian as PNG wants) and
/// PNG colour type `colourType` (0 grey, 2 RGB, 4 grey + alpha, 6 RGBA).
/// Only depths 8 and 16 get pixel data; any other depth writes the header
/// with no image data (enough for stb_image to refuse it).
std::filesystem::path writePng(const std::filesystem::path& path, uint32_t width, uint32_t height, int bitDepth,
                               int colourType, const std::vector<uint16_t>& samples);

/// A real, small OpenEXR file (8x8 float RGB, `compression` an Imf::Compression
/// value, 3 = ZIP) whose header then claims `width` x `height` pixels: what a
/// damaged or hostile header looks like. A few hundred bytes.
std::filesystem::path writeExrDeclaring(const std::filesystem::path& path, uint32_t width, uint32_t height,
                                        int compression = 3);

/// A real `side` x `side` 8-bit grey PNG, every pixel black, deflated at
/// about 160:1 (fixed-Huffman blocks of 258-byte matches), written as it is
/// encoded: a decompression bomb (16384 a side: 1.7 MB on disk, 268 MB of
/// samples, 4 GiB as float RGBA) made without holding the image.
std::filesystem::path writePngBomb(const std::filesystem::path& path, uint32_t side);

/// The repository's third-party assets: assets/ (sources and terms in assets/README.md).
std::filesystem::path assetsDir();

} // namespace vkrt::test

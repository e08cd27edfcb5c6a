#include "texture/TextureTestFiles.h"

#include "support/TestSupport.h"

#include <stb/stb_image_write.h>

#include <gtest/gtest.h>

#include <array>
#include <cstdlib>
#include <fstream>

namespace vkrt::test {

namespace fs = std::filesystem;

fs::path textureTestDir()
{
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    return freshTempDir(std::string("texture-") + info->test_suite_name() + "-" + info->name());
}

fs::path writeBytes(const fs::path& path, const std::string& bytes)
{
    std::ofstream out(path, std::ios::binary);
    out.write(bytes.data(), std::streamsize(bytes.size()));
    return path;
}

fs::path write8BitPng(const fs::path& path, uint32_t width, uint32_t height, int channels,
                      const std::vector<uint8_t>& samples)
{
    EXPECT_EQ(samples.size(), size_t(width) * height * channels);
    EXPECT_TRUE(stbi_write_png(path.c_str(), int(width), int(height), channels, samples.data(),
                               int(width) * channels));
    return path;
}

namespace {

uint32_t crc32(const std::string& bytes)
{
    uint32_t crc = 0xffffffffu;
    for (unsigned char byte : bytes) {
        crc ^= byte;
        for (int bit = 0; bit < 8; ++bit) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
    }
    return ~crc;
}

void appendBigEndian(std::string& out, uint32_t value, int bytes)
{
    for (int i = bytes - 1; i >= 0; --i) out += char((value >> (8 * i)) & 0xffu);
}

std::string chunk(const std::string& type, const std::string& data)
{
    std::string out;
    appendBigEndian(out, uint32_t(data.size()), 4);
    out += type + data;
    appendBigEndian(out, crc32(type + data), 4);
    return out;
}

/// zlib stream of stored (uncompressed) deflate blocks.
std::string zlibStored(const std::string& data)
{
    std::string out = "\x78\x01";
    size_t at = 0;
    do {
        const size_t length = std::min<size_t>(65535, data.size() - at);
        out += char(at + length == data.size() ? 1 : 0);
        out += char(length & 0xff);
        out += char(length >> 8);
        out += char(~length & 0xff);
        out += char((~length >> 8) & 0xff);
        out += data.substr(at, length);
        at += length;
    } while (at < data.size());
    uint32_t a = 1, b = 0;
    for (unsigned char byte : data) {
        a = (a + byte) % 65521;
        b = (b + a) % 65521;
    }
    appendBigEndian(out, b << 16 | a, 4);
    return out;
}

int channelsOf(int colourType)
{
    constexpr std::array<int, 7> channels{1, 0, 3, 0, 2, 0, 4};
    return channels.at(size_t(colourType));
}

} // namespace

fs::path writePng(const fs::path& path, uint32_t width, uint32_t height, int bitDepth, int colourType,
                  const std::vector<uint16_t>& samples)
{
    std::string header;
    appendBigEndian(header, width, 4);
    appendBigEndian(header, height, 4);
    header += char(bitDepth);
    header += char(colourType);
    header += std::string(3, '\0'); // deflate, adaptive filtering, no interlace
    std::string png = "\x89PNG\r\n\x1a\n" + chunk("IHDR", header);
    if (bitDepth == 8 || bitDepth == 16) {
        const size_t rowSamples = size_t(width) * channelsOf(colourType);
        EXPECT_EQ(samples.size(), rowSamples * height);
        std::string raw;
        for (uint32_t y = 0; y < height; ++y) {
            raw += '\0'; // filter: none
            for (size_t i = 0; i < rowSamples; ++i) appendBigEndian(raw, samples[y * rowSamples + i], bitDepth / 8);
        }
        png += chunk("IDAT", zlibStored(raw));
    }
    png += chunk("IEND", "");
    return writeBytes(path, png);
}

fs::path assetsDir()
{
    return fs::path(VKRT_TEST_SOURCE_DIR) / "assets";
}

} // namespace vkrt::test

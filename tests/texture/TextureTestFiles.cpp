#include "texture/TextureTestFiles.h"

#include "support/TestSupport.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <stb/stb_image_write.h>

#include <gtest/gtest.h>

#include <array>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>

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
    EXPECT_TRUE(stbi_write_png(path.c_str(), int(width), int(height), channels, samples.data(), int(width) * channels));
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

fs::path writeExrDeclaring(const fs::path& path, uint32_t width, uint32_t height, int compression)
{
    const int side = 8;
    std::vector<float> pixels(side * side * 3, 0.5f);
    Imf::Header header(side, side);
    header.compression() = Imf::Compression(compression);
    Imf::FrameBuffer frame;
    for (int c = 0; c < 3; ++c) {
        const char* name[3] = {"R", "G", "B"};
        header.channels().insert(name[c], Imf::Channel(Imf::FLOAT));
        frame.insert(name[c], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(pixels.data() + c), 12, 12 * side));
    }
    {
        Imf::OutputFile file(path.c_str(), header);
        file.setFrameBuffer(frame);
        file.writePixels(side);
    }
    // The data window's four ints follow "dataWindow\0box2i\0" and the attribute's size.
    std::ifstream in(path, std::ios::binary);
    std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    const std::string key("dataWindow\0box2i\0", 17);
    const size_t at = bytes.find(key);
    EXPECT_NE(at, std::string::npos);
    const int32_t window[4] = {0, 0, int32_t(width) - 1, int32_t(height) - 1};
    std::memcpy(&bytes[at + key.size() + 4], window, sizeof window); // little-endian, as EXR
    return writeBytes(path, bytes);
}

namespace {

/// Deflate's bits, least significant first; Huffman codes most significant first.
class BitWriter {
public:
    explicit BitWriter(std::string& out) : m_out(out) {}
    void bits(uint32_t value, int count)
    {
        for (int i = 0; i < count; ++i) put((value >> i) & 1u);
    }
    void code(uint32_t value, int count)
    {
        for (int i = count - 1; i >= 0; --i) put((value >> i) & 1u);
    }
    void flush()
    {
        if (m_used) m_out += char(m_byte);
        m_byte = 0, m_used = 0;
    }

private:
    void put(uint32_t bit)
    {
        m_byte |= uint8_t(bit << m_used);
        if (++m_used == 8) flush();
    }
    std::string& m_out;
    uint8_t m_byte = 0;
    int m_used = 0;
};

/// A zlib stream of `length` zero bytes: one fixed-Huffman block, a literal 0
/// then matches of 258 at distance 1 (RFC 1951, 3.2.6).
std::string zlibZeros(uint64_t length)
{
    std::string out = "\x78\x01";
    BitWriter writer(out);
    writer.bits(1, 1); // final block
    writer.bits(1, 2); // fixed Huffman codes
    auto literalZero = [&] { writer.code(0x30, 8); };
    literalZero();
    uint64_t left = length - 1;
    for (; left >= 258; left -= 258) {
        writer.code(0xc5, 8); // length symbol 285 (258), codes 280-287 are 11000000 + n
        writer.code(0, 5);    // distance code 0: distance 1
    }
    for (; left > 0; --left) literalZero();
    writer.code(0, 7); // end of block (256)
    writer.flush();
    appendBigEndian(out, uint32_t(length % 65521) << 16 | 1u, 4); // Adler-32 of zeros
    return out;
}

} // namespace

fs::path writePngBomb(const fs::path& path, uint32_t side)
{
    std::string header;
    appendBigEndian(header, side, 4);
    appendBigEndian(header, side, 4);
    header += char(8); // bit depth
    header += char(0); // grey
    header += std::string(3, '\0');
    // Each row: filter byte 0 and `side` black samples, all zero bytes.
    const std::string png = "\x89PNG\r\n\x1a\n" + chunk("IHDR", header) +
                            chunk("IDAT", zlibZeros(uint64_t(side) * (side + 1))) + chunk("IEND", "");
    return writeBytes(path, png);
}

fs::path assetsDir() { return fs::path(VKRT_TEST_SOURCE_DIR) / "assets"; }

} // namespace vkrt::test

// Radiance .hdr files (io/RadianceHdr.h), written here byte by byte: flat and
// run-length scanlines decode to the RGBE values worked out from the format's
// definition; a damaged file (a run of length 0, a run past the scanline, a
// header claiming more pixels than the file can hold, a file cut short) is an
// InputError naming it, in bounded time and before any pixel buffer exists,
// whether it is read as an image, a texture or a scene's environment map.
#include "io/PngFile.h"
#include "io/RadianceHdr.h"
#include "render/Environment.h"
#include "scene/SceneParser.h"
#include "support/TestSupport.h"
#include "texture/TextureImage.h"
#include "util/Error.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace vkrt::test {
namespace {

namespace fs = std::filesystem;

std::vector<uint8_t> bytesOf(const std::string& text) { return {text.begin(), text.end()}; }

std::vector<uint8_t> header(uint32_t width, uint32_t height)
{
    return bytesOf("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\nEXPOSURE=1.0\n\n-Y " + std::to_string(height) + " +X " +
                   std::to_string(width) + "\n");
}

/// The RGBE quadruple of pixel (x, y) of the test pattern: mantissas that vary, exponents 128 + 1 .. 128 + 4.
std::array<uint8_t, 4> patternPixel(uint32_t x, uint32_t y)
{
    return {uint8_t(128 + (x * 7 + y) % 128), uint8_t(200 - x % 50), uint8_t((x + 3 * y) % 256),
            uint8_t(129 + (x + y) % 4)};
}

/// RGBE to linear: mantissa / 256 times 2^(exponent - 128) (the format's definition).
float decodedChannel(const std::array<uint8_t, 4>& rgbe, int channel)
{
    return float(rgbe[size_t(channel)]) / 256.0f * std::pow(2.0f, float(rgbe[3]) - 128.0f);
}

std::vector<uint8_t> flatFile(uint32_t width, uint32_t height)
{
    std::vector<uint8_t> bytes = header(width, height);
    for (uint32_t y = 0; y < height; ++y)
        for (uint32_t x = 0; x < width; ++x)
            for (uint8_t b : patternPixel(x, y)) bytes.push_back(b);
    return bytes;
}

/// The same pattern run-length encoded: each channel as literal runs of up to
/// 128 bytes, except that a channel constant across the scanline is written as
/// runs of 127 copies (the exponent is, in the first scanline below).
std::vector<uint8_t> runLengthFile(uint32_t width, uint32_t height)
{
    std::vector<uint8_t> bytes = header(width, height);
    for (uint32_t y = 0; y < height; ++y) {
        bytes.insert(bytes.end(), {2, 2, uint8_t(width >> 8), uint8_t(width & 0xff)});
        for (int c = 0; c < 4; ++c) {
            bool constant = true;
            for (uint32_t x = 1; x < width; ++x) constant = constant && patternPixel(x, y)[c] == patternPixel(0, y)[c];
            for (uint32_t x = 0; x < width;) {
                const uint32_t length = std::min(width - x, constant ? 127u : 128u);
                if (constant) {
                    bytes.insert(bytes.end(), {uint8_t(128 + length), patternPixel(x, y)[c]});
                } else {
                    bytes.push_back(uint8_t(length));
                    for (uint32_t i = 0; i < length; ++i) bytes.push_back(patternPixel(x + i, y)[c]);
                }
                x += length;
            }
        }
    }
    return bytes;
}

void expectPattern(const RadianceHdrImage& image, uint32_t width, uint32_t height)
{
    ASSERT_EQ(image.extent.width, width);
    ASSERT_EQ(image.extent.height, height);
    for (uint32_t y = 0; y < height; ++y)
        for (uint32_t x = 0; x < width; ++x)
            for (int c = 0; c < 3; ++c)
                ASSERT_EQ(image.rgba[4 * (size_t(y) * width + x) + size_t(c)], decodedChannel(patternPixel(x, y), c))
                    << "pixel (" << x << ", " << y << ") channel " << c;
}

/// `printf '#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 64\n\x02\x02\x00\x40'`: an RLE
/// scanline of 64 pixels, then nothing (whose runs read as 0).
std::vector<uint8_t> sweepZeroRunFile()
{
    std::vector<uint8_t> bytes = bytesOf("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 64\n");
    bytes.insert(bytes.end(), {0x02, 0x02, 0x00, 0x40});
    return bytes;
}

std::string errorOf(const std::vector<uint8_t>& bytes, const std::string& name = "sky.hdr")
{
    try {
        decodeRadianceHdr(bytes, name);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

TEST(RadianceHdr, FlatAndRunLengthScanlinesDecodeToTheirRgbeValues)
{
    expectPattern(decodeRadianceHdr(flatFile(5, 3), "flat.hdr"), 5, 3);
    // Widths below 8 are always flat; 300 needs several runs per channel.
    expectPattern(decodeRadianceHdr(runLengthFile(300, 4), "rle.hdr"), 300, 4);
    // Top row first: the first scanline is row 0.
    const RadianceHdrImage image = decodeRadianceHdr(flatFile(2, 2), "rows.hdr");
    EXPECT_EQ(image.rgba[0], decodedChannel(patternPixel(0, 0), 0));
    EXPECT_EQ(image.rgba[8], decodedChannel(patternPixel(0, 1), 0));
    EXPECT_EQ(image.rgba[3], 1.0f) << "alpha";
}

TEST(RadianceHdr, ARunOfLengthZeroIsAnErrorNotAnEndlessLoop)
{
    // The sweep's 50-byte file: an RLE scanline whose first run count is 0.
    const std::vector<uint8_t> file = sweepZeroRunFile();
    ASSERT_EQ(file.size(), 50u);
    std::vector<uint8_t> bytes = file;
    bytes.resize(bytes.size() + 64, 0); // long enough for the header's claim, then zeros: runs of length 0
    const auto start = std::chrono::steady_clock::now();
    const std::string error = errorOf(bytes);
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(1));
    EXPECT_NE(error.find("sky.hdr: truncated or damaged Radiance HDR: scanline 0 has a run of length 0"),
              std::string::npos)
        << error;
    // As the sweep wrote it (50 bytes): too short for two scanlines of 64 pixels.
    EXPECT_NE(errorOf(file).find("truncated or damaged"), std::string::npos);
}

TEST(RadianceHdr, RunsPastTheScanlineAndShortScanlinesAreErrors)
{
    std::vector<uint8_t> overrun = runLengthFile(16, 1);
    // The first channel's literal run of 16 becomes a repeat of 127.
    overrun[header(16, 1).size() + 4] = 128 + 127;
    EXPECT_NE(errorOf(overrun).find("scanline 0 has a run of 127 past its end (16 pixels left in channel 0)"),
              std::string::npos)
        << errorOf(overrun);
    std::vector<uint8_t> widthMismatch = runLengthFile(16, 1);
    widthMismatch[header(16, 1).size() + 3] = 15;
    EXPECT_NE(errorOf(widthMismatch).find("declares 15 pixels, the header 16"), std::string::npos);
    // Cut inside the last scanline's runs: the header's minimum is met, the data is not.
    std::vector<uint8_t> cut = runLengthFile(300, 4);
    cut.resize(cut.size() - 10);
    EXPECT_NE(errorOf(cut).find("scanline 3 ends before its runs"), std::string::npos) << errorOf(cut);
}

TEST(RadianceHdr, HeadersAreCheckedAgainstTheFilesLengthBeforeAllocating)
{
    // 51 bytes declaring 8192 x 8192 (the sweep's: 3.9 GB before).
    std::vector<uint8_t> claim = header(8192, 8192);
    EXPECT_NE(errorOf(claim).find("the header declares 8192x8192 pixels, which take at least"), std::string::npos)
        << errorOf(claim);
    // A flat file cut to 300 bytes (black rows before).
    std::vector<uint8_t> flat = flatFile(64, 64);
    flat.resize(300);
    EXPECT_NE(errorOf(flat).find("truncated or damaged"), std::string::npos) << errorOf(flat);
    // Sizes beyond the image limits, orientations and formats vkrt does not read, broken headers.
    const std::vector<std::pair<std::string, std::string>> bad = {
        {"#?RADIANCE\n\n-Y 20000 +X 4\n", "at most 16384 pixels a side"},
        {"#?RADIANCE\n\n-Y 0 +X 4\n", "empty image"},
        {"#?RADIANCE\n\n+Y 4 +X 4\n", "unsupported Radiance HDR orientation '+Y 4 +X 4'"},
        {"#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n-Y 1 +X 1\n", "32-bit_rle_xyze"},
        {"#?RADIANCE\n\n-Y four +X 4\n", "has no size"},
        {"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n", "ends before its resolution line"},
        {"#?JUNK\n\n-Y 1 +X 1\n", "not #?RADIANCE or #?RGBE"},
        {"#?RADIANCE\n" + std::string(70000, 'x'), "no end of header within 65536 bytes"},
    };
    for (const auto& [text, message] : bad)
        EXPECT_NE(errorOf(bytesOf(text)).find(message), std::string::npos)
            << text.substr(0, 40) << " -> " << errorOf(bytesOf(text));
}

TEST(RadianceHdr, TexturesEnvironmentsAndImageReadersAllUseTheCheckedDecoder)
{
    const fs::path dir = freshTempDir("radiance-hdr");
    std::vector<uint8_t> zeroRun = sweepZeroRunFile();
    zeroRun.resize(zeroRun.size() + 64, 0);
    {
        std::ofstream(dir / "zero-run.hdr", std::ios::binary)
            .write(reinterpret_cast<const char*>(zeroRun.data()), std::streamsize(zeroRun.size()));
        const std::vector<uint8_t> good = runLengthFile(16, 8);
        std::ofstream(dir / "good.hdr", std::ios::binary)
            .write(reinterpret_cast<const char*>(good.data()), std::streamsize(good.size()));
    }
    auto expectNamed = [&](auto&& read, const std::string& what) {
        try {
            read();
            ADD_FAILURE() << what << ": accepted a run of length 0";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find("zero-run.hdr"), std::string::npos) << what << ": " << e.what();
            EXPECT_NE(std::string(e.what()).find("run of length 0"), std::string::npos) << what << ": " << e.what();
        }
    };
    expectNamed([&] { loadTextureImage(dir / "zero-run.hdr", true); }, "texture");
    expectNamed([&] { readRgbImage(dir / "zero-run.hdr"); }, "image");
    const std::string camera = "[camera]\neye = [0, 0, 5]\ntarget = [0, 0, 0]\nfov = 40\n";
    const Scene scene =
        parseSceneString(camera + "[background.environment]\nfile = \"zero-run.hdr\"\n", (dir / "scene.toml").string());
    ASSERT_TRUE(scene.background.environment.has_value());
    expectNamed([&] { loadEnvironmentMap(*scene.background.environment); }, "environment");
    // A good file decodes the same through each.
    const TextureImage texture = loadTextureImage(dir / "good.hdr", true);
    EXPECT_EQ(texture.pixels.width, 16u);
    EXPECT_EQ(texture.pixels.at(3, 5)[1], decodedChannel(patternPixel(3, 5), 1));
    const Image image = readRgbImage(dir / "good.hdr");
    EXPECT_EQ(image.rgb[3 * (5 * 16 + 3) + 1], decodedChannel(patternPixel(3, 5), 1));
}

} // namespace
} // namespace vkrt::test

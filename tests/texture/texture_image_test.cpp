// Decoding texture files (src/texture/TextureImage.h): sRGB and linear 8-bit,
// 16-bit PNG, channel expansion, EXR, and every bad input's message. All
// images are written by the tests.
#include "io/ExrFile.h"
#include "mesh/MeshLoader.h"
#include "texture/TextureImage.h"
#include "texture/TextureTestFiles.h"
#include "util/Error.h"

#include <stb/stb_image_write.h>

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>

namespace vkrt::test {
namespace {

namespace fs = std::filesystem;

/// The sRGB EOTF written out here, independently of the library's.
double srgbReference(double v) { return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4); }

/// The message of the InputError `load` throws (fails the test if none).
template <typename F>
std::string errorOf(F load)
{
    try {
        load();
    } catch (const InputError& error) {
        return error.what();
    }
    ADD_FAILURE() << "no InputError";
    return {};
}

TEST(TextureImage, EverySrgbCodeDecodesByTheExactFormula)
{
    std::vector<uint8_t> samples;
    for (int code = 0; code < 256; ++code)
        samples.insert(samples.end(), {uint8_t(code), uint8_t(code), uint8_t(code), uint8_t(255 - code)});
    const fs::path file = write8BitPng(textureTestDir() / "ramp.png", 256, 1, 4, samples);
    const TextureImage image = loadTextureImage(file, false);
    EXPECT_EQ(image.encoding, TexelEncoding::Srgb8);
    ASSERT_EQ(image.pixels.width, 256u);
    for (uint32_t code = 0; code < 256; ++code) {
        const float* texel = image.pixels.at(code, 0);
        for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(texel[c], float(srgbReference(code / 255.0))) << code;
        EXPECT_FLOAT_EQ(texel[3], float((255 - code) / 255.0)) << "alpha is linear, code " << code;
    }
    EXPECT_EQ(image.pixels.at(255, 0)[0], 1.0f);
    EXPECT_EQ(image.pixels.at(0, 0)[0], 0.0f);
}

TEST(TextureImage, LinearFlagKeepsEightBitCodes)
{
    const fs::path file = write8BitPng(textureTestDir() / "linear.png", 2, 1, 3, {0, 51, 128, 255, 7, 200});
    const TextureImage image = loadTextureImage(file, true);
    EXPECT_EQ(image.encoding, TexelEncoding::Unorm8);
    EXPECT_FLOAT_EQ(image.pixels.at(0, 0)[1], 51.0f / 255.0f);
    EXPECT_FLOAT_EQ(image.pixels.at(0, 0)[2], 128.0f / 255.0f);
    EXPECT_FLOAT_EQ(image.pixels.at(1, 0)[1], 7.0f / 255.0f);
    EXPECT_EQ(image.pixels.at(1, 0)[3], 1.0f);
}

TEST(TextureImage, SixteenBitPngKeepsItsPrecision)
{
    const std::vector<uint16_t> samples{0, 1, 1000, 32768, 65534, 65535}; // grey, 6 x 1
    const fs::path file = writePng(textureTestDir() / "deep.png", 6, 1, 16, 0, samples);
    const TextureImage srgb = loadTextureImage(file, false);
    const TextureImage linear = loadTextureImage(file, true);
    EXPECT_EQ(srgb.encoding, TexelEncoding::Half);
    EXPECT_EQ(linear.encoding, TexelEncoding::Half);
    for (uint32_t x = 0; x < 6; ++x) {
        const double value = samples[x] / 65535.0;
        EXPECT_FLOAT_EQ(srgb.pixels.at(x, 0)[1], float(srgbReference(value))) << x;
        EXPECT_FLOAT_EQ(linear.pixels.at(x, 0)[2], float(value)) << x;
        EXPECT_EQ(linear.pixels.at(x, 0)[3], 1.0f);
    }
    // Codes 65534 and 65535 stay apart: the data were not cut to 8 bits.
    EXPECT_LT(linear.pixels.at(4, 0)[0], linear.pixels.at(5, 0)[0]);
}

TEST(TextureImage, SixteenBitRgbaAlphaIsLinear)
{
    const fs::path file = writePng(textureTestDir() / "rgba16.png", 1, 1, 16, 6, {65535, 0, 32768, 16384});
    const TextureImage image = loadTextureImage(file, false);
    EXPECT_FLOAT_EQ(image.pixels.at(0, 0)[0], 1.0f);
    EXPECT_FLOAT_EQ(image.pixels.at(0, 0)[2], float(srgbReference(32768 / 65535.0)));
    EXPECT_FLOAT_EQ(image.pixels.at(0, 0)[3], float(16384 / 65535.0));
}

TEST(TextureImage, GreyAndAlphaExpandToRgba)
{
    const fs::path dir = textureTestDir();
    const TextureImage grey = loadTextureImage(write8BitPng(dir / "g.png", 2, 1, 1, {10, 250}), true);
    const TextureImage greyAlpha = loadTextureImage(write8BitPng(dir / "ga.png", 1, 1, 2, {40, 90}), true);
    const TextureImage rgb = loadTextureImage(write8BitPng(dir / "rgb.png", 1, 1, 3, {1, 2, 3}), true);
    const TextureImage rgba = loadTextureImage(write8BitPng(dir / "rgba.png", 1, 1, 4, {4, 5, 6, 7}), true);
    auto expectTexel = [](const TextureImage& image, uint32_t x, std::array<int, 4> codes) {
        for (int c = 0; c < 4; ++c) EXPECT_FLOAT_EQ(image.pixels.at(x, 0)[c], codes[c] / 255.0f) << "channel " << c;
    };
    expectTexel(grey, 0, {10, 10, 10, 255});
    expectTexel(grey, 1, {250, 250, 250, 255});
    expectTexel(greyAlpha, 0, {40, 40, 40, 90});
    expectTexel(rgb, 0, {1, 2, 3, 255});
    expectTexel(rgba, 0, {4, 5, 6, 7});
    // Rows stay top to bottom as in the file.
    const TextureImage rows = loadTextureImage(write8BitPng(dir / "rows.png", 1, 2, 1, {0, 255}), true);
    EXPECT_EQ(rows.pixels.at(0, 0)[0], 0.0f);
    EXPECT_EQ(rows.pixels.at(0, 1)[0], 1.0f);
}

TEST(TextureImage, JpegIsDecodedAsSrgb)
{
    const fs::path file = textureTestDir() / "flat.jpg";
    const std::vector<uint8_t> grey(8 * 8 * 3, 128);
    ASSERT_TRUE(stbi_write_jpg(file.c_str(), 8, 8, 3, grey.data(), 95));
    const TextureImage image = loadTextureImage(file, false);
    EXPECT_EQ(image.encoding, TexelEncoding::Srgb8);
    EXPECT_NEAR(image.pixels.at(3, 3)[0], srgbReference(128 / 255.0), 0.01); // JPEG is lossy
}

/// The bytes of an 8x8 JPEG stb_image_write makes (baseline: one scan, then the end-of-image marker).
std::string eightByEightJpeg()
{
    const fs::path file = textureTestDir() / "whole.jpg";
    std::vector<uint8_t> rgb(8 * 8 * 3);
    for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = uint8_t(i * 37);
    EXPECT_TRUE(stbi_write_jpg(file.c_str(), 8, 8, 3, rgb.data(), 95));
    std::ifstream in(file, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

// stb_image decodes a JPEG cut short as though the missing data were zeros:
// the sweep's 8x8 JPEG with its headers and no scan data became a texture
// without a word. Refused now, naming the file.
TEST(TextureImage, ATruncatedJpegIsRefusedNamingTheFile)
{
    const std::string whole = eightByEightJpeg();
    const size_t scan = whole.find("\xFF\xDA");
    ASSERT_NE(scan, std::string::npos);
    const size_t scanHeader =
        (static_cast<size_t>(static_cast<uint8_t>(whole[scan + 2])) << 8 | static_cast<uint8_t>(whole[scan + 3])) + 2;
    const std::vector<std::pair<std::string, std::string>> cuts = {
        {"no-scan.jpg", whole.substr(0, scan)},                              // the headers alone
        {"empty-scan.jpg", whole.substr(0, scan + scanHeader) + "\xFF\xD9"}, // a scan header, no data
        {"half-scan.jpg", whole.substr(0, (scan + scanHeader + whole.size()) / 2)},
        {"no-end.jpg", whole.substr(0, whole.size() - 2)}, // without its end-of-image marker
    };
    for (const auto& [name, bytes] : cuts) {
        const fs::path file = writeBytes(textureTestDir() / name, bytes);
        const std::string error = errorOf([&] { loadTextureImage(file, false); });
        EXPECT_EQ(error.rfind(file.string() + ": damaged JPEG image: ", 0), 0u) << error;
        const std::vector<uint8_t> data(bytes.begin(), bytes.end());
        EXPECT_EQ(errorOf([&] { readTextureHeader(data, name, false); }).rfind(name + ": damaged JPEG image", 0), 0u);
    }
    EXPECT_NE(errorOf([&] {
                  loadTextureImage(writeBytes(textureTestDir() / "n.jpg", cuts[0].second), false);
              }).find("no start-of-scan"),
              std::string::npos);
    // The whole file, and one with bytes after its end-of-image marker (allowed), decode.
    const fs::path good = writeBytes(textureTestDir() / "trailing.jpg", whole + "trailing bytes");
    EXPECT_EQ(loadTextureImage(good, false).pixels.width, 8u);
}

TEST(TextureImage, ExrRoundTripIsLinearAndExact)
{
    Image rgb(3, 2);
    for (size_t i = 0; i < rgb.rgb.size(); ++i) rgb.rgb[i] = float(i) * 0.37f - 1.0f + (i == 7 ? 1e4f : 0.0f);
    const fs::path file = textureTestDir() / "linear.exr";
    writeExr(file, rgb, {});
    for (bool linear : {false, true}) { // EXR is linear whatever the flag says
        const TextureImage image = loadTextureImage(file, linear);
        EXPECT_EQ(image.encoding, TexelEncoding::Half);
        ASSERT_EQ(image.pixels.width, 3u);
        ASSERT_EQ(image.pixels.height, 2u);
        for (uint32_t y = 0; y < 2; ++y) {
            for (uint32_t x = 0; x < 3; ++x) {
                for (int c = 0; c < 3; ++c) EXPECT_EQ(image.pixels.at(x, y)[c], rgb.at(x, y)[c]);
                EXPECT_EQ(image.pixels.at(x, y)[3], 1.0f);
            }
        }
    }
}

TEST(TextureImage, SrgbFunctionsAreInverse)
{
    for (int i = 0; i <= 1000; ++i) {
        const double v = i / 1000.0;
        EXPECT_NEAR(linearToSrgb(srgbToLinear(v)), v, 1e-12);
        EXPECT_DOUBLE_EQ(srgbToLinear(v), srgbReference(v));
    }
}

// ---------------------------------------------------------------------------
// Bad input: each a message naming the file and saying what is wrong.

TEST(TextureImageBad, MissingFile)
{
    const fs::path file = textureTestDir() / "nope.png";
    EXPECT_EQ(errorOf([&] { loadTextureImage(file, false); }), file.string() + ": texture file not found");
}

TEST(TextureImageBad, Directory)
{
    const fs::path dir = textureTestDir();
    EXPECT_EQ(errorOf([&] { loadTextureImage(dir, false); }), dir.string() + ": is a directory, not an image file");
}

TEST(TextureImageBad, EmptyFile)
{
    const fs::path file = writeBytes(textureTestDir() / "empty.png", "");
    EXPECT_EQ(errorOf([&] { loadTextureImage(file, false); }), file.string() + ": empty file, not an image");
}

TEST(TextureImageBad, NotAnImage)
{
    const fs::path file = writeBytes(textureTestDir() / "notes.png", "albedo = 0.5\n");
    const std::string message = errorOf([&] { loadTextureImage(file, false); });
    EXPECT_EQ(message.rfind(file.string() + ": not an image file (stb_image: ", 0), 0u) << message;
}

TEST(TextureImageBad, UnsupportedBitDepth)
{
    const fs::path file = writePng(textureTestDir() / "three.png", 4, 4, 3, 0, {});
    const std::string message = errorOf([&] { loadTextureImage(file, false); });
    EXPECT_EQ(message, file.string() + ": unsupported or damaged image (stb_image: 1/2/4/8/16-bit only)");
}

TEST(TextureImageBad, TooLarge)
{
    // A header is enough: the size is refused before any pixel is decoded.
    const fs::path file = writePng(textureTestDir() / "wide.png", 16385, 2, 1, 0, {});
    EXPECT_EQ(errorOf([&] { loadTextureImage(file, false); }),
              file.string() + ": unsupported image: 16385x2 pixels (textures may have at most 16384 pixels a side)");
}

TEST(TextureImageBad, ZeroPixels)
{
    const fs::path file = writePng(textureTestDir() / "zero.png", 0, 4, 8, 0, {});
    const std::string message = errorOf([&] { loadTextureImage(file, false); });
    EXPECT_EQ(message, file.string() + ": unsupported or damaged image (stb_image: 0-pixel image)");
}

TEST(TextureImageBad, TruncatedPixelData)
{
    const fs::path dir = textureTestDir();
    std::vector<uint8_t> noise(64 * 64 * 3);
    for (size_t i = 0; i < noise.size(); ++i) noise[i] = uint8_t(i * 2654435761u >> 13);
    const fs::path whole = write8BitPng(dir / "whole.png", 64, 64, 3, noise);
    const std::string bytes = [&] {
        std::ifstream in(whole, std::ios::binary);
        return std::string(std::istreambuf_iterator<char>(in), {});
    }();
    const fs::path file = writeBytes(dir / "cut.png", bytes.substr(0, bytes.size() / 2));
    const std::string message = errorOf([&] { loadTextureImage(file, false); });
    EXPECT_EQ(message.rfind(file.string() + ": cannot decode image (stb_image: ", 0), 0u) << message;
}

TEST(TextureImageBad, NonFiniteExrTexel)
{
    Image rgb(5, 4);
    rgb.at(3, 2)[1] = std::numeric_limits<float>::quiet_NaN();
    const fs::path file = textureTestDir() / "nan.exr";
    writeExr(file, rgb, {});
    EXPECT_EQ(errorOf([&] { loadTextureImage(file, false); }),
              file.string() + ": non-finite texel (NaN) at pixel x=3, y=2 (from the top left)");
    rgb.at(3, 2)[1] = 0.0f;
    rgb.at(0, 3)[2] = std::numeric_limits<float>::infinity();
    writeExr(file, rgb, {});
    EXPECT_EQ(errorOf([&] { loadTextureImage(file, false); }),
              file.string() + ": non-finite texel (infinity) at pixel x=0, y=3 (from the top left)");
}

TEST(TextureImageBad, DamagedExr)
{
    const fs::path file = writeBytes(textureTestDir() / "bad.exr", std::string("\x76\x2f\x31\x01", 4) + "garbage");
    const std::string message = errorOf([&] { loadTextureImage(file, false); });
    EXPECT_EQ(message.rfind(file.string() + ": not a readable EXR file", 0), 0u) << message;
}

// ---------------------------------------------------------------------------
// The uv convention of lib/texture.glsl: v up from the bottom (OBJ). glTF
// stores v down from the top; assimp's glTF importer stores 1 - v. Cube.gltf's
// raw TEXCOORD_0 v values are 0 (x18), 1 (x9), -1 (x9): flipped, 1, 0, 2.

TEST(TextureUv, GltfArrivesFlippedToTheObjConvention)
{
    const fs::path file = assetsDir() / "gltf" / "Cube" / "Cube.gltf";
    const MeshData mesh = loadMeshFile(file);
    ASSERT_EQ(mesh.uvs.size(), 36u);
    std::map<float, int> vCounts;
    for (const auto& uv : mesh.uvs) ++vCounts[uv.y + 0.0f]; // + 0 folds -0 into 0
    EXPECT_EQ(vCounts, (std::map<float, int>{{0.0f, 9}, {1.0f, 18}, {2.0f, 9}}));
}

} // namespace
} // namespace vkrt::test

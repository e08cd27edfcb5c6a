// Packing textures (src/texture/TextureAtlas.h): records, level offsets,
// encodings, de-duplication, located errors, the chunks of texels beyond one
// buffer and the device's limits.
#include "texture/MipPyramid.h"
#include "texture/TextureAtlas.h"
#include "texture/TextureTestFiles.h"

#include <Imath/half.h>

#include <chrono>

#include <gtest/gtest.h>

namespace vkrt::test {
namespace {

namespace fs = std::filesystem;

TextureImage solid(uint32_t width, uint32_t height, TexelEncoding encoding, float value = 0.5f)
{
    TextureImage image{RgbaImage(width, height), encoding};
    std::fill(image.pixels.rgba.begin(), image.pixels.rgba.end(), value);
    return image;
}

TEST(TextureAtlas, RecordsPointAtEveryLevel)
{
    TextureAtlas atlas;
    EXPECT_EQ(atlas.add(solid(5, 3, TexelEncoding::Srgb8), "a", TextureWrap::Clamp, TextureWrap::Mirror), 0u);
    EXPECT_EQ(atlas.add(solid(4, 4, TexelEncoding::Half), "b"), 1u);
    const TextureBuffers buffers = atlas.pack();
    ASSERT_EQ(buffers.records.size(), 2u);
    const gpu::TextureRecord& a = buffers.records[0];
    EXPECT_EQ(a.width, 5u);
    EXPECT_EQ(a.height, 3u);
    EXPECT_EQ(a.levels, 3u); // 5x3, 2x1, 1x1
    EXPECT_EQ(a.format, gpu::TEXTURE_FORMAT_RGBA8_SRGB);
    EXPECT_EQ(a.wrapU, gpu::TEXTURE_WRAP_CLAMP);
    EXPECT_EQ(a.wrapV, gpu::TEXTURE_WRAP_MIRROR);
    EXPECT_EQ(a.levelOffset[0], 0u);
    EXPECT_EQ(a.levelOffset[1], 15u);
    EXPECT_EQ(a.levelOffset[2], 17u);
    EXPECT_EQ(a.levelOffset[3], 0u);
    const gpu::TextureRecord& b = buffers.records[1];
    EXPECT_EQ(b.format, gpu::TEXTURE_FORMAT_RGBA16F);
    EXPECT_EQ(b.levels, 3u); // 4x4, 2x2, 1x1, two words a texel
    EXPECT_EQ(b.levelOffset[0], 18u);
    EXPECT_EQ(b.levelOffset[1], 18u + 32u);
    EXPECT_EQ(b.levelOffset[2], 18u + 40u);
    EXPECT_EQ(buffers.texels.size(), 18u + 42u);
    EXPECT_EQ(atlas.texelBytes(), 4u * 60u);
}

TEST(TextureAtlas, EightBitSrgbKeepsTheFileCodes)
{
    std::vector<uint8_t> samples;
    for (int code = 0; code < 256; ++code)
        for (int c = 0; c < 4; ++c) samples.push_back(uint8_t(code + 50 * c)); // wraps mod 256
    const fs::path file = write8BitPng(textureTestDir() / "codes.png", 256, 1, 4, samples);
    TextureAtlas atlas;
    atlas.add(TextureRequest{file});
    const TextureBuffers buffers = atlas.pack();
    for (uint32_t x = 0; x < 256; ++x) {
        const uint32_t word = buffers.texels[x];
        for (int c = 0; c < 4; ++c) EXPECT_EQ((word >> (8 * c)) & 0xffu, samples[x * 4 + c]) << x << " " << c;
    }
}

TEST(TextureAtlas, HalfFloatsPackAsPackHalf2x16)
{
    const float texel[4] = {1.0f, -2.5f, 1e6f, 0.333f};
    uint32_t words[2];
    encodeRgba16f(texel, words);
    EXPECT_EQ(words[0] & 0xffffu, 0x3c00u); // 1.0 in the low half, as packHalf2x16's x
    EXPECT_EQ(words[0] >> 16, 0xc100u);     // -2.5
    EXPECT_EQ(words[1] & 0xffffu, 0x7bffu); // clamped to 65504, not infinity
    Imath::half third;
    third.setBits(uint16_t(words[1] >> 16));
    EXPECT_NEAR(float(third), 0.333f, 0.333f / 1024);
}

TEST(TextureAtlas, LinearEightBitIsUnorm)
{
    const float texel[4] = {0.5f, 0.0f, 1.0f, 0.2f};
    EXPECT_EQ(encodeRgba8(texel, false), 128u | 0u << 8 | 255u << 16 | 51u << 24);
    // sRGB: 0.5 linear encodes to 188 (0.7354 * 255 = 187.5 rounds up), alpha stays linear.
    EXPECT_EQ(encodeRgba8(texel, true), 188u | 0u << 8 | 255u << 16 | 51u << 24);
}

TEST(TextureAtlas, SameFileIsLoadedOnce)
{
    const fs::path dir = textureTestDir();
    const fs::path file = write8BitPng(dir / "wood.png", 4, 2, 3, std::vector<uint8_t>(24, 77));
    fs::create_directories(dir / "sub");
    TextureAtlas atlas;
    const uint32_t first = atlas.add(TextureRequest{file});
    EXPECT_EQ(atlas.add(TextureRequest{dir / "sub" / ".." / "wood.png"}), first);
    const uint32_t clamped = atlas.add(TextureRequest{file, false, TextureWrap::Clamp, TextureWrap::Clamp});
    const uint32_t linear = atlas.add(TextureRequest{file, true});
    EXPECT_NE(clamped, first);
    EXPECT_NE(linear, first);
    EXPECT_EQ(atlas.imageCount(), 2u); // (file, sRGB) and (file, linear)
    EXPECT_EQ(atlas.recordCount(), 3u);
    const TextureBuffers buffers = atlas.pack();
    EXPECT_EQ(buffers.records[clamped].levelOffset[0], buffers.records[first].levelOffset[0]);
    EXPECT_NE(buffers.records[linear].levelOffset[0], buffers.records[first].levelOffset[0]);
    EXPECT_EQ(buffers.records[linear].format, gpu::TEXTURE_FORMAT_RGBA8_UNORM);
}

TEST(TextureAtlas, LoadErrorCarriesTheSceneLocation)
{
    const fs::path file = textureTestDir() / "missing.png";
    TextureAtlas atlas;
    try {
        atlas.add(TextureRequest{file}, SourceLocation{"scene.toml", 12, 20});
        FAIL() << "no error";
    } catch (const SceneError& error) {
        EXPECT_EQ(std::string(error.what()), "scene.toml:12:20: " + file.string() + ": texture file not found");
        EXPECT_EQ(error.where().line, 12);
    }
    EXPECT_THROW(atlas.add(TextureRequest{file}), InputError); // no location: the loader's own error
    EXPECT_EQ(atlas.imageCount(), 0u);
}

/// Three textures of 341, 2 x 2731 and 2 x 85 words (a word of padding
/// before the first half-float one, which starts at an even word).
TextureAtlas threeTextures()
{
    TextureAtlas atlas;
    atlas.add(solid(16, 16, TexelEncoding::Srgb8), "small.png");
    atlas.add(solid(64, 32, TexelEncoding::Half), "big.exr");
    atlas.add(solid(8, 8, TexelEncoding::Half), "tiny.exr");
    return atlas;
}

TEST(TextureChunks, TexelsThatFitOneBufferStayInOne)
{
    const TextureAtlas atlas = threeTextures();
    const uint64_t bytes = atlas.texelBytes();
    EXPECT_EQ(atlas.chunking({bytes, 1, bytes}), TextureChunking{}); // exactly at the limit fits
    const TextureBuffers buffers = atlas.pack(atlas.chunking({bytes, 1, bytes}));
    ASSERT_EQ(buffers.chunking.count, 1u);
    EXPECT_EQ(buffers.chunk(0).size(), buffers.texels.size());
    EXPECT_EQ(buffers.chunk(0).data(), buffers.texels.data());
}

// Beyond one buffer the words keep their one address space (the records are
// the same) and are cut into chunks of the largest power of two that fits.
TEST(TextureChunks, TexelsOverOneBufferAreSplitAtPowersOfTwo)
{
    const TextureAtlas atlas = threeTextures();
    const TextureBuffers whole = atlas.pack();
    const uint64_t words = whole.texels.size();
    ASSERT_EQ(words * 4, atlas.texelBytes());
    const TextureChunking chunks = atlas.chunking({words * 4 - 4, UINT32_MAX, UINT64_MAX});
    // 5974 words (one of them padding): chunks of 4096 words, the largest
    // power of two up to the 5973 that fit.
    ASSERT_EQ(words, 341u + 1u + 2u * 2731u + 2u * 85u);
    EXPECT_EQ(chunks.shift, 12u);
    EXPECT_EQ(chunks.count, 2u);
    const TextureChunking small = atlas.chunking({1000, UINT32_MAX, UINT64_MAX}); // 250 words: chunks of 128
    EXPECT_EQ(small.shift, 7u);
    EXPECT_EQ(small.count, (words + 127) / 128);
    const TextureBuffers split = atlas.pack(small);
    ASSERT_EQ(split.records.size(), whole.records.size());
    for (size_t r = 0; r < whole.records.size(); ++r)
        for (uint32_t level = 0; level < gpu::TEXTURE_MAX_LEVELS; ++level)
            EXPECT_EQ(split.records[r].levelOffset[level], whole.records[r].levelOffset[level]) << r << " " << level;
    size_t seen = 0;
    for (uint32_t c = 0; c < small.count; ++c) {
        const std::span<const uint32_t> chunk = split.chunk(c);
        EXPECT_EQ(chunk.size(), c + 1 < small.count ? 128u : words - 128u * (small.count - 1)) << c;
        for (size_t i = 0; i < chunk.size(); ++i) ASSERT_EQ(chunk[i], whole.texels[(size_t(c) << 7) + i]) << c;
        seen += chunk.size();
    }
    EXPECT_EQ(seen, words);
}

TEST(TextureChunks, HalfFloatTexelsNeverStraddleTwoChunks)
{
    TextureAtlas atlas;
    atlas.add(solid(7, 1, TexelEncoding::Srgb8), "odd.png"); // 7 + 3 + 1 = 11 words
    atlas.add(solid(3, 3, TexelEncoding::Half), "half.exr");
    const TextureBuffers buffers = atlas.pack();
    const gpu::TextureRecord& half = buffers.records[1];
    EXPECT_EQ(half.levelOffset[0], 12u) << "a half-float image starts at an even word";
    for (uint32_t level = 0; level < half.levels; ++level) EXPECT_EQ(half.levelOffset[level] % 2, 0u) << level;
    EXPECT_EQ(buffers.texels[11], 0u); // the padding
    // Chunks of two words (8 bytes, the smallest) hold whole texels.
    EXPECT_EQ(atlas.chunking({8, UINT32_MAX, UINT64_MAX}).shift, 1u);
    EXPECT_EQ(atlas.chunking({15, UINT32_MAX, UINT64_MAX}).shift, 1u);
}

// The arithmetic at real sizes, without the texels: lavapipe's 128 MiB
// buffers and the scene that one buffer refused (224 MiB of texels), and a
// discrete GPU's 4 GiB - 1, where chunks stop at kMaxChunkBytes.
TEST(TextureChunks, ChunkingAtDeviceSizes)
{
    const uint64_t lavapipe = uint64_t(128) << 20, discrete = UINT32_MAX;
    const uint64_t words = (uint64_t(224) << 20) / 4;
    EXPECT_EQ(textureChunkingFor(words, {lavapipe, 8, UINT64_MAX}), (TextureChunking{2, 25}));
    EXPECT_EQ(textureChunkingFor(words + 1, {lavapipe, 8, UINT64_MAX}), (TextureChunking{2, 25}));
    EXPECT_EQ(textureChunkingFor(uint64_t(3) << 25, {lavapipe, 8, UINT64_MAX}), (TextureChunking{3, 25}));
    EXPECT_EQ(textureChunkingFor(words, {discrete, 8, UINT64_MAX}), TextureChunking{});
    EXPECT_EQ(textureChunkingFor(uint64_t(1) << 31, {discrete, 8, UINT64_MAX}), (TextureChunking{8, 28}));
    // The largest scene the texel budget lets in: 64 Mi half-float texels with their mip levels.
    const uint64_t largest = 2 * (TextureAtlas::kMaxSceneTexels * 4 - 1) / 3;
    EXPECT_EQ(textureChunkingFor(largest, {lavapipe, 8, UINT64_MAX}), (TextureChunking{6, 25}));
}

// A scene over one buffer of lavapipe's (128 MiB), which pack refused before:
// three 2048 x 2048 half-float textures with their mip levels fill it but for
// two words, and a fourth, 16 x 16, starts there and straddles the chunks.
TEST(TextureChunks, SceneOverOneLavapipeBufferIsSplitNotRefused)
{
    TextureAtlas atlas;
    for (int i = 0; i < 3; ++i) atlas.add(solid(2048, 2048, TexelEncoding::Half, 0.25f * float(i + 1)), "big.exr");
    const uint64_t lavapipe = uint64_t(128) << 20;
    EXPECT_EQ(atlas.chunking({lavapipe, 8, UINT64_MAX}), TextureChunking{});
    atlas.add(solid(16, 16, TexelEncoding::Srgb8), "small.png");
    ASSERT_GT(atlas.texelBytes(), lavapipe);
    const TextureChunking chunks = atlas.chunking({lavapipe, 8, UINT64_MAX});
    EXPECT_EQ(chunks, (TextureChunking{2, 25}));
    const TextureBuffers buffers = atlas.pack(chunks);
    EXPECT_EQ(buffers.records[3].levelOffset[0], (1u << 25) - 2);
    EXPECT_EQ(buffers.chunk(0).size(), size_t(1) << 25);
    EXPECT_EQ(buffers.chunk(1).size(), 341u - 2u);
    const float grey[4] = {0.5f, 0.5f, 0.5f, 0.5f};
    EXPECT_EQ(buffers.chunk(0).back(), encodeRgba8(grey, true));
    EXPECT_EQ(buffers.chunk(1).front(), encodeRgba8(grey, true));
    EXPECT_EQ(buffers.chunk(0)[buffers.records[2].levelOffset[0]], 0x3a003a00u); // the third's half 0.75, twice
}

TEST(TextureChunks, MoreChunksThanTheKernelCanBindAreRefusedNamingTheLargest)
{
    const TextureAtlas atlas = threeTextures();
    const uint64_t bytes = atlas.texelBytes();
    EXPECT_NO_THROW(atlas.chunking({bytes - 4, 2, UINT64_MAX}));
    try {
        atlas.chunking({bytes - 4, 1, UINT64_MAX});
        FAIL() << "no error";
    } catch (const InputError& error) {
        const std::string message = error.what();
        EXPECT_NE(message.find("2 storage buffers of 0.02 MiB (maxStorageBufferRange), and the kernel can bind 1 "
                               "more (maxPerStageDescriptorStorageBuffers)"),
                  std::string::npos)
            << message;
        EXPECT_NE(message.find("the largest is big.exr (64x32, "), std::string::npos) << message;
    }
}

TEST(TextureChunks, TexelsBeyondTheDeviceMemoryAreRefusedNamingTheLargest)
{
    const TextureAtlas atlas = threeTextures();
    const uint64_t bytes = atlas.texelBytes();
    EXPECT_NO_THROW(atlas.chunking({UINT64_MAX, 1, bytes}));
    try {
        atlas.chunking({UINT64_MAX, 1, bytes - 1});
        FAIL() << "no error";
    } catch (const InputError& error) {
        const std::string message = error.what();
        EXPECT_NE(message.find("more than this device can hold: the device's 0.02 MiB of memory"), std::string::npos)
            << message;
        EXPECT_NE(message.find("the largest is big.exr (64x32, "), std::string::npos) << message;
    }
}

/// TextureAtlas::add's message for `file`, or "" when it takes it.
std::string addRefusal(TextureAtlas& atlas, const fs::path& file)
{
    try {
        atlas.add(TextureRequest{file});
        return "";
    } catch (const InputError& e) {
        return e.what();
    }
}

TEST(TextureBudget, TexelsBeyondTheSceneBudgetAreRefusedFromTheHeader)
{
    const fs::path dir = textureTestDir();
    TextureAtlas atlas(3 * 64 * 64); // three 64x64 textures
    for (int i = 0; i < 3; ++i)
        EXPECT_EQ(addRefusal(atlas, writePngBomb(dir / ("t" + std::to_string(i) + ".png"), 64)), "") << i;
    const fs::path fourth = writePngBomb(dir / "t3.png", 64);
    EXPECT_EQ(addRefusal(atlas, fourth), fourth.string() + ": a 64x64 texture brings the scene's textures to 16384 "
                                                           "texels, more than the 12288 vkrt loads for one scene; "
                                                           "use smaller textures");
    EXPECT_EQ(atlas.imageCount(), 3u);
    // The same file again is the same image: no new texels.
    EXPECT_EQ(addRefusal(atlas, dir / "t0.png"), "");
    // Images made in memory count too.
    EXPECT_THROW(atlas.add(solid(2, 2, TexelEncoding::Half), "made"), InputError);
}

TEST(TextureBudget, PngBombIsRefusedBeforeDecoding)
{
    const fs::path dir = textureTestDir();
    const fs::path bomb = writePngBomb(dir / "bomb.png", 16384); // 1.7 MB; decoded 4 GiB as float RGBA
    TextureAtlas atlas;
    const auto start = std::chrono::steady_clock::now();
    EXPECT_EQ(addRefusal(atlas, bomb), bomb.string() + ": a 16384x16384 texture brings the scene's textures to " +
                                           "268435456 texels, more than the 67108864 (one 8192x8192) vkrt loads "
                                           "for one scene; use smaller textures");
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 2.0);
    EXPECT_EQ(atlas.texelBytes(), 0u);
}

TEST(TextureBudget, ExrTextureClaimingHugeSizeIsRefusedFromTheHeader)
{
    const fs::path dir = textureTestDir();
    const fs::path huge = writeExrDeclaring(dir / "huge.exr", 16384, 16384);
    const fs::path big = writeExrDeclaring(dir / "big.exr", 8192, 8192);
    TextureAtlas atlas;
    EXPECT_NE(addRefusal(atlas, huge).find(huge.string() + ": the header declares 16384x16384 pixels"),
              std::string::npos)
        << addRefusal(atlas, huge);
    EXPECT_NE(addRefusal(atlas, big).find(big.string() + ": the header declares 8192x8192 pixels of 3 channels"),
              std::string::npos)
        << addRefusal(atlas, big);
}

TEST(TextureBudget, LargeButFineTextureStillLoads)
{
    const fs::path dir = textureTestDir();
    TextureAtlas atlas;
    const uint32_t record = atlas.add(TextureRequest{writePngBomb(dir / "large.png", 4096)});
    EXPECT_EQ(atlas.imageCount(), 1u);
    EXPECT_EQ(atlas.meanOf(record)[0], 0.0);
    EXPECT_EQ(atlas.meanOf(record)[3], 1.0);
    // 8-bit sRGB: one word a texel, and a third more for the mip levels.
    EXPECT_EQ(atlas.texelBytes(), 4 * (uint64_t(4096) * 4096 * 4 - 1) / 3);
}

// The host's lookup (emitters' power, render/EmissionPower.h) follows
// lib/texture.glsl's conventions: texel (x, y) centred at uv ((x + 0.5) / w,
// 1 - (y + 0.5) / h), bilinear between centres, wrap modes on texel indices.
TEST(TextureAtlas, HostLookupIsBilinearBetweenTexelCentresWithTheWrapModes)
{
    TextureImage image{RgbaImage(4, 2), TexelEncoding::Half}; // half floats: exact for these values
    for (uint32_t y = 0; y < 2; ++y)
        for (uint32_t x = 0; x < 4; ++x)
            for (int c = 0; c < 4; ++c) image.pixels.at(x, y)[c] = float(x + 4 * y) + 0.25f * float(c);
    TextureAtlas atlas;
    const uint32_t repeat = atlas.add(image, "grid");
    const uint32_t clamp = atlas.add(image, "grid", TextureWrap::Clamp, TextureWrap::Clamp);
    auto value = [](double x, double y) { return x + 4.0 * y; }; // channel 0 at image position (x, y)
    // Texel centres: row 0 is the top (v near 1).
    EXPECT_DOUBLE_EQ(atlas.sampleLevel(repeat, 2.5 / 4.0, 1.0 - 0.5 / 2.0, 0)[0], value(2, 0));
    EXPECT_DOUBLE_EQ(atlas.sampleLevel(repeat, 1.5 / 4.0, 1.0 - 1.5 / 2.0, 0)[3], value(1, 1) + 0.75);
    // Between centres: the weighted mean of the four.
    const double four = (value(1, 0) + value(2, 0) + value(1, 1) + value(2, 1)) / 4;
    EXPECT_NEAR(atlas.sampleLevel(repeat, 2.0 / 4.0, 0.5, 0)[0], four, 1e-12);
    // At u = 0 repeat mixes the last column with the first; clamp keeps the first.
    EXPECT_NEAR(atlas.sampleLevel(repeat, 0.0, 1.0 - 0.5 / 2.0, 0)[0], (value(3, 0) + value(0, 0)) / 2, 1e-12);
    EXPECT_NEAR(atlas.sampleLevel(clamp, 0.0, 1.0 - 0.5 / 2.0, 0)[0], value(0, 0), 1e-12);
    // Level 1 (2 x 1) is the box average of level 0.
    EXPECT_NEAR(atlas.sampleLevel(clamp, 0.25, 0.5, 1)[0], (value(0, 0) + value(1, 0) + value(0, 1) + value(1, 1)) / 4,
                1e-12);
    EXPECT_EQ(atlas.widthOf(clamp), 4u);
    EXPECT_EQ(atlas.heightOf(clamp), 2u);
    EXPECT_EQ(atlas.levelsOf(clamp), 3u);
}

// TextureRecord::filters: glTF's filters as bits, vkrt's trilinear default 0.
TEST(TextureFilters, RecordBitsSayWhatIsNearest)
{
    using Mip = TextureFilter::Mip;
    EXPECT_EQ(TextureFilter{}.bits(), 0u);
    EXPECT_EQ((TextureFilter{true, false, Mip::Linear}.bits()), gpu::TEXTURE_FILTER_MAG_NEAREST);
    EXPECT_EQ((TextureFilter{false, true, Mip::Linear}.bits()), gpu::TEXTURE_FILTER_MIN_NEAREST);
    EXPECT_EQ((TextureFilter{false, false, Mip::Nearest}.bits()), gpu::TEXTURE_FILTER_MIP_NEAREST);
    EXPECT_EQ((TextureFilter{true, true, Mip::None}.bits()),
              gpu::TEXTURE_FILTER_MAG_NEAREST | gpu::TEXTURE_FILTER_MIN_NEAREST | gpu::TEXTURE_FILTER_MIP_NONE);
}

// One image under two filters: two records over the same texels; the same
// filter again: the same record.
TEST(TextureFilters, OtherFiltersGetTheirOwnRecordOverTheSameTexels)
{
    const fs::path file = write8BitPng(textureTestDir() / "grey.png", 4, 4, 3, std::vector<uint8_t>(48, 100));
    TextureAtlas atlas;
    const TextureFilter nearest{true, true, TextureFilter::Mip::Nearest};
    const uint32_t plain = atlas.add(TextureRequest{file});
    const uint32_t sharp = atlas.add(TextureRequest{file, false, TextureWrap::Repeat, TextureWrap::Repeat, nearest});
    EXPECT_NE(sharp, plain);
    EXPECT_EQ(atlas.add(TextureRequest{file, false, TextureWrap::Repeat, TextureWrap::Repeat, nearest}), sharp);
    EXPECT_EQ(atlas.imageCount(), 1u);
    const TextureBuffers buffers = atlas.pack();
    EXPECT_EQ(buffers.records[plain].filters, 0u);
    EXPECT_EQ(buffers.records[sharp].filters, nearest.bits());
    EXPECT_EQ(buffers.records[sharp].levelOffset[0], buffers.records[plain].levelOffset[0]);
}

// The host's level lookup follows the magnification filter, as
// lib/texture.glsl's sampleTextureLevel does: nearest, the texel whose square holds the point.
TEST(TextureFilters, HostLookupWithNearestMagnificationTakesTheTexelUnderThePoint)
{
    TextureImage image{RgbaImage(4, 2), TexelEncoding::Half};
    for (uint32_t y = 0; y < 2; ++y)
        for (uint32_t x = 0; x < 4; ++x)
            for (int c = 0; c < 4; ++c) image.pixels.at(x, y)[c] = float(x + 4 * y);
    TextureAtlas atlas;
    const uint32_t nearest = atlas.add(image, "grid", TextureWrap::Repeat, TextureWrap::Repeat, {true, false});
    EXPECT_EQ(atlas.sampleLevel(nearest, 0.49, 0.9, 0)[0], 1.0);  // x = 1.96, row 0
    EXPECT_EQ(atlas.sampleLevel(nearest, 0.51, 0.9, 0)[0], 2.0);  // x = 2.04
    EXPECT_EQ(atlas.sampleLevel(nearest, 0.51, 0.1, 0)[0], 6.0);  // row 1
    EXPECT_EQ(atlas.sampleLevel(nearest, -0.01, 0.9, 0)[0], 3.0); // repeat: the last column
}

} // namespace
} // namespace vkrt::test

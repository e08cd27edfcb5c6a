// The texture cache (texture/TextureCache.h) and the atlas's deferred,
// parallel decoding (TextureAtlas::settle): an image read back from the cache
// packs to exactly the words it was decoded to; a damaged entry is a miss that
// decodes again; many images decoded in parallel land in the order they were
// added; a file that fails to decode still fails at its scene key.
#include "TextureTestFiles.h"
#include "texture/TextureAtlas.h"
#include "util/Error.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <random>

namespace fs = std::filesystem;

namespace vkrt::test {
namespace {

/// Points the texture cache at `dir` ("off": none) for its lifetime, then back.
class TextureCacheDir {
public:
    explicit TextureCacheDir(const std::string& dir)
    {
        if (const char* old = std::getenv("VKRT_TEXTURE_CACHE_DIR")) m_previous = old;
        setenv("VKRT_TEXTURE_CACHE_DIR", dir.c_str(), 1);
    }
    ~TextureCacheDir()
    {
        if (m_previous) setenv("VKRT_TEXTURE_CACHE_DIR", m_previous->c_str(), 1);
        else unsetenv("VKRT_TEXTURE_CACHE_DIR");
    }
    TextureCacheDir(const TextureCacheDir&) = delete;
    TextureCacheDir& operator=(const TextureCacheDir&) = delete;

private:
    std::optional<std::string> m_previous;
};

/// A noisy RGBA PNG (every texel different, so a wrong level or order shows).
fs::path noisyPng(const fs::path& dir, const std::string& name, uint32_t side, unsigned seed)
{
    std::mt19937 random(seed);
    std::vector<uint8_t> samples(size_t(side) * side * 4);
    for (uint8_t& sample : samples) sample = uint8_t(random());
    return write8BitPng(dir / name, side, side, 4, samples);
}

TextureBuffers packAll(const std::vector<fs::path>& files, TextureLoadStats* stats = nullptr)
{
    TextureAtlas atlas;
    for (size_t i = 0; i < files.size(); ++i) atlas.add(TextureRequest{files[i], i % 2 == 1});
    if (stats) *stats = atlas.loadStats();
    return atlas.pack();
}

TEST(TextureCache, AnImageFromTheCachePacksToTheWordsItWasDecodedTo)
{
    const fs::path dir = textureTestDir();
    const std::vector<fs::path> files{noisyPng(dir, "a.png", 64, 1), noisyPng(dir, "b.png", 33, 2)};
    TextureBuffers uncached;
    {
        TextureCacheDir off("off");
        uncached = packAll(files);
    }
    TextureCacheDir cache((dir / "cache").string());
    TextureLoadStats first, second;
    const TextureBuffers decoded = packAll(files, &first);
    const TextureBuffers cached = packAll(files, &second);
    EXPECT_EQ(first.decoded, 2u);
    EXPECT_EQ(first.fromCache, 0u);
    EXPECT_EQ(second.decoded, 0u);
    EXPECT_EQ(second.fromCache, 2u);
    EXPECT_EQ(decoded.texels, uncached.texels);
    EXPECT_EQ(cached.texels, uncached.texels);
    ASSERT_EQ(cached.records.size(), uncached.records.size());
    for (size_t i = 0; i < cached.records.size(); ++i) {
        EXPECT_EQ(cached.records[i].levels, uncached.records[i].levels);
        EXPECT_EQ(cached.records[i].format, uncached.records[i].format);
        EXPECT_EQ(cached.records[i].levelOffset[1], uncached.records[i].levelOffset[1]);
    }
    // The same file read as linear data is another entry: sRGB and linear words differ.
    EXPECT_NE(TextureCache::keyOf(std::vector<uint8_t>{1, 2, 3}, true),
              TextureCache::keyOf(std::vector<uint8_t>{1, 2, 3}, false));
}

TEST(TextureCache, ADamagedEntryIsAMissThatDecodesAgain)
{
    const fs::path dir = textureTestDir();
    const std::vector<fs::path> files{noisyPng(dir, "a.png", 40, 3)};
    TextureCacheDir cache((dir / "cache").string());
    const TextureBuffers decoded = packAll(files);
    int damaged = 0;
    for (const auto& entry : fs::directory_iterator(dir / "cache")) {
        fs::resize_file(entry.path(), fs::file_size(entry.path()) / 2);
        ++damaged;
    }
    ASSERT_EQ(damaged, 1);
    TextureLoadStats again;
    EXPECT_EQ(packAll(files, &again).texels, decoded.texels);
    EXPECT_EQ(again.decoded, 1u);
    EXPECT_EQ(again.fromCache, 0u);
}

TEST(TextureCache, ImagesDecodedInParallelLandInTheOrderTheyWereAdded)
{
    const fs::path dir = textureTestDir();
    std::vector<fs::path> files;
    for (unsigned i = 0; i < 9; ++i) files.push_back(noisyPng(dir, "t" + std::to_string(i) + ".png", 16 + 7 * i, i));
    TextureCacheDir off("off");
    const TextureBuffers all = packAll(files);
    // One image at a time, in the same order, gives the same buffer.
    TextureAtlas serial;
    for (size_t i = 0; i < files.size(); ++i) {
        serial.add(TextureRequest{files[i], i % 2 == 1});
        serial.settle();
    }
    EXPECT_EQ(serial.pack().texels, all.texels);
}

TEST(TextureCache, AFileThatFailsToDecodeFailsAtItsSceneKey)
{
    const fs::path dir = textureTestDir();
    // A PNG whose header is whole but whose image data is cut off.
    std::ifstream in(noisyPng(dir, "whole.png", 64, 4), std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const fs::path cut = writeBytes(dir / "cut.png", bytes.substr(0, bytes.size() / 2));
    TextureCacheDir off("off");
    TextureAtlas atlas;
    atlas.add(TextureRequest{cut, false}, SourceLocation{"scene.toml", 7, 11});
    try {
        atlas.settle();
        FAIL() << "a cut-off PNG decoded";
    } catch (const SceneError& error) {
        EXPECT_EQ(std::string(error.what()).rfind("scene.toml:7:11: ", 0), 0u) << error.what();
        EXPECT_NE(std::string(error.what()).find("cut.png"), std::string::npos) << error.what();
    }
}

// The cache was trimmed to its size limit after every store, and each trim
// lists the whole folder: 1,000 new textures beside 20,000 cached entries
// took 10.9 s (5,000 past 30 s), the folder listed 1,000 times. Trimmed once
// per batch now: the time is linear in the images, whatever the cache holds.
TEST(TextureCache, ManyNewImagesBesideAFullCacheAreStoredInTimeLinearInTheImages)
{
    const fs::path folder = textureTestDir(), dir = folder / "cache";
    fs::create_directories(dir);
    for (int i = 0; i < 40000; ++i) std::ofstream(dir / ("old" + std::to_string(i) + ".vtex")) << "entry";
    const TextureCacheDir cache(dir.string());
    std::vector<fs::path> files;
    for (unsigned i = 0; i < 2000; ++i) files.push_back(noisyPng(folder, "tiny" + std::to_string(i) + ".png", 2, i));
    TextureLoadStats stats;
    const auto start = std::chrono::steady_clock::now();
    packAll(files, &stats);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_EQ(stats.decoded, 2000u);
    // Linear, this is about a second (two with the sanitizers); a trim per store lists 80 million entries.
    EXPECT_LT(seconds, 20.0);
    size_t entries = 0;
    for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir)) ++entries;
    EXPECT_EQ(entries, 42000u) << "every new image is stored, nothing evicted under the size limit";
}

} // namespace
} // namespace vkrt::test

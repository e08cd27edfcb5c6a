#pragma once
// Decoded, mip-mapped and encoded textures on disk, keyed by the content of
// the image file (as the SPIR-V cache is keyed by the shader sources): a
// scene opened again skips decoding its PNG and JPEG files and building
// their mip chains, which was most of a textured glTF model's warm start
// (docs/performance.md, "Round four"). A damaged or foreign entry is a miss.
#include "texture/TextureImage.h"

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace vkrt {

/// An image as the kernels read it (TextureAtlas): everything but its place in the texel buffer.
struct EncodedTexture {
    uint32_t width = 0, height = 0, levels = 0, format = 0;
    std::vector<uint64_t> levelWords; ///< each level's first word
    std::vector<uint32_t> words;      ///< every level, encoded
    std::array<double, 4> mean{};     ///< level 0's mean linear RGBA
};

/// Builds the mip chain of `image` and encodes every level in its format (TextureAtlas.cpp).
EncodedTexture encodeTexture(TextureImage image);

class TextureCache {
public:
    /// An empty directory: no cache (every load misses, nothing is stored).
    explicit TextureCache(std::filesystem::path directory);
    /// $VKRT_TEXTURE_CACHE_DIR ("off": none), else a "textures" folder in
    /// $VKRT_CACHE_DIR, else $XDG_CACHE_HOME/vkrt/textures, else ~/.cache/vkrt/textures.
    static std::filesystem::path defaultDirectory();
    /// At most this many bytes stay in the folder: storing evicts the least recently used.
    static constexpr uint64_t kMaxBytes = uint64_t(2) << 30;

    /// The key of an image file's bytes read as `linear` (or sRGB) data, by this build of vkrt.
    static std::string keyOf(std::span<const uint8_t> bytes, bool linear);
    std::optional<EncodedTexture> load(const std::string& key) const;
    /// Best effort: a cache that cannot be written is skipped, never an error.
    /// Call evictBeyondLimit() once after a batch of stores.
    void store(const std::string& key, const EncodedTexture& texture) const;
    /// Removes the least recently used entries beyond kMaxBytes. It lists the
    /// whole folder, so it runs once per batch: once per store, a scene of
    /// 5,000 new textures listed it 5,000 times (past 30 s).
    void evictBeyondLimit() const;
    const std::filesystem::path& directory() const { return m_directory; }

private:
    std::filesystem::path m_directory;
    std::filesystem::path pathFor(const std::string& key) const;
};

} // namespace vkrt

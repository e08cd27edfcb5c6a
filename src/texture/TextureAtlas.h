#pragma once
// Every texture of a scene, all mip levels, packed into one address space of
// 32-bit words plus a table of gpu::TextureRecord (shared/TextureTypes.h) that
// lib/texture.glsl reads. The words are one storage buffer when they fit the
// device's maxStorageBufferRange, else chunks of 2^k words, one buffer each
// (TextureChunking): a few buffers however many textures, so the texture
// count never meets a descriptor limit.
#include "shared/TextureTypes.h"
#include "texture/TextureCache.h"
#include "texture/TextureImage.h"
#include "util/Error.h"

#include <array>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace vkrt {

enum class TextureWrap : uint32_t {
    Repeat = gpu::TEXTURE_WRAP_REPEAT,
    Clamp = gpu::TEXTURE_WRAP_CLAMP,
    Mirror = gpu::TEXTURE_WRAP_MIRROR,
};

/// How lookups filter a texture (glTF's sampler magFilter and minFilter;
/// gpu::TextureRecord::filters). The default is vkrt's own: bilinear when
/// magnified, trilinear when minified (glTF's LINEAR, LINEAR_MIPMAP_LINEAR).
struct TextureFilter {
    enum class Mip : uint8_t {
        Linear,  ///< two levels blended
        Nearest, ///< the nearest level
        None,    ///< level 0 alone
    };
    bool magNearest = false; ///< magnified: the nearest texel, not bilinear
    bool minNearest = false; ///< minified: the nearest texel within a level, not bilinear
    Mip mip = Mip::Linear;   ///< minified: which levels

    /// The gpu::TEXTURE_FILTER_* bits.
    uint32_t bits() const;
    bool operator==(const TextureFilter&) const = default;
};

/// A texture as a scene names it.
struct TextureRequest {
    std::filesystem::path file; ///< already resolved against the scene file's folder
    bool linear = false;        ///< 8/16-bit data that is not sRGB (roughness, normal maps)
    TextureWrap wrapU = TextureWrap::Repeat;
    TextureWrap wrapV = TextureWrap::Repeat;
    TextureFilter filter;
};

/// How the texel words are split into storage buffers. Word w lives in
/// chunk w >> shift at index w & (2^shift - 1) (lib/texture_bindings.glsl).
struct TextureChunking {
    uint32_t count = 1; ///< buffers; 1: every word in one buffer, whatever its size (shift unused)
    uint32_t shift = 0; ///< with several: log2 of the words each holds (the last may hold fewer)

    bool operator==(const TextureChunking&) const = default;
};

/// What the device allows the texel words.
struct TextureStorageLimits {
    /// Bytes of one buffer: maxStorageBufferRange and maxMemoryAllocationSize
    /// (tests ask for less, to split small scenes).
    uint64_t maxBufferBytes = UINT64_MAX;
    /// Buffers the kernel can bind for texels (the per-stage storage-buffer
    /// descriptors its other bindings leave).
    uint32_t maxBuffers = UINT32_MAX;
    /// Memory there is for them at all (the largest device-local heap).
    uint64_t memoryBytes = UINT64_MAX;
};

/// The chunks for `words` texel words: one buffer when they fit
/// maxBufferBytes, else the largest even power of two words that fits
/// maxBufferBytes and TextureAtlas::kMaxChunkBytes. The count may exceed
/// limits.maxBuffers (TextureAtlas::chunking refuses that).
TextureChunking textureChunkingFor(uint64_t words, const TextureStorageLimits& limits);

/// What the kernels bind: BINDING_TEXTURE_TEXELS (the words, in chunking.count
/// buffers) and BINDING_TEXTURE_RECORDS.
struct TextureBuffers {
    std::vector<uint32_t> texels; ///< every word, in one address space (TextureRecord::levelOffset)
    std::vector<gpu::TextureRecord> records;
    TextureChunking chunking;

    /// The words of buffer `chunk` (< chunking.count).
    std::span<const uint32_t> chunk(uint32_t chunk) const;
};

/// How a scene's images were loaded (vkrt info's start-up split).
struct TextureLoadStats {
    double seconds = 0.0;   ///< wall time decoding or reading the cache (in parallel)
    uint32_t decoded = 0;   ///< images decoded from their files
    uint32_t fromCache = 0; ///< images read decoded from the texture cache
};

class TextureAtlas {
public:
    /// Level-0 texels all of a scene's textures may have together (one
    /// 8192x8192, or sixteen 2048x2048): checked from each file's header
    /// before it is decoded, since decoding costs about 32 bytes of CPU memory
    /// a texel (float RGBA and its mip chain) and the atlas keeps 5.3 (8-bit)
    /// or 10.7 (half) bytes a texel on the GPU. At most 683 MiB of GPU storage.
    static constexpr uint64_t kMaxSceneTexels = uint64_t(64) << 20;
    /// The largest chunk of several (1 GiB): a shift of at most 28, and
    /// buffers of a size every driver allocates. A scene's texels (683 MiB at
    /// most) need more than one chunk only on a device whose buffers are smaller.
    static constexpr uint64_t kMaxChunkBytes = uint64_t(1) << 30;

    /// `maxTexels`: the budget (tests use a small one).
    explicit TextureAtlas(uint64_t maxTexels = kMaxSceneTexels) : m_maxTexels(maxTexels) {}

    /// Loads the file (once per (file, linear) pair) and returns the index of
    /// its record (one per distinct pair, wrap modes and filter: records of
    /// one image share its texels). Load errors are
    /// InputErrors naming the file; given a location (the scene's `texture`
    /// key), a SceneError starting "file:line:column: ".
    uint32_t add(const TextureRequest& request, const SourceLocation& where = {});

    /// An image file's bytes already in memory (embedded in a .glb, a data:
    /// URI): its header checked against the budget before it is decoded.
    uint32_t addEncoded(const std::shared_ptr<const std::vector<uint8_t>>& bytes, const std::string& name, bool linear,
                        TextureWrap wrapU = TextureWrap::Repeat, TextureWrap wrapV = TextureWrap::Repeat,
                        const TextureFilter& filter = {});

    /// An image made in memory (procedural textures, tests); `name` is used in messages.
    uint32_t add(const TextureImage& image, const std::string& name, TextureWrap wrapU = TextureWrap::Repeat,
                 TextureWrap wrapV = TextureWrap::Repeat, const TextureFilter& filter = {});

    size_t recordCount() const { return m_records.size(); }
    /// Distinct images loaded (each with its mip chain).
    size_t imageCount() const { return m_images.size(); }
    /// Bytes of texel storage so far.
    uint64_t texelBytes() const
    {
        settle();
        return m_words * 4;
    }
    /// Decodes the images added so far (in parallel, through the texture
    /// cache) and places them in the texel buffer; every accessor below does
    /// it first. A file that fails to decode throws here, as add would have.
    void settle() const;
    /// What loading the images took: decoding, or reading them from the cache.
    const TextureLoadStats& loadStats() const;
    /// The mean linear RGBA of a record's image (level 0), as Mitsuba's
    /// Texture::mean() gives for a bitmap: what a plastic's sampling weight uses.
    std::array<double, 4> meanOf(uint32_t record) const;
    /// The name (file) of a record's image, for messages.
    const std::string& nameOf(uint32_t record) const;
    /// A record's level-0 size and its mip level count.
    uint32_t widthOf(uint32_t record) const;
    uint32_t heightOf(uint32_t record) const;
    uint32_t levelsOf(uint32_t record) const;
    /// The linear RGBA that lib/texture.glsl's sampleTextureLevel returns for
    /// the record at (u, v) in mip level `level` (< levelsOf): the stored
    /// (encoded) texels decoded, the record's wrap modes, bilinear weights
    /// (the nearest texel with a nearest magnification filter); in double.
    /// For host integrals of a texture (emitters' power).
    std::array<double, 4> sampleLevel(uint32_t record, double u, double v, uint32_t level) const;

    /// How the texels will be split (textureChunkingFor). Throws InputError,
    /// naming the largest texture, when they need more buffers or memory
    /// than `limits` allow.
    TextureChunking chunking(const TextureStorageLimits& limits) const;
    /// The buffers to upload, split as `chunking` (from chunking()) says.
    TextureBuffers pack(const TextureChunking& chunking = {}) const;
    /// The records alone (what pack returns in TextureBuffers::records).
    std::vector<gpu::TextureRecord> records() const;

private:
    struct StoredImage {
        std::string name;
        uint32_t width = 0, height = 0; ///< from the file's header, before it is decoded
        uint64_t firstWord = 0;         ///< in the packed buffer (once settled)
        EncodedTexture encoded;         ///< levels, format, words (levelWords relative to firstWord), mean
    };
    /// A file's bytes waiting for settle() to decode them into m_images[image].
    struct PendingImage {
        size_t image = 0;
        std::shared_ptr<const std::vector<uint8_t>> bytes;
        bool linear = false;
        SourceLocation where; ///< the scene's `texture` key, for errors (may be empty)
    };
    uint32_t addImage(TextureImage image, const std::string& name);
    /// Counts a texture of `header`'s size against the budget, or refuses it naming `name`.
    void reserveTexels(const TextureHeader& header, const std::string& name);
    /// Header check and budget now; decoding and storing at settle().
    uint32_t addDecoded(std::shared_ptr<const std::vector<uint8_t>> bytes, const std::string& name, bool linear,
                        const SourceLocation& where = {});
    /// A decode failure of a pending image, as a SceneError at `where` when there is one.
    [[noreturn]] static void rethrowAt(const std::exception_ptr& error, const SourceLocation& where);
    /// What makes a record: its image and how lookups read it.
    struct RecordKey {
        uint32_t image = 0;
        TextureWrap wrapU = TextureWrap::Repeat, wrapV = TextureWrap::Repeat;
        TextureFilter filter;
        bool operator==(const RecordKey&) const = default;
    };
    uint32_t addRecord(const RecordKey& key);
    /// Texel (x, y) of a level of width `width` starting at word `levelWord`, decoded to linear RGBA.
    std::array<double, 4> fetch(const StoredImage& image, uint64_t levelWord, uint32_t width, uint32_t x,
                                uint32_t y) const;

    mutable std::vector<StoredImage> m_images;
    mutable std::vector<PendingImage> m_pending;
    mutable size_t m_placed = 0; ///< images [0, m_placed) have their firstWord
    mutable TextureLoadStats m_load;
    std::vector<RecordKey> m_records;
    std::map<std::pair<std::string, bool>, uint32_t> m_imageByFile; ///< (canonical path, linear)
    /// Embedded images by (their bytes' address, linear): a file's image named
    /// by many slots shares one set of bytes (FileTexture::embedded), and is
    /// decoded and counted against the budget once. The weak pointer tells a
    /// freed address that was reused from the same bytes.
    std::map<std::pair<const void*, bool>, std::pair<std::weak_ptr<const std::vector<uint8_t>>, uint32_t>>
        m_imageByBytes;
    mutable uint64_t m_words = 0;
    uint64_t m_maxTexels = kMaxSceneTexels;
    uint64_t m_texels = 0; ///< level 0, of every image added
};

/// Texel encodings (exposed for tests): RGBA8 words (unpackUnorm4x8 order)
/// and half-float pairs (packHalf2x16 order). Linear values to sRGB 8-bit round
/// to nearest, so an 8-bit sRGB level 0 keeps its file's codes exactly;
/// half floats clamp to +-65504 (no infinity from a bright EXR).
uint32_t encodeRgba8(const float* linearRgba, bool srgb);
void encodeRgba16f(const float* linearRgba, uint32_t words[2]);

} // namespace vkrt

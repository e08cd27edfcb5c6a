#include "texture/TextureAtlas.h"

#include "texture/MipPyramid.h"
#include "texture/TextureCache.h"
#include "util/Error.h"

#include <Imath/half.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <exception>
#include <sstream>
#include <thread>

namespace vkrt {

namespace fs = std::filesystem;

uint32_t encodeRgba8(const float* linearRgba, bool srgb)
{
    uint32_t word = 0;
    for (int c = 0; c < 4; ++c) {
        double value = std::clamp(double(linearRgba[c]), 0.0, 1.0);
        if (srgb && c < 3) value = linearToSrgb(value);
        word |= uint32_t(std::lround(value * 255.0)) << (8 * c);
    }
    return word;
}

void encodeRgba16f(const float* linearRgba, uint32_t words[2])
{
    auto bits = [](float value) { return uint32_t(Imath::half(std::clamp(value, -65504.0f, 65504.0f)).bits()); };
    words[0] = bits(linearRgba[0]) | bits(linearRgba[1]) << 16;
    words[1] = bits(linearRgba[2]) | bits(linearRgba[3]) << 16;
}

namespace {

uint32_t formatOf(TexelEncoding encoding)
{
    switch (encoding) {
    case TexelEncoding::Srgb8: return gpu::TEXTURE_FORMAT_RGBA8_SRGB;
    case TexelEncoding::Unorm8: return gpu::TEXTURE_FORMAT_RGBA8_UNORM;
    case TexelEncoding::Half: return gpu::TEXTURE_FORMAT_RGBA16F;
    }
    throw InternalError("unknown texel encoding");
}

void appendLevel(const RgbaImage& level, uint32_t format, std::vector<uint32_t>& words)
{
    for (size_t i = 0; i < level.texelCount(); ++i) {
        const float* texel = &level.rgba[i * 4];
        if (format == gpu::TEXTURE_FORMAT_RGBA16F) {
            uint32_t pair[2];
            encodeRgba16f(texel, pair);
            words.insert(words.end(), pair, pair + 2);
        } else {
            words.push_back(encodeRgba8(texel, format == gpu::TEXTURE_FORMAT_RGBA8_SRGB));
        }
    }
}

} // namespace

EncodedTexture encodeTexture(TextureImage image)
{
    EncodedTexture encoded;
    encoded.width = image.pixels.width;
    encoded.height = image.pixels.height;
    encoded.format = formatOf(image.encoding);
    for (size_t i = 0; i < image.pixels.texelCount(); ++i)
        for (int c = 0; c < 4; ++c) encoded.mean[c] += image.pixels.rgba[i * 4 + c];
    for (double& m : encoded.mean) m /= double(image.pixels.texelCount());
    // The pyramid takes level 0 over: no second copy of the largest level.
    for (const RgbaImage& level : buildMipPyramid(std::move(image.pixels))) {
        encoded.levelWords.push_back(encoded.words.size());
        appendLevel(level, encoded.format, encoded.words);
    }
    encoded.levels = uint32_t(encoded.levelWords.size());
    VKRT_CHECK(encoded.levels <= gpu::TEXTURE_MAX_LEVELS);
    return encoded;
}

namespace {

std::string mebibytes(uint64_t bytes)
{
    std::ostringstream text;
    text.precision(bytes < (10u << 20) ? 2 : 0);
    text << std::fixed << double(bytes) / double(1u << 20) << " MiB";
    return text.str();
}

std::string fileKey(const fs::path& file)
{
    std::error_code error;
    const fs::path canonical = fs::weakly_canonical(file, error);
    return (error ? file : canonical).string();
}

} // namespace

void TextureAtlas::reserveTexels(const TextureHeader& header, const std::string& name)
{
    if (m_texels + header.texels() > m_maxTexels)
        throw InputError(name + ": a " + std::to_string(header.width) + "x" + std::to_string(header.height) +
                         " texture brings the scene's textures to " + std::to_string(m_texels + header.texels()) +
                         " texels, more than the " + std::to_string(m_maxTexels) +
                         (m_maxTexels == kMaxSceneTexels ? " (one 8192x8192)" : "") +
                         " vkrt loads for one scene; use smaller textures");
    m_texels += header.texels();
}

uint32_t TextureAtlas::addDecoded(std::shared_ptr<const std::vector<uint8_t>> bytes, const std::string& name,
                                  bool linear, const SourceLocation& where)
{
    const TextureHeader header = readTextureHeader(*bytes, name, linear);
    reserveTexels(header, name);
    // Decoded later, with the scene's other images, in parallel (settle).
    StoredImage stored;
    stored.name = name;
    stored.width = header.width;
    stored.height = header.height;
    m_images.push_back(std::move(stored));
    m_pending.push_back({m_images.size() - 1, std::move(bytes), linear, where});
    return uint32_t(m_images.size() - 1);
}

uint32_t TextureAtlas::addImage(TextureImage image, const std::string& name)
{
    StoredImage stored;
    stored.name = name;
    stored.encoded = encodeTexture(std::move(image));
    stored.width = stored.encoded.width;
    stored.height = stored.encoded.height;
    m_images.push_back(std::move(stored));
    return uint32_t(m_images.size() - 1);
}

namespace {

/// One pending image's outcome: its encoding, or why it could not be decoded.
struct DecodeOutcome {
    EncodedTexture encoded;
    std::exception_ptr error;
    bool fromCache = false;
};

DecodeOutcome decodeThroughCache(const TextureCache& cache, std::span<const uint8_t> bytes, const std::string& name,
                                 bool linear, uint32_t width, uint32_t height)
{
    DecodeOutcome outcome;
    try {
        const std::string key = TextureCache::keyOf(bytes, linear);
        if (std::optional<EncodedTexture> cached = cache.load(key);
            cached && cached->width == width && cached->height == height) {
            outcome.encoded = std::move(*cached);
            outcome.fromCache = true;
            return outcome;
        }
        outcome.encoded = encodeTexture(decodeTextureImage(bytes, name, linear));
        cache.store(key, outcome.encoded);
    } catch (...) {
        outcome.error = std::current_exception();
    }
    return outcome;
}

} // namespace

void TextureAtlas::settle() const
{
    if (!m_pending.empty()) {
        const auto start = std::chrono::steady_clock::now();
        const TextureCache cache(TextureCache::defaultDirectory());
        std::vector<DecodeOutcome> outcomes(m_pending.size());
        // A few workers, not one thread per image: each holds a decoded
        // level 0 in floats (64 MiB for a 2048x2048 image) while it works.
        std::atomic<size_t> next{0};
        auto work = [&] {
            for (size_t i; (i = next++) < m_pending.size();) {
                const PendingImage& job = m_pending[i];
                const StoredImage& image = m_images[job.image];
                outcomes[i] = decodeThroughCache(cache, *job.bytes, image.name, job.linear, image.width, image.height);
            }
        };
        const size_t workers = std::min<size_t>(m_pending.size(), std::max(1u, std::thread::hardware_concurrency()));
        std::vector<std::thread> threads;
        for (size_t w = 1; w < workers; ++w) threads.emplace_back(work);
        work();
        for (std::thread& thread : threads) thread.join();
        if (std::any_of(outcomes.begin(), outcomes.end(), [](const DecodeOutcome& o) { return !o.fromCache; }))
            cache.evictBeyondLimit();
        std::vector<PendingImage> pending = std::move(m_pending);
        m_pending.clear();
        m_load.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        for (size_t i = 0; i < pending.size(); ++i) {
            if (outcomes[i].error) rethrowAt(outcomes[i].error, pending[i].where);
            m_images[pending[i].image].encoded = std::move(outcomes[i].encoded);
            ++(outcomes[i].fromCache ? m_load.fromCache : m_load.decoded);
        }
    }
    // Places in the packed buffer, in the order the images were added.
    for (; m_placed < m_images.size(); ++m_placed) {
        StoredImage& image = m_images[m_placed];
        VKRT_CHECK(image.encoded.levels >= 1 && image.encoded.levels <= gpu::TEXTURE_MAX_LEVELS);
        // Half-float images start at an even word, so that no two-word texel
        // straddles two chunks (each holds an even number of words).
        if (image.encoded.format == gpu::TEXTURE_FORMAT_RGBA16F) m_words += m_words % 2;
        image.firstWord = m_words;
        m_words += image.encoded.words.size();
    }
}

void TextureAtlas::rethrowAt(const std::exception_ptr& error, const SourceLocation& where)
{
    try {
        std::rethrow_exception(error);
    } catch (const SceneError&) {
        throw;
    } catch (const InputError& input) {
        if (where.file.empty()) throw;
        throw SceneError(where, input.what());
    }
}

const TextureLoadStats& TextureAtlas::loadStats() const
{
    settle();
    return m_load;
}

std::array<double, 4> TextureAtlas::meanOf(uint32_t record) const
{
    VKRT_CHECK(record < m_records.size());
    settle();
    return m_images[m_records[record].image].encoded.mean;
}

const std::string& TextureAtlas::nameOf(uint32_t record) const
{
    VKRT_CHECK(record < m_records.size());
    return m_images[m_records[record].image].name;
}

uint32_t TextureAtlas::widthOf(uint32_t record) const
{
    VKRT_CHECK(record < m_records.size());
    return m_images[m_records[record].image].width;
}

uint32_t TextureAtlas::heightOf(uint32_t record) const
{
    VKRT_CHECK(record < m_records.size());
    return m_images[m_records[record].image].height;
}

uint32_t TextureAtlas::levelsOf(uint32_t record) const
{
    VKRT_CHECK(record < m_records.size());
    settle();
    return m_images[m_records[record].image].encoded.levels;
}

namespace {

/// lib/texture.glsl's wrapTextureCoordinate: whole periods removed.
double wrapCoordinate(double s, TextureWrap wrap)
{
    if (wrap == TextureWrap::Repeat) return s - std::floor(s);
    if (wrap == TextureWrap::Mirror) return s - 2.0 * std::floor(0.5 * s);
    return std::clamp(s, -1.0, 2.0);
}

/// lib/texture.glsl's wrapTexelIndex.
uint32_t wrapIndex(int64_t i, int64_t n, TextureWrap wrap)
{
    if (wrap == TextureWrap::Mirror) {
        const int64_t j = ((i % (2 * n)) + 2 * n) % (2 * n);
        i = j < n ? j : 2 * n - 1 - j;
    } else if (wrap == TextureWrap::Repeat) {
        i = ((i % n) + n) % n;
    }
    return uint32_t(std::clamp<int64_t>(i, 0, n - 1));
}

} // namespace

std::array<double, 4> TextureAtlas::fetch(const StoredImage& image, uint64_t levelWord, uint32_t width, uint32_t x,
                                          uint32_t y) const
{
    const uint64_t index = uint64_t(y) * width + x;
    std::array<double, 4> texel{};
    if (image.encoded.format == gpu::TEXTURE_FORMAT_RGBA16F) {
        const uint32_t* words = &image.encoded.words[levelWord + 2 * index];
        for (int c = 0; c < 4; ++c) {
            Imath::half h;
            h.setBits(uint16_t(words[c / 2] >> (16 * (c % 2))));
            texel[c] = double(float(h));
        }
        return texel;
    }
    // unpackUnorm4x8 rounds code / 255 to float before the EOTF; one table per encoding.
    static const auto tables = [] {
        std::array<std::array<double, 256>, 2> t{}; // linear, sRGB
        for (uint32_t code = 0; code < 256; ++code) {
            t[0][code] = double(float(code) / 255.0f);
            t[1][code] = srgbToLinear(t[0][code]);
        }
        return t;
    }();
    const uint32_t word = image.encoded.words[levelWord + index];
    const bool srgb = image.encoded.format == gpu::TEXTURE_FORMAT_RGBA8_SRGB;
    for (int c = 0; c < 4; ++c) texel[c] = tables[srgb && c < 3 ? 1 : 0][(word >> (8 * c)) & 0xffu];
    return texel;
}

std::array<double, 4> TextureAtlas::sampleLevel(uint32_t record, double u, double v, uint32_t level) const
{
    VKRT_CHECK(record < m_records.size());
    settle();
    const auto& [imageIndex, wrapU, wrapV, filter] = m_records[record];
    const StoredImage& image = m_images[imageIndex];
    VKRT_CHECK(level < image.encoded.levels);
    const int64_t w = mipSize(image.width, level), h = mipSize(image.height, level);
    const uint64_t at = image.encoded.levelWords[level];
    if (filter.magNearest) {
        // Texel i spans [i, i + 1) of the continuous coordinates.
        const auto i = int64_t(std::floor(wrapCoordinate(u, wrapU) * double(w)));
        const auto j = int64_t(std::floor(wrapCoordinate(1.0 - v, wrapV) * double(h)));
        return fetch(image, at, uint32_t(w), wrapIndex(i, w, wrapU), wrapIndex(j, h, wrapV));
    }
    // Continuous texel coordinates, texel centres at integers; y down from the top row.
    const double s = wrapCoordinate(u, wrapU) * double(w) - 0.5;
    const double t = wrapCoordinate(1.0 - v, wrapV) * double(h) - 0.5;
    const double bs = std::floor(s), bt = std::floor(t);
    const double fs = s - bs, ft = t - bt;
    const auto i0 = int64_t(bs), j0 = int64_t(bt);
    const uint32_t x0 = wrapIndex(i0, w, wrapU), x1 = wrapIndex(i0 + 1, w, wrapU);
    const uint32_t y0 = wrapIndex(j0, h, wrapV), y1 = wrapIndex(j0 + 1, h, wrapV);
    const auto a = fetch(image, at, uint32_t(w), x0, y0), b = fetch(image, at, uint32_t(w), x1, y0);
    const auto c = fetch(image, at, uint32_t(w), x0, y1), d = fetch(image, at, uint32_t(w), x1, y1);
    std::array<double, 4> result{};
    for (int k = 0; k < 4; ++k) {
        const double top = a[k] + (b[k] - a[k]) * fs, bottom = c[k] + (d[k] - c[k]) * fs;
        result[k] = top + (bottom - top) * ft;
    }
    return result;
}

uint32_t TextureFilter::bits() const
{
    return (magNearest ? gpu::TEXTURE_FILTER_MAG_NEAREST : 0u) | (minNearest ? gpu::TEXTURE_FILTER_MIN_NEAREST : 0u) |
           (mip == Mip::Nearest ? gpu::TEXTURE_FILTER_MIP_NEAREST : 0u) |
           (mip == Mip::None ? gpu::TEXTURE_FILTER_MIP_NONE : 0u);
}

uint32_t TextureAtlas::addRecord(const RecordKey& key)
{
    const auto found = std::find(m_records.begin(), m_records.end(), key);
    if (found != m_records.end()) return uint32_t(found - m_records.begin());
    m_records.push_back(key);
    return uint32_t(m_records.size() - 1);
}

uint32_t TextureAtlas::add(const TextureRequest& request, const SourceLocation& where)
{
    const auto key = std::make_pair(fileKey(request.file), request.linear);
    auto found = m_imageByFile.find(key);
    if (found == m_imageByFile.end()) {
        uint32_t image = 0;
        try {
            image = addDecoded(std::make_shared<const std::vector<uint8_t>>(readTextureFile(request.file)),
                               request.file.string(), request.linear, where);
        } catch (const SceneError&) {
            throw;
        } catch (const InputError& error) {
            if (where.file.empty()) throw;
            throw SceneError(where, error.what());
        }
        found = m_imageByFile.emplace(key, image).first;
    }
    return addRecord({found->second, request.wrapU, request.wrapV, request.filter});
}

uint32_t TextureAtlas::addEncoded(const std::shared_ptr<const std::vector<uint8_t>>& bytes, const std::string& name,
                                  bool linear, TextureWrap wrapU, TextureWrap wrapV, const TextureFilter& filter)
{
    VKRT_CHECK(bytes != nullptr);
    auto& [kept, image] = m_imageByBytes[{bytes.get(), linear}];
    if (kept.lock() != bytes) {
        image = addDecoded(bytes, name, linear);
        kept = bytes;
    }
    return addRecord({image, wrapU, wrapV, filter});
}

uint32_t TextureAtlas::add(const TextureImage& image, const std::string& name, TextureWrap wrapU, TextureWrap wrapV,
                           const TextureFilter& filter)
{
    VKRT_CHECK(image.pixels.width >= 1 && image.pixels.width <= gpu::TEXTURE_MAX_SIZE);
    VKRT_CHECK(image.pixels.height >= 1 && image.pixels.height <= gpu::TEXTURE_MAX_SIZE);
    reserveTexels({image.pixels.width, image.pixels.height, image.encoding}, name);
    return addRecord({addImage(image, name), wrapU, wrapV, filter});
}

TextureChunking textureChunkingFor(uint64_t words, const TextureStorageLimits& limits)
{
    // One buffer whenever it fits: the kernels of such scenes stay as they were.
    if (words <= limits.maxBufferBytes / 4) return {};
    const uint64_t chunkWords = std::min(limits.maxBufferBytes, TextureAtlas::kMaxChunkBytes) / 4;
    VKRT_CHECK(chunkWords >= 2); // a half-float texel's two words fit one chunk
    const auto shift = uint32_t(std::bit_width(chunkWords) - 1);
    return {uint32_t((words + (uint64_t(1) << shift) - 1) >> shift), shift};
}

std::span<const uint32_t> TextureBuffers::chunk(uint32_t index) const
{
    VKRT_CHECK(index < chunking.count);
    if (chunking.count == 1) return texels;
    const size_t first = size_t(index) << chunking.shift;
    VKRT_CHECK(first < texels.size());
    return std::span(texels).subspan(first, std::min(size_t(1) << chunking.shift, texels.size() - first));
}

TextureChunking TextureAtlas::chunking(const TextureStorageLimits& limits) const
{
    settle();
    const TextureChunking chunks = textureChunkingFor(m_words, limits);
    if (chunks.count <= limits.maxBuffers && texelBytes() <= limits.memoryBytes) return chunks;
    const auto largest = std::max_element(m_images.begin(), m_images.end(), [](const auto& a, const auto& b) {
        return a.encoded.words.size() < b.encoded.words.size();
    });
    const std::string room = chunks.count > limits.maxBuffers
                                 ? std::to_string(chunks.count) + " storage buffers of " +
                                       mebibytes(uint64_t(4) << chunks.shift) +
                                       " (maxStorageBufferRange), and the kernel can bind " +
                                       std::to_string(limits.maxBuffers) + " more (maxPerStageDescriptorStorageBuffers)"
                                 : "the device's " + mebibytes(limits.memoryBytes) + " of memory";
    throw InputError("textures need " + mebibytes(texelBytes()) + " of GPU storage (all mip levels), more than " +
                     "this device can hold: " + room + "; the largest is " + largest->name + " (" +
                     std::to_string(largest->width) + "x" + std::to_string(largest->height) + ", " +
                     mebibytes(largest->encoded.words.size() * 4) + ")");
}

std::vector<gpu::TextureRecord> TextureAtlas::records() const
{
    settle();
    std::vector<gpu::TextureRecord> records;
    for (const auto& [imageIndex, wrapU, wrapV, filter] : m_records) {
        const StoredImage& image = m_images[imageIndex];
        gpu::TextureRecord record{image.width,     image.height,    image.encoded.levels, image.encoded.format,
                                  uint32_t(wrapU), uint32_t(wrapV), filter.bits(),        {}};
        for (uint32_t level = 0; level < image.encoded.levels; ++level)
            record.levelOffset[level] = uint32_t(image.firstWord + image.encoded.levelWords[level]);
        records.push_back(record);
    }
    return records;
}

TextureBuffers TextureAtlas::pack(const TextureChunking& chunking) const
{
    // Word addresses are 32-bit (TextureRecord::levelOffset). A level-0
    // texel takes at most 5 words: 2 (half floats), as many again for its
    // mip chain (a 1-texel-high image's levels halve one side only), and one
    // of padding before its image. So the scene's texel budget keeps them
    // below 2^32; the check stands for an atlas made with a larger budget.
    static_assert(5 * TextureAtlas::kMaxSceneTexels < (uint64_t(1) << 32));
    settle();
    VKRT_CHECK(m_words <= uint64_t(UINT32_MAX));
    VKRT_CHECK(chunking.count == 1 || ((m_words - 1) >> chunking.shift) + 1 == chunking.count);
    TextureBuffers buffers;
    buffers.texels.reserve(m_words);
    for (const StoredImage& image : m_images) {
        buffers.texels.resize(image.firstWord, 0u); // the padding before a half-float image
        buffers.texels.insert(buffers.texels.end(), image.encoded.words.begin(), image.encoded.words.end());
    }
    buffers.records = records();
    buffers.chunking = chunking;
    return buffers;
}

} // namespace vkrt

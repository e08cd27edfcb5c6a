#include "texture/TextureCache.h"

#include "GitCommit.h"
#include "shared/TextureTypes.h"
#include "util/Hash.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string_view>
#include <unistd.h>

namespace vkrt {

namespace fs = std::filesystem;

namespace {

constexpr char kMagic[8] = {'v', 'k', 'r', 't', 't', 'e', 'x', '1'};

struct FileHeader {
    char magic[8];
    uint32_t width, height, levels, format;
    double mean[4];
    uint64_t wordCount;
};

} // namespace

TextureCache::TextureCache(fs::path directory) : m_directory(std::move(directory)) {}

fs::path TextureCache::defaultDirectory()
{
    if (const char* dir = std::getenv("VKRT_TEXTURE_CACHE_DIR"); dir && *dir)
        return std::string_view(dir) == "off" ? fs::path() : fs::path(dir);
    if (const char* dir = std::getenv("VKRT_CACHE_DIR"); dir && *dir) return fs::path(dir) / "textures";
    if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return fs::path(xdg) / "vkrt" / "textures";
    if (const char* home = std::getenv("HOME"); home && *home) return fs::path(home) / ".cache" / "vkrt" / "textures";
    return fs::temp_directory_path() / "vkrt-cache" / "textures";
}

std::string TextureCache::keyOf(std::span<const uint8_t> bytes, bool linear)
{
    // The version and commit stand for the decoders, the mip filter and the
    // encoders: another build never reads this one's entries (outside a git
    // clone the commit is "unknown" and the version still differs).
    Fnv1a64 hash;
    hash.addField("vkrt-texture-cache-v1").addField(VKRT_VERSION).addField(VKRT_GIT_COMMIT);
    hash.addField(linear ? "linear" : "srgb");
    hash.addField(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
    return toHex(hash.value()) + "-" + std::to_string(bytes.size());
}

fs::path TextureCache::pathFor(const std::string& key) const { return m_directory / (key + ".vtex"); }

std::optional<EncodedTexture> TextureCache::load(const std::string& key) const
{
    if (m_directory.empty()) return std::nullopt;
    std::ifstream in(pathFor(key), std::ios::binary);
    FileHeader header{};
    if (!in.read(reinterpret_cast<char*>(&header), sizeof header)) return std::nullopt;
    if (std::memcmp(header.magic, kMagic, sizeof kMagic) != 0 || header.levels == 0 ||
        header.levels > gpu::TEXTURE_MAX_LEVELS || header.wordCount > (uint64_t(1) << 32))
        return std::nullopt;
    EncodedTexture texture;
    texture.width = header.width;
    texture.height = header.height;
    texture.levels = header.levels;
    texture.format = header.format;
    std::copy(std::begin(header.mean), std::end(header.mean), texture.mean.begin());
    texture.levelWords.resize(header.levels);
    texture.words.resize(header.wordCount);
    if (!in.read(reinterpret_cast<char*>(texture.levelWords.data()), std::streamsize(header.levels * 8)) ||
        !in.read(reinterpret_cast<char*>(texture.words.data()), std::streamsize(header.wordCount * 4)) ||
        in.peek() != std::char_traits<char>::eof())
        return std::nullopt;
    for (uint64_t first : texture.levelWords)
        if (first >= header.wordCount) return std::nullopt;
    std::error_code error;
    fs::last_write_time(pathFor(key), fs::file_time_type::clock::now(), error); // recently used
    return texture;
}

void TextureCache::store(const std::string& key, const EncodedTexture& texture) const
{
    if (m_directory.empty()) return;
    std::error_code error;
    fs::create_directories(m_directory, error);
    FileHeader header{};
    std::memcpy(header.magic, kMagic, sizeof kMagic);
    header.width = texture.width;
    header.height = texture.height;
    header.levels = texture.levels;
    header.format = texture.format;
    std::copy(texture.mean.begin(), texture.mean.end(), std::begin(header.mean));
    header.wordCount = texture.words.size();
    // Written under a name of its own, then renamed: a reader never sees half a file.
    const fs::path temporary = pathFor(key).string() + ".tmp" + std::to_string(getpid());
    {
        std::ofstream out(temporary, std::ios::binary);
        out.write(reinterpret_cast<const char*>(&header), sizeof header);
        out.write(reinterpret_cast<const char*>(texture.levelWords.data()),
                  std::streamsize(texture.levelWords.size() * 8));
        out.write(reinterpret_cast<const char*>(texture.words.data()), std::streamsize(texture.words.size() * 4));
        if (!out.flush()) {
            fs::remove(temporary, error);
            return;
        }
    }
    fs::rename(temporary, pathFor(key), error);
    if (error) fs::remove(temporary, error);
}

void TextureCache::evictBeyondLimit() const
{
    std::error_code error;
    std::vector<std::pair<fs::file_time_type, fs::path>> entries;
    uint64_t total = 0;
    for (const auto& entry : fs::directory_iterator(m_directory, error)) {
        if (entry.path().extension() != ".vtex") continue;
        total += entry.file_size(error);
        entries.emplace_back(entry.last_write_time(error), entry.path());
    }
    if (total <= kMaxBytes) return;
    std::sort(entries.begin(), entries.end());
    for (const auto& [time, path] : entries) {
        if (total <= kMaxBytes) break;
        const uint64_t size = fs::file_size(path, error);
        if (fs::remove(path, error)) total -= std::min(total, size);
    }
}

} // namespace vkrt

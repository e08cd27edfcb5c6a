#pragma once
// Image files decoded for use as textures: linear RGBA float, rows top to
// bottom as stored in the file. PNG, JPEG (and stb_image's other formats) are
// sRGB unless the caller says the data is linear; EXR is always linear.
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace vkrt {

/// How a texture's texels are stored on the GPU (shared/TextureTypes.h's TEXTURE_FORMAT_*).
enum class TexelEncoding : uint8_t {
    Srgb8,  ///< 8-bit source decoded as sRGB: stored as 8-bit sRGB, decoded texel by texel in the shader
    Unorm8, ///< 8-bit source marked linear
    Half,   ///< 16-bit PNG, EXR, HDR: half floats
};

/// Linear RGBA floats (straight, not premultiplied alpha), rows top to bottom.
struct RgbaImage {
    uint32_t width = 0;
    uint32_t height = 0;
    std::vector<float> rgba; ///< width * height * 4 floats

    RgbaImage() = default;
    RgbaImage(uint32_t w, uint32_t h) : width(w), height(h), rgba(size_t(w) * h * 4, 0.0f) {}

    size_t texelCount() const { return size_t(width) * height; }
    float* at(uint32_t x, uint32_t y) { return &rgba[(size_t(y) * width + x) * 4]; }
    const float* at(uint32_t x, uint32_t y) const { return &rgba[(size_t(y) * width + x) * 4]; }
};

/// A decoded texture file and the encoding its source precision asks for.
struct TextureImage {
    RgbaImage pixels;
    TexelEncoding encoding = TexelEncoding::Half;
};

/// Reads `file` by its content (not its extension). `linear`: the 8- or 16-bit
/// data is already linear (normal, roughness maps), no sRGB decoding. Throws
/// InputError whose message starts with the file name when it is missing, a
/// directory, empty, not an image, of a depth or size vkrt does not take
/// (zero, or more than TEXTURE_MAX_SIZE texels a side) or an EXR with a
/// non-finite texel. Callers that know where the file was named catch it and
/// rethrow with the location (TextureAtlas::add does).
TextureImage loadTextureImage(const std::filesystem::path& file, bool linear);

/// The same from the bytes of an image file already in memory (an image
/// embedded in a .glb or a data: URI): the same checks and messages, with
/// `name` where they name the file.
TextureImage decodeTextureImage(std::span<const uint8_t> bytes, const std::string& name, bool linear);

/// What decoding a file will give, from its header alone: its size (with
/// the same checks and messages as decoding) and texel encoding.
struct TextureHeader {
    uint32_t width = 0;
    uint32_t height = 0;
    TexelEncoding encoding = TexelEncoding::Half;

    uint64_t texels() const { return uint64_t(width) * height; }
};
TextureHeader readTextureHeader(std::span<const uint8_t> bytes, const std::string& name, bool linear);

/// A texture file's bytes; InputError naming it when it is missing, not a
/// regular file (a FIFO could block forever) or empty.
std::vector<uint8_t> readTextureFile(const std::filesystem::path& file);

/// The exact sRGB EOTF (IEC 61966-2-1, piecewise), `encoded` in [0, 1].
double srgbToLinear(double encoded);
/// Its inverse.
double linearToSrgb(double linear);

} // namespace vkrt

#include "texture/TextureImage.h"

#include "texture/JpegStructure.h"

#include "io/ExrFile.h"
#include "io/ImageHeader.h"
#include "io/RadianceHdr.h"
#include "shared/TextureTypes.h"
#include "util/Error.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>

// stb_image's implementation is compiled once, in the system's libstb (the `stb` target).
#include <stb/stb_image.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <memory>

namespace vkrt {

namespace fs = std::filesystem;

double srgbToLinear(double encoded)
{
    return encoded <= 0.04045 ? encoded / 12.92 : std::pow((encoded + 0.055) / 1.055, 2.4);
}

double linearToSrgb(double linear)
{
    return linear <= 0.0031308 ? linear * 12.92 : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
}

namespace {

/// Every message starts with the file, or the name an in-memory image was given.
std::vector<uint8_t> readBytes(const fs::path& file)
{
    std::error_code error;
    const fs::file_status status = fs::status(file, error);
    if (!fs::exists(status)) failInFile(file, "texture file not found");
    if (fs::is_directory(status)) failInFile(file, "is a directory, not an image file");
    // A device or pipe (/dev/zero, a FIFO) could block or never end.
    if (!fs::is_regular_file(status)) failInFile(file, "is not a regular file");
    std::ifstream in(file, std::ios::binary);
    if (!in) failInFile(file, "cannot open texture file");
    std::vector<uint8_t> bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    if (bytes.empty()) failInFile(file, "empty file, not an image");
    return bytes;
}

bool isExr(std::span<const uint8_t> bytes)
{
    return bytes.size() >= 4 && bytes[0] == 0x76 && bytes[1] == 0x2f && bytes[2] == 0x31 && bytes[3] == 0x01;
}

void checkSize(const std::string& file, uint64_t width, uint64_t height)
{
    if (width == 0 || height == 0)
        failInFile(file, "unsupported image: " + std::to_string(width) + "x" + std::to_string(height) + " pixels");
    if (width > gpu::TEXTURE_MAX_SIZE || height > gpu::TEXTURE_MAX_SIZE)
        failInFile(file, "unsupported image: " + std::to_string(width) + "x" + std::to_string(height) +
                             " pixels (textures may have at most " + std::to_string(gpu::TEXTURE_MAX_SIZE) +
                             " pixels a side)");
}

std::string stbReason()
{
    const char* reason = stbi_failure_reason();
    return reason ? reason : "unknown reason";
}

/// stb_image results, freed with stbi_image_free.
template <typename T>
using StbPixels = std::unique_ptr<T, void (*)(void*)>;

/// An EXR's R, G, B (alpha 1) as a texture, refusing non-finite texels.
TextureImage exrTexture(const Image& rgb, const std::string& file)
{
    checkSize(file, rgb.width, rgb.height);
    TextureImage texture{RgbaImage(rgb.width, rgb.height), TexelEncoding::Half};
    for (uint32_t y = 0; y < rgb.height; ++y) {
        for (uint32_t x = 0; x < rgb.width; ++x) {
            const float* in = rgb.at(x, y);
            float* out = texture.pixels.at(x, y);
            for (int c = 0; c < 3; ++c) {
                if (!std::isfinite(in[c]))
                    failInFile(file, "non-finite texel (" + std::string(std::isnan(in[c]) ? "NaN" : "infinity") +
                                         ") at pixel x=" + std::to_string(x) + ", y=" + std::to_string(y) +
                                         " (from the top left)");
                out[c] = in[c];
            }
            out[3] = 1.0f;
        }
    }
    return texture;
}

/// io/ExrFile's reading of R, G and B (the same messages), from memory, the
/// header checked (io/ImageHeader.h) before anything is allocated.
TextureImage decodeExr(std::span<const uint8_t> bytes, const std::string& name)
{
    try {
        MemoryExrStream stream(bytes, name);
        const ImageExtent extent = extentOf(readCheckedExrHeader(stream, bytes.size(), name));
        checkSize(name, extent.width, extent.height);
        stream.seekg(0);
        Imf::InputFile file(stream);
        const Imath::Box2i window = file.header().dataWindow();
        Image rgb(extent.width, extent.height);
        Imf::FrameBuffer frame;
        const char* const channels[3] = {"R", "G", "B"};
        for (int c = 0; c < 3; ++c) {
            if (!file.header().channels().findChannel(channels[c]))
                failInFile(name, "no channel '" + std::string(channels[c]) + "'");
            char* base =
                reinterpret_cast<char*>(rgb.rgb.data() + c) -
                (int64_t(window.min.x) + int64_t(window.min.y) * int64_t(rgb.width)) * int64_t(sizeof(float) * 3);
            frame.insert(channels[c], Imf::Slice(Imf::FLOAT, base, sizeof(float) * 3, sizeof(float) * 3 * rgb.width));
        }
        file.setFrameBuffer(frame);
        file.readPixels(window.min.y, window.max.y);
        return exrTexture(rgb, name);
    } catch (const InputError&) {
        throw;
    } catch (const std::exception& e) {
        failInFile(name, std::string("not a readable EXR file: ") + e.what());
    }
}

/// Decodes channel values quantized to `maxCode` (8 or 16 bits) into linear
/// floats. Each code's two values (sRGB colour, linear) are computed once,
/// exactly as per texel before: a 2048x2048 image no longer calls pow() 12
/// million times.
template <typename T>
void decodeChannels(const T* codes, RgbaImage& image, double maxCode, bool linear)
{
    std::vector<float> asColour(size_t(maxCode) + 1), asLinear(size_t(maxCode) + 1);
    for (size_t code = 0; code < asLinear.size(); ++code) {
        const double value = double(code) / maxCode;
        asColour[code] = float(linear ? value : srgbToLinear(value));
        asLinear[code] = float(value);
    }
    for (size_t i = 0; i < image.rgba.size(); ++i) {
        const bool colour = i % 4 != 3; // alpha is always linear
        image.rgba[i] = (colour ? asColour : asLinear)[codes[i]];
    }
}

/// stb_image's header: the size, or the reason it cannot be read.
ImageExtent stbHeader(std::span<const uint8_t> bytes, const std::string& file)
{
    const auto* data = bytes.data();
    const int length = int(bytes.size());
    int width = 0, height = 0, channels = 0;
    if (bytes.size() > size_t(INT32_MAX)) failInFile(file, "unsupported image: larger than 2 GiB");
    if (!stbi_info_from_memory(data, length, &width, &height, &channels)) {
        // stbi_info tries every format in turn and reports the last one's
        // complaint ("unknown image type"); a decode attempt stops at the
        // format whose signature matches and says what is wrong with it.
        // (Only a header stb_image cannot parse gets here: no size to believe.)
        StbPixels<stbi_uc> pixels(stbi_load_from_memory(data, length, &width, &height, &channels, 4), stbi_image_free);
        const std::string reason = pixels ? "its header cannot be read" : stbReason();
        if (reason == "unknown image type") failInFile(file, "not an image file (stb_image: " + reason + ")");
        failInFile(file, "unsupported or damaged image (stb_image: " + reason + ")");
    }
    checkSize(file, uint64_t(width), uint64_t(height));
    // stb_image decodes a JPEG cut short as if the rest were zeros: its structure is checked first.
    if (isJpeg(bytes))
        if (const auto problem = jpegStructureProblem(bytes)) failInFile(file, "damaged JPEG image: " + *problem);
    return {uint32_t(width), uint32_t(height)};
}

TexelEncoding stbEncoding(std::span<const uint8_t> bytes, bool linear)
{
    const int length = int(bytes.size());
    if (stbi_is_hdr_from_memory(bytes.data(), length) || stbi_is_16_bit_from_memory(bytes.data(), length))
        return TexelEncoding::Half;
    return linear ? TexelEncoding::Unorm8 : TexelEncoding::Srgb8;
}

TextureImage decodeHdr(std::span<const uint8_t> bytes, const std::string& file)
{
    const ImageExtent extent = radianceHdrExtent(bytes, bytes.size(), file);
    checkSize(file, extent.width, extent.height);
    RadianceHdrImage decoded = decodeRadianceHdr(bytes, file);
    TextureImage texture{RgbaImage(), TexelEncoding::Half};
    texture.pixels.width = extent.width;
    texture.pixels.height = extent.height;
    texture.pixels.rgba = std::move(decoded.rgba);
    return texture;
}

TextureImage decodeStb(std::span<const uint8_t> bytes, const std::string& file, bool linear)
{
    const auto* data = bytes.data();
    const int length = int(bytes.size());
    const ImageExtent extent = stbHeader(bytes, file);
    int width = 0, height = 0, channels = 0;
    TextureImage texture{RgbaImage(extent.width, extent.height), stbEncoding(bytes, linear)};
    // Four channels requested: grey becomes (g, g, g, 1), grey + alpha (g, g, g, a), RGB gets alpha 1.
    if (stbi_is_hdr_from_memory(data, length)) {
        StbPixels<float> pixels(stbi_loadf_from_memory(data, length, &width, &height, &channels, 4), stbi_image_free);
        if (!pixels) failInFile(file, "cannot decode image (stb_image: " + stbReason() + ")");
        std::copy_n(pixels.get(), texture.pixels.rgba.size(), texture.pixels.rgba.begin());
    } else if (stbi_is_16_bit_from_memory(data, length)) {
        StbPixels<stbi_us> pixels(stbi_load_16_from_memory(data, length, &width, &height, &channels, 4),
                                  stbi_image_free);
        if (!pixels) failInFile(file, "cannot decode image (stb_image: " + stbReason() + ")");
        decodeChannels(pixels.get(), texture.pixels, 65535.0, linear);
    } else {
        StbPixels<stbi_uc> pixels(stbi_load_from_memory(data, length, &width, &height, &channels, 4), stbi_image_free);
        if (!pixels) failInFile(file, "cannot decode image (stb_image: " + stbReason() + ")");
        decodeChannels(pixels.get(), texture.pixels, 255.0, linear);
    }
    return texture;
}

} // namespace

std::vector<uint8_t> readTextureFile(const fs::path& file) { return readBytes(file); }

TextureHeader readTextureHeader(std::span<const uint8_t> bytes, const std::string& name, bool linear)
{
    if (bytes.empty()) failInFile(name, "empty file, not an image");
    if (isExr(bytes)) {
        MemoryExrStream stream(bytes, name);
        const ImageExtent extent = extentOf(readCheckedExrHeader(stream, bytes.size(), name));
        checkSize(name, extent.width, extent.height);
        return {extent.width, extent.height, TexelEncoding::Half};
    }
    if (isRadianceHdr(bytes)) {
        const ImageExtent extent = radianceHdrExtent(bytes, bytes.size(), name);
        checkSize(name, extent.width, extent.height);
        return {extent.width, extent.height, TexelEncoding::Half};
    }
    const ImageExtent extent = stbHeader(bytes, name);
    return {extent.width, extent.height, stbEncoding(bytes, linear)};
}

TextureImage loadTextureImage(const fs::path& file, bool linear)
{
    return decodeTextureImage(readBytes(file), file.string(), linear);
}

TextureImage decodeTextureImage(std::span<const uint8_t> bytes, const std::string& name, bool linear)
{
    if (bytes.empty()) failInFile(name, "empty file, not an image");
    if (isExr(bytes)) return decodeExr(bytes, name);         // EXR is linear whatever `linear` says
    if (isRadianceHdr(bytes)) return decodeHdr(bytes, name); // so is HDR
    return decodeStb(bytes, name, linear);
}

} // namespace vkrt

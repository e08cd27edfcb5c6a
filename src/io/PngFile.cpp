#include "io/PngFile.h"

#include "io/AtomicFile.h"
#include "io/ExrFile.h"
#include "io/RadianceHdr.h"
#include "util/Error.h"

#include <stb/stb_image.h>
#include <stb/stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

namespace vkrt {

uint8_t toneMapToSrgb8(float linear, float exposure, ToneCurve curve)
{
    float v = linear * std::exp2(exposure);
    if (!(v > 0.0f)) return 0; // also maps NaN to black
    if (curve == ToneCurve::Filmic) {
        // An infinite radiance is white (inf / inf would be NaN).
        v = std::isinf(v) ? 1.0f : (v * (2.51f * v + 0.03f)) / (v * (2.43f * v + 0.59f) + 0.14f);
    }
    v = std::min(v, 1.0f);
    float encoded = v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
    return uint8_t(std::lround(encoded * 255.0f));
}

std::vector<uint8_t> toneMapImage(const Image& image, float exposure, ToneCurve curve)
{
    std::vector<uint8_t> pixels(image.pixelCount() * 4, 255);
    for (size_t i = 0; i < image.pixelCount(); ++i)
        for (int c = 0; c < 3; ++c) pixels[i * 4 + c] = toneMapToSrgb8(image.rgb[i * 3 + c], exposure, curve);
    return pixels;
}

namespace {

/// stb's writer appends here instead of writing a file itself: stbi_write_png
/// ignores fwrite and fclose errors, so a full disk left a short PNG.
extern "C" void appendToString(void* context, void* data, int size)
{
    static_cast<std::string*>(context)->append(static_cast<const char*>(data), size_t(size));
}

} // namespace

void writePngPixels(const std::filesystem::path& path, uint32_t width, uint32_t height,
                    const std::vector<uint8_t>& rgba)
{
    VKRT_CHECK(rgba.size() == size_t(width) * height * 4);
    if (resolveOutputTarget(path).kind == OutputTargetKind::Discarded) return; // before the encode's cost
    std::string encoded;
    if (!stbi_write_png_to_func(appendToString, &encoded, int(width), int(height), 4, rgba.data(), int(width * 4)))
        throw InputError(path.string() + ": cannot encode PNG (" + std::to_string(width) + "x" +
                         std::to_string(height) + ")");
    writeBytesAtomically(path, encoded);
}

void writePng(const std::filesystem::path& path, const Image& image, float exposure, ToneCurve curve)
{
    writePngPixels(path, image.width, image.height, toneMapImage(image, exposure, curve));
}

} // namespace vkrt

namespace vkrt {

float srgb8ToLinear(uint8_t value)
{
    float v = float(value) / 255.0f;
    return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

Image readPng(const std::filesystem::path& path)
{
    int width = 0, height = 0, channels = 0;
    std::unique_ptr<stbi_uc, void (*)(void*)> pixels(stbi_load(path.c_str(), &width, &height, &channels, 3),
                                                     stbi_image_free);
    if (!pixels)
        throw InputError(path.string() + ": cannot read PNG: " + (stbi_failure_reason() ? stbi_failure_reason() : "?"));
    Image image{uint32_t(width), uint32_t(height)};
    for (size_t i = 0; i < image.rgb.size(); ++i) image.rgb[i] = srgb8ToLinear(pixels.get()[i]);
    return image;
}

Image readRadianceHdr(const std::filesystem::path& path)
{
    std::error_code error;
    if (!std::filesystem::is_regular_file(path, error))
        throw InputError(path.string() +
                         (std::filesystem::exists(path, error) ? ": is not a regular file" : ": no such file"));
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path.string() + ": cannot be opened");
    const std::vector<uint8_t> bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    const RadianceHdrImage decoded = decodeRadianceHdr(bytes, path.string());
    Image image{decoded.extent.width, decoded.extent.height};
    for (size_t i = 0; i < decoded.extent.pixels(); ++i) std::copy_n(&decoded.rgba[4 * i], 3, &image.rgb[3 * i]);
    return image;
}

Image readRgbImage(const std::filesystem::path& path)
{
    std::string extension = path.extension().string();
    for (char& c : extension) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (extension == ".exr") return readExr(path).image;
    if (extension == ".png") return readPng(path);
    if (extension == ".hdr") return readRadianceHdr(path);
    throw InputError(path.string() + ": unsupported image type (expected .exr, .hdr or .png)");
}

} // namespace vkrt

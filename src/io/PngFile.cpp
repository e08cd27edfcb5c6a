#include "io/PngFile.h"

#include "io/AtomicFile.h"
#include "util/Error.h"

#include <stb/stb_image_write.h>

#include <algorithm>
#include <cmath>

namespace vkrt {

uint8_t toneMapToSrgb8(float linear, float exposure)
{
    float v = linear * std::exp2(exposure);
    if (!(v > 0.0f)) return 0; // also maps NaN to black
    v = std::min(v, 1.0f);
    float encoded = v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
    return uint8_t(std::lround(encoded * 255.0f));
}

std::vector<uint8_t> toneMapImage(const Image& image, float exposure)
{
    std::vector<uint8_t> pixels(image.pixelCount() * 4, 255);
    for (size_t i = 0; i < image.pixelCount(); ++i)
        for (int c = 0; c < 3; ++c) pixels[i * 4 + c] = toneMapToSrgb8(image.rgb[i * 3 + c], exposure);
    return pixels;
}

void writePng(const std::filesystem::path& path, const Image& image, float exposure)
{
    std::vector<uint8_t> pixels = toneMapImage(image, exposure);
    writeFileAtomically(path, [&](const std::filesystem::path& temporary) {
        if (!stbi_write_png(temporary.c_str(), int(image.width), int(image.height), 4, pixels.data(),
                            int(image.width * 4)))
            throw InputError(path.string() + ": cannot write PNG");
    });
}

} // namespace vkrt

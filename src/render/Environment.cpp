#include "render/Environment.h"

#include "io/ImageHeader.h"
#include "io/PngFile.h"
#include "util/Error.h"

#include <algorithm>
#include <cmath>

namespace vkrt {

namespace {

const char* const kFaceKeys[6] = {"px", "nx", "py", "ny", "pz", "nz"};

std::string faceLabel(const Cubemap& cubemap, int face)
{
    return cubemap.where.str() + ": background.cubemap." + kFaceKeys[face] + ": ";
}

/// A face's size: square, within kMaxCubeFaceSide, and like the first face's (`first`, 0 for px itself).
void checkFaceSize(const Cubemap& cubemap, int face, ImageExtent size, uint32_t first)
{
    const std::string label = faceLabel(cubemap, face) + cubemap.facePaths[face];
    if (size.width != size.height || size.width == 0)
        throw InputError(label + ": a cube face must be square, got " + size.str());
    if (size.width > kMaxCubeFaceSide)
        throw InputError(label + ": a cube face may have at most " + std::to_string(kMaxCubeFaceSide) +
                         " pixels a side, got " + size.str());
    if (first != 0 && size.width != first)
        throw InputError(label + ": all faces must have the same size (" + std::to_string(first) + " for px), got " +
                         std::to_string(size.width));
}

/// Every face's header, before any face is decoded: six files that claim
/// more than a cubemap may hold cost nothing but their headers.
void checkFaceHeaders(const Cubemap& cubemap)
{
    uint32_t first = 0;
    for (int i = 0; i < 6; ++i) {
        ImageExtent size;
        try {
            size = imageFileExtent(cubemap.facePaths[i]);
        } catch (const InputError& e) {
            throw InputError(faceLabel(cubemap, i) + e.what());
        }
        checkFaceSize(cubemap, i, size, first);
        first = size.width;
    }
}

} // namespace

std::array<Image, 6> loadCubemapFaces(const Cubemap& cubemap)
{
    checkFaceHeaders(cubemap);
    std::array<Image, 6> faces;
    for (int i = 0; i < 6; ++i) {
        std::string label = faceLabel(cubemap, i);
        try {
            faces[i] = readRgbImage(cubemap.facePaths[i]);
        } catch (const InputError& e) {
            throw InputError(label + e.what());
        }
        // The decoder must agree with the header it was checked by.
        checkFaceSize(cubemap, i, {faces[i].width, faces[i].height}, faces[0].width);
        for (float v : faces[i].rgb)
            if (!std::isfinite(v) || v < 0.0f)
                throw InputError(label + cubemap.facePaths[i] + ": contains a negative or non-finite value");
    }
    return faces;
}

namespace {

void checkLatLongSize(const std::string& label, ImageExtent size)
{
    if (size.width < 2 || size.height < 2)
        throw InputError(label + ": a lat-long map needs at least 2x2 texels, got " + size.str());
    if (size.width > kMaxLatLongSide || size.height > kMaxLatLongSide || size.pixels() > ImageLimits::maxPixels)
        throw InputError(label + ": a lat-long map may have at most " + std::to_string(kMaxLatLongSide) +
                         " texels a side and " + std::to_string(ImageLimits::maxPixels) + " in all, got " + size.str());
}

} // namespace

Image studioEnvironment()
{
    constexpr uint32_t width = 256, height = 128;
    Image image(width, height);
    image.rgb.resize(size_t(width) * height * 3);
    for (uint32_t j = 0; j < height; ++j) {
        // The row's centre: y = cos(theta), theta = pi (j + 0.5) / height (row 0 looks up).
        const double y = std::cos(3.14159265358979323846 * (j + 0.5) / height);
        double radiance = 0.6 + 0.4 * y; // the sky: 1 at the zenith, 0.6 at the horizon
        if (y < 0.0) {
            const double t = std::min(1.0, -y / std::sin(15.0 * 3.14159265358979323846 / 180.0));
            radiance = 0.6 + (0.25 - 0.6) * t * t * (3.0 - 2.0 * t); // smoothstep down to the ground's 0.25
        }
        for (uint32_t i = 0; i < width; ++i)
            for (int c = 0; c < 3; ++c) image.rgb[(size_t(j) * width + i) * 3 + c] = float(radiance);
    }
    return image;
}

Image loadEnvironmentMap(const EnvironmentMap& map)
{
    if (map.studio) {
        Image image = studioEnvironment();
        for (size_t i = 0; i < image.rgb.size(); ++i)
            image.rgb[i] = float(double(image.rgb[i]) * map.scale[int(i % 3)]);
        return image;
    }
    const std::string label = map.where.str() + ": background.environment.file: " + map.path;
    Image image;
    try {
        checkLatLongSize(label, imageFileExtent(map.path));
        image = readRgbImage(map.path);
    } catch (const InputError& e) {
        if (std::string(e.what()).starts_with(label)) throw;
        throw InputError(map.where.str() + ": background.environment.file: " + e.what());
    }
    checkLatLongSize(label, {image.width, image.height}); // the decoder must agree with the header
    for (size_t i = 0; i < image.rgb.size(); ++i) {
        const float value = float(double(image.rgb[i]) * map.scale[int(i % 3)]);
        if (!std::isfinite(image.rgb[i]) || image.rgb[i] < 0.0f || !std::isfinite(value))
            throw InputError(label + ": contains a negative or non-finite value" +
                             (std::isfinite(image.rgb[i]) ? " once scaled" : ""));
        image.rgb[i] = value;
    }
    return image;
}

} // namespace vkrt

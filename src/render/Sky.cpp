#include "render/Sky.h"

#include "render/CubeFaces.h"

#include <algorithm>
#include <cmath>
#include <glm/gtc/constants.hpp>

namespace vkrt {

glm::dvec3 sunDirection(const SkyParameters& sky)
{
    double elevation = glm::radians(sky.sunElevationDegrees), azimuth = glm::radians(sky.sunAzimuthDegrees);
    return {std::cos(elevation) * std::sin(azimuth), std::sin(elevation), std::cos(elevation) * std::cos(azimuth)};
}

glm::dvec3 skyRadiance(const SkyParameters& sky, const glm::dvec3& d)
{
    if (d.y < 0.0) return sky.ground;
    glm::dvec3 base = glm::mix(sky.horizon, sky.zenith, std::pow(d.y, 0.6));
    double angle = std::acos(std::clamp(glm::dot(d, sunDirection(sky)), -1.0, 1.0));
    double radius = glm::radians(sky.sunAngularRadiusDegrees);
    if (angle <= radius) return base + sky.sunColor * sky.sunRadiance;
    double glow = std::exp(-(angle - radius) / (4.0 * radius));
    return base + sky.sunColor * (sky.glowRadiance * glow);
}

std::array<Image, 6> renderSkyFaces(const SkyParameters& sky, uint32_t size)
{
    constexpr int kSubsamples = 4;
    std::array<Image, 6> faces;
    for (int face = 0; face < 6; ++face) {
        faces[face] = Image(size, size);
        for (uint32_t y = 0; y < size; ++y) {
            for (uint32_t x = 0; x < size; ++x) {
                glm::dvec3 sum(0.0);
                for (int j = 0; j < kSubsamples; ++j)
                    for (int i = 0; i < kSubsamples; ++i)
                        sum += skyRadiance(sky, cubeFaceDirection(face, (x + (i + 0.5) / kSubsamples) / size,
                                                                  (y + (j + 0.5) / kSubsamples) / size));
                glm::dvec3 mean = sum / double(kSubsamples * kSubsamples);
                float* texel = faces[face].at(x, y);
                texel[0] = float(mean.x), texel[1] = float(mean.y), texel[2] = float(mean.z);
            }
        }
    }
    return faces;
}

Image renderSkyLatLong(const SkyParameters& sky, uint32_t width)
{
    constexpr int kSubsamples = 4;
    const uint32_t height = width / 2 + 1;
    Image map(width, height);
    for (uint32_t y = 0; y < height; ++y) {
        for (uint32_t x = 0; x < width; ++x) {
            glm::dvec3 sum(0.0);
            for (int j = 0; j < kSubsamples; ++j) {
                for (int i = 0; i < kSubsamples; ++i) {
                    double u = (x + (i + 0.5) / kSubsamples) / width;
                    double v = std::clamp((y + (j + 0.5) / kSubsamples - 0.5) / (height - 1), 0.0, 1.0);
                    double phi = 2.0 * glm::pi<double>() * u, theta = glm::pi<double>() * v;
                    sum += skyRadiance(sky, {std::sin(phi) * std::sin(theta), std::cos(theta),
                                             -std::cos(phi) * std::sin(theta)});
                }
            }
            glm::dvec3 mean = sum / double(kSubsamples * kSubsamples);
            float* texel = map.at(x, y);
            texel[0] = float(mean.x), texel[1] = float(mean.y), texel[2] = float(mean.z);
        }
    }
    return map;
}

} // namespace vkrt

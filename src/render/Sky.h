#pragma once
// An analytic sky for demo scenes: a vertical gradient from horizon to zenith,
// a darker ground below the horizon, and a sun disk with a soft glow. Used by
// tools/make_sky to write cubemap faces (we ship no downloaded skies).
#include "io/Image.h"

#include <array>
#include <glm/glm.hpp>

namespace vkrt {

struct SkyParameters {
    glm::dvec3 zenith{0.08, 0.15, 0.4};
    glm::dvec3 horizon{0.4, 0.45, 0.55};
    glm::dvec3 ground{0.1, 0.09, 0.08};
    glm::dvec3 sunColor{1.0, 0.92, 0.8};
    double sunElevationDegrees = 35.0;
    double sunAzimuthDegrees = 45.0; ///< from +z towards +x
    double sunAngularRadiusDegrees = 3.0;
    double sunRadiance = 12.0; ///< scale of sunColor inside the disk
    double glowRadiance = 0.6; ///< scale of the glow around the sun
};

/// Unit vector towards the sun.
glm::dvec3 sunDirection(const SkyParameters& sky);

/// Radiance arriving from unit direction `d`.
glm::dvec3 skyRadiance(const SkyParameters& sky, const glm::dvec3& d);

/// Six size x size faces (Vulkan order), each texel the radiance averaged over
/// a 4x4 grid of directions inside it (so the small sun is not aliased away).
std::array<Image, 6> renderSkyFaces(const SkyParameters& sky, uint32_t size);

/// A width x (width / 2 + 1) lat-long map in the layout of [background.environment]
/// (src/scene/Scene.h, EnvironmentMap: column i at u = (i + 0.5) / width, row j
/// at v = j / (height - 1)), each texel the radiance averaged over a 4x4 grid
/// of directions in the texel-sized patch around it.
Image renderSkyLatLong(const SkyParameters& sky, uint32_t width);

} // namespace vkrt

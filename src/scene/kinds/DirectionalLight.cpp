// Directional lights (`type = "directional"`, a sun): keys, reader and GPU
// record; infinitely far away, so never hit by a surface's ray and unbounded.
// A soft sun (angle > 0) is seen by rays that escape towards it. The
// kernel's side is shaders/lib/lights/directional.glsl.
#include "scene/SceneOverrides.h"
#include "scene/SceneValues.h"
#include "scene/kinds/Kinds.h"

#include <algorithm>
#include <cmath>
#include <glm/gtc/constants.hpp>
#include <limits>

namespace vkrt {

namespace {

/// The cone's half angle in radians.
double halfAngle(const DirectionalLight& light) { return glm::radians(light.angle) / 2.0; }

/// The uniform radiance of a disk of half angle alpha that gives `irradiance`
/// on a surface facing it: E = L * pi * sin^2(alpha).
Color diskRadiance(const DirectionalLight& light)
{
    const double s = std::sin(halfAngle(light));
    return light.irradiance / (glm::pi<double>() * s * s);
}

} // namespace

KeyList directionalLightKeys()
{
    static constexpr std::array<std::string_view, 4> keys{"type", "direction", "irradiance", "angle"};
    return keys;
}

void readDirectionalLight(const TableField& table, ParseContext& context)
{
    DirectionalLight light;
    const Field directionField = table.require("direction");
    const std::optional<glm::dvec3> direction = normalized(readVector(directionField));
    if (!direction) directionField.fail("must not be zero-length");
    light.direction = *direction;
    light.irradiance = readRadiance(table.require("irradiance"));
    if (const auto angle = table.find("angle")) {
        light.angle = readNumberIn(*angle, {0.0, 180.0, false, true});
        const Color radiance = light.angle > 0 ? diskRadiance(light) : Color(0.0);
        const double largest = std::max({radiance.r, radiance.g, radiance.b});
        if (!(largest <= std::numeric_limits<float>::max()))
            angle->fail("a sun this small and bright has a radiance beyond 32-bit float range (" +
                        formatNumber(largest) + "); make it larger or dimmer");
    }
    context.scene.directionalLights.push_back(light);
}

gpu::DirectionalLight toGpu(const DirectionalLight& l, const Relativizer&, uint32_t)
{
    gpu::DirectionalLight g{};
    g.toLight = glm::vec3(-l.direction);
    if (l.angle == 0.0) {
        g.radiance = glm::vec3(l.irradiance);
        return g;
    }
    const double alpha = halfAngle(l), s = std::sin(alpha / 2.0);
    g.oneMinusCos = float(2.0 * s * s); // 1 - cos(alpha) without cancellation
    g.sin2Alpha = float(std::sin(alpha) * std::sin(alpha));
    g.radiance = glm::vec3(diskRadiance(l));
    return g;
}

} // namespace vkrt

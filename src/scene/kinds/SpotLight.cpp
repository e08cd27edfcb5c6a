// Spot lights (`type = "spot"`): keys, reader and GPU record; a point light
// whose intensity falls off away from its axis as glTF's KHR_lights_punctual
// specifies. No area, so never hit and unbounded. The kernel's side is
// shaders/lib/lights/spot.glsl.
#include "scene/SceneOverrides.h"
#include "scene/SceneValues.h"
#include "scene/kinds/Kinds.h"

#include <algorithm>
#include <cmath>
#include <glm/gtc/constants.hpp>

namespace vkrt {

KeyList spotLightKeys()
{
    static constexpr std::array<std::string_view, 6> keys{
        "type", "position", "direction", "intensity", "inner_cone_angle", "outer_cone_angle"};
    return keys;
}

void readSpotLight(const TableField& table, ParseContext& context)
{
    SpotLight light;
    light.position = readVector(table.require("position"));
    const Field directionField = table.require("direction");
    const std::optional<glm::dvec3> direction = normalized(readVector(directionField));
    if (!direction) directionField.fail("must not be zero-length");
    light.direction = *direction;
    light.intensity = readRadiance(table.require("intensity"));
    // glTF's defaults: inner 0, outer pi/4.
    const auto outer = [](const Field& field) { return readNumberIn(field, {0.0, 90.0, true, false}); };
    light.outerConeAngle = readOr(table, "outer_cone_angle", light.outerConeAngle, outer);
    if (const auto inner = table.find("inner_cone_angle")) {
        light.innerConeAngle = readNumberIn(*inner, {0.0, 90.0});
        if (light.innerConeAngle > light.outerConeAngle)
            inner->fail("must not exceed outer_cone_angle (" + formatNumber(light.outerConeAngle) + ")");
    } else {
        light.innerConeAngle = std::min(light.innerConeAngle, light.outerConeAngle);
    }
    context.scene.spotLights.push_back(light);
}

gpu::SpotLight toGpu(const SpotLight& l, const Relativizer& rel, uint32_t)
{
    const double cosInner = std::cos(glm::radians(l.innerConeAngle));
    const double cosOuter = std::cos(glm::radians(l.outerConeAngle));
    gpu::SpotLight g{};
    g.position = rel(l.position);
    g.cosOuter = float(cosOuter);
    g.intensity = glm::vec3(l.intensity);
    // A cone narrower than float can tell from a hard edge is one.
    const float width = float(cosInner) - float(cosOuter);
    g.falloffScale = width > 0.0f ? float(1.0 / (cosInner - cosOuter)) : 0.0f;
    g.axis = glm::vec3(l.direction);
    return g;
}

} // namespace vkrt

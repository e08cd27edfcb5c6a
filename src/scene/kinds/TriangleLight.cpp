// Triangle lights (`type = "triangle"`): keys, reader, bounds, the GPU record
// rays are tested against and the Emitter that says what it emits (one of
// all emitters, shared/SceneTypes.h). The kernel's side is
// shaders/lib/lights/triangle.glsl and shaders/lib/emitters.glsl.
#include "scene/SceneValues.h"
#include "scene/kinds/Kinds.h"

#include <cmath>
#include <glm/gtc/constants.hpp>

namespace vkrt {

KeyList triangleLightKeys()
{
    static constexpr std::array<std::string_view, 4> keys{"type", "vertices", "radiance", "two_sided"};
    return keys;
}

void readTriangleLight(const TableField& table, ParseContext& context)
{
    TriangleLight light;
    light.vertices = readVertices(table.require("vertices"));
    light.radiance = readRadiance(table.require("radiance"));
    light.twoSided = readOr(table, "two_sided", false, readBool);
    context.scene.triangleLights.push_back(light);
}

bool emits(const TriangleLight& light)
{
    const double area = triangleArea(light.vertices);
    return area > 0.0 && float(area) > 0.0 && std::isfinite(area);
}

Aabb boundsOf(const TriangleLight& light)
{
    Aabb box;
    for (const glm::dvec3& p : light.vertices) box.extend(p);
    return box;
}

/// Triangle lights are the first emitters: the index-th one is Emitter index.
gpu::TriangleLight toGpu(const TriangleLight& light, const Relativizer& rel, uint32_t index)
{
    return {rel(light.vertices[0]), index, rel(light.vertices[1]), rel(light.vertices[2])};
}

gpu::Emitter emitterOf(const TriangleLight& light, const Relativizer& rel)
{
    gpu::Emitter e{};
    e.v0 = rel(light.vertices[0]);
    e.v1 = rel(light.vertices[1]);
    e.v2 = rel(light.vertices[2]);
    e.area = float(triangleArea(light.vertices));
    e.twoSided = light.twoSided ? 1u : 0u;
    e.radiance = glm::vec3(light.radiance);
    e.textures = gpu::NO_EMISSION_TEXTURE;
    return e;
}

double emittedPower(const TriangleLight& light)
{
    const Color& c = light.radiance;
    return (c.r + c.g + c.b) / 3.0 * triangleArea(light.vertices) * (light.twoSided ? 2.0 : 1.0) * glm::pi<double>();
}

} // namespace vkrt

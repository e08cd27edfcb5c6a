// Point lights (`type = "point"`): keys, reader and GPU record; no area, so
// never hit and unbounded. The kernel's side is shaders/lib/lights/point.glsl.
#include "scene/SceneValues.h"
#include "scene/kinds/Kinds.h"

namespace vkrt {

KeyList pointLightKeys()
{
    static constexpr std::array<std::string_view, 3> keys{"type", "position", "intensity"};
    return keys;
}

void readPointLight(const TableField& table, ParseContext& context)
{
    context.scene.pointLights.push_back(
        {readVector(table.require("position")), readRadiance(table.require("intensity"))});
}

gpu::PointLight toGpu(const PointLight& l, const Relativizer& rel, uint32_t)
{
    return {rel(l.position), glm::vec3(l.intensity)};
}

} // namespace vkrt

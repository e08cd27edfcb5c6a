// Infinite planes (`shape = "plane"`): keys, reader and GPU record; unbounded
// (registry column bounded = 0), so no boundsOf. The kernel's side is
// shaders/lib/shapes/plane.glsl.
#include "scene/SceneOverrides.h"
#include "scene/kinds/Kinds.h"

#include <optional>

namespace vkrt {

KeyList planeKeys()
{
    static constexpr std::array<std::string_view, 4> keys{"shape", "material", "point", "normal"};
    return keys;
}

void readPlane(const TableField& table, uint32_t material, ParseContext& context)
{
    const glm::dvec3 point = readVector(table.require("point"));
    const Field normalField = table.require("normal");
    const std::optional<glm::dvec3> normal = normalized(readVector(normalField));
    if (!normal) normalField.fail("must not be zero-length");
    context.scene.planes.push_back({point, *normal, material});
}

gpu::Plane toGpu(const Plane& p, const Relativizer& rel, uint32_t)
{
    return {rel(p.point), p.material, glm::vec3(p.normal)};
}

} // namespace vkrt

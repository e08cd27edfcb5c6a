// Single triangles (`shape = "triangle"`): keys, reader, bounds and GPU
// record. The kernel's side is shaders/lib/shapes/triangle.glsl.
#include "scene/SceneValues.h"
#include "scene/kinds/Kinds.h"

namespace vkrt {

KeyList triangleKeys()
{
    static constexpr std::array<std::string_view, 3> keys{"shape", "material", "vertices"};
    return keys;
}

void readTriangle(const TableField& table, uint32_t material, ParseContext& context)
{
    // Degenerate triangles are accepted on purpose: meshes exported by tools
    // contain them, and the renderer handles them.
    context.scene.triangles.push_back({readVertices(table.require("vertices")), material});
}

Aabb boundsOf(const Triangle& t)
{
    Aabb box;
    for (const glm::dvec3& p : t.vertices) box.extend(p);
    return box;
}

gpu::Triangle toGpu(const Triangle& t, const Relativizer& rel, uint32_t)
{
    return {rel(t.vertices[0]), t.material, rel(t.vertices[1]), rel(t.vertices[2])};
}

double triangleArea(const std::array<glm::dvec3, 3>& v)
{
    return 0.5 * glm::length(glm::cross(v[1] - v[0], v[2] - v[0]));
}

} // namespace vkrt

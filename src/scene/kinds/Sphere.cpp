// Spheres (`shape = "sphere"`): keys, reader, bounds and GPU record. The
// kernel's side is shaders/lib/shapes/sphere.glsl.
#include "scene/kinds/Kinds.h"

namespace vkrt {

KeyList sphereKeys()
{
    static constexpr std::array<std::string_view, 4> keys{"shape", "material", "center", "radius"};
    return keys;
}

void readSphere(const TableField& table, uint32_t material, ParseContext& context)
{
    context.scene.spheres.push_back(
        {readVector(table.require("center")), readPositive(table.require("radius")), material});
}

Aabb boundsOf(const Sphere& s) { return {s.center - glm::dvec3(s.radius), s.center + glm::dvec3(s.radius)}; }

gpu::Sphere toGpu(const Sphere& s, const Relativizer& rel, uint32_t)
{
    return {rel(s.center), float(s.radius), s.material};
}

} // namespace vkrt

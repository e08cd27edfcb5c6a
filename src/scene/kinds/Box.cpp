// Axis-aligned boxes (`shape = "box"`): keys, reader, bounds and GPU record.
// The kernel's side is shaders/lib/shapes/box.glsl.
#include "scene/kinds/Kinds.h"

namespace vkrt {

KeyList boxKeys()
{
    static constexpr std::array<std::string_view, 4> keys{"shape", "material", "min", "max"};
    return keys;
}

namespace {

void checkBoxExtent(const Field& maxField, const glm::dvec3& min, const glm::dvec3& max)
{
    static constexpr char axes[] = "xyz";
    for (int axis = 0; axis < 3; ++axis) {
        if (min[axis] < max[axis]) continue;
        maxField.fail("must be greater than min in every component, but " + std::string(1, axes[axis]) +
                      ": min = " + formatNumber(min[axis]) + " >= max = " + formatNumber(max[axis]));
    }
}

} // namespace

void readBox(const TableField& table, uint32_t material, ParseContext& context)
{
    const glm::dvec3 min = readVector(table.require("min"));
    const Field maxField = table.require("max");
    const glm::dvec3 max = readVector(maxField);
    checkBoxExtent(maxField, min, max);
    context.scene.boxes.push_back({min, max, material});
}

Aabb boundsOf(const Box& b) { return {b.min, b.max}; }

gpu::Box toGpu(const Box& b, const Relativizer& rel, uint32_t) { return {rel(b.min), b.material, rel(b.max)}; }

} // namespace vkrt

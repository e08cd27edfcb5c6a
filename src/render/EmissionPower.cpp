#include "render/EmissionPower.h"

#include <algorithm>
#include <cmath>

namespace vkrt {

glm::dvec2 slotUv(const MaterialTexture& slot, const glm::dvec2& uv)
{
    const double c = std::cos(slot.rotation), s = std::sin(slot.rotation);
    const glm::dvec2 scaled = uv * slot.scale;
    return glm::dvec2(c * scaled.x + s * scaled.y, c * scaled.y - s * scaled.x) + slot.offset;
}

namespace {

/// The mip level whose texels the footprint (in level-0 texels) covers at most 64 of.
uint32_t integrationLevel(double footprintTexels, uint32_t levels)
{
    uint32_t level = 0;
    while (level + 1 < levels && footprintTexels > 64.0) {
        footprintTexels /= 4.0;
        ++level;
    }
    return level;
}

} // namespace

glm::dvec3 meanEmissionTexel(const TextureAtlas& atlas, const MaterialTexture& slot,
                             const std::array<glm::dvec2, 3>& uvs)
{
    std::array<glm::dvec2, 3> at;
    for (int k = 0; k < 3; ++k) at[k] = slotUv(slot, uvs[k]);
    const glm::dvec2 e1 = at[1] - at[0], e2 = at[2] - at[0];
    const double texels = double(atlas.widthOf(slot.record)) * double(atlas.heightOf(slot.record));
    double footprint = 0.5 * std::abs(e1.x * e2.y - e1.y * e2.x) * texels;
    if (!std::isfinite(footprint)) footprint = 0.0;
    const uint32_t level = integrationLevel(footprint, atlas.levelsOf(slot.record));
    const double levelTexels = footprint / std::pow(4.0, double(level));
    const int k = std::clamp(int(std::ceil(2.0 * std::sqrt(levelTexels))), 4, 16);
    // Stratified points of the unit square warped onto the triangle as
    // lib/sampling.glsl's sampleTriangle does (barycentrics 1 - s, s (1 - v), s v, s = sqrt(u)).
    glm::dvec3 sum(0.0);
    for (int i = 0; i < k; ++i) {
        for (int j = 0; j < k; ++j) {
            const double s = std::sqrt((i + 0.5) / k), v = (j + 0.5) / k;
            const glm::dvec2 uv = (1.0 - s) * at[0] + s * (1.0 - v) * at[1] + s * v * at[2];
            const auto texel = atlas.sampleLevel(slot.record, uv.x, uv.y, level);
            sum += glm::max(glm::dvec3(texel[0], texel[1], texel[2]), glm::dvec3(0.0));
        }
    }
    return sum / double(k * k);
}

} // namespace vkrt

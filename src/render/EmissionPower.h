#pragma once
// The mean of an emission texture over a mesh triangle, for the emitters'
// alias table (render/GpuScene: emitterTableOf): a triangle is chosen in
// proportion to the power it emits, factor x texture, so the dark parts of a
// mostly dark emissive map cost no light samples.
#include "scene/Scene.h"
#include "texture/TextureAtlas.h"

#include <array>
#include <glm/glm.hpp>

namespace vkrt {

/// A slot's lookup coordinates of a mesh uv: R (uv * scale) + offset, as
/// lib/material_textures.glsl's slotUv (glTF KHR_texture_transform).
glm::dvec2 slotUv(const MaterialTexture& slot, const glm::dvec2& uv);

/// The mean linear RGB of `slot`'s texture over the triangle with mesh uvs
/// `uvs` (uniform in its area, which is uniform in barycentrics): bilinear
/// lookups (TextureAtlas::sampleLevel) at k x k stratified points of the
/// triangle, in the mip level whose texels the triangle's uv footprint covers
/// at most 64 of (each texel of a level is the box average of level 0's, so
/// a bright texel anywhere under the footprint shows in it), with k = 4 ... 16
/// (about two points per texel side). A footprint over black texels only
/// gives exactly 0. About 10 us a triangle (DamagedHelmet: 15452 triangles,
/// 2048^2 emissive map, in 0.15 s on one core).
glm::dvec3 meanEmissionTexel(const TextureAtlas& atlas, const MaterialTexture& slot,
                             const std::array<glm::dvec2, 3>& uvs);

} // namespace vkrt

#pragma once
// Mip chains for textures of any size, filtered in linear space.
#include "texture/TextureImage.h"

#include <vector>

namespace vkrt {

/// Size of level `level` of a `size`-texel side: max(1, floor(size / 2^level)),
/// so repeated halving and a shift agree (floor(floor(n/2)/2) = floor(n/4)).
uint32_t mipSize(uint32_t size, uint32_t level);

/// Levels of a w x h texture down to 1 x 1: floor(log2(max(w, h))) + 1.
uint32_t mipLevelCount(uint32_t width, uint32_t height);

/// Level `level` of the chain: max(1, floor(w / 2^level)) x ..., each texel
/// the exact area average (a box filter) of level 0 over the texel's
/// footprint, every level spanning the same uv square. A footprint that cuts
/// a level-0 texel takes the covered fraction of it, so odd sizes neither
/// shift nor lose anything: every level keeps level 0's mean, and a mirrored
/// image gives the mirrored chain. Separable (x, then y); alpha is filtered
/// like colour (straight alpha). For odd sides this is the polyphase box of
/// NVIDIA's "Non-Power-of-Two Mipmapping" whitepaper, applied to level 0
/// rather than step by step, whose small errors would add up.
RgbaImage mipLevel(const RgbaImage& level0, uint32_t level);

/// Level 0 (the image itself) to 1 x 1. A level is filtered from the last
/// level whose sides are whole multiples of its own (exact, as its texels
/// are whole footprints: the previous level for power-of-two sizes), else from
/// level 0.
std::vector<RgbaImage> buildMipPyramid(RgbaImage level0);

} // namespace vkrt

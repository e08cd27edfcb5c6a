// Host-side checks of shared/TextureTypes.h, in the manner of SharedTypes.cpp:
// the scalar layout lays TextureRecord out as C++ does while no padding
// appears; tests/texture/texture_layout_test.cpp compares the offsets with
// glslang's reflection.
#include "shared/TextureTypes.h"

#include <cstddef>

namespace vkrt::gpu {

static_assert(sizeof(TextureRecord) == 4 * (7 + TEXTURE_MAX_LEVELS));
static_assert(offsetof(TextureRecord, wrapV) == 20 && offsetof(TextureRecord, filters) == 24 &&
              offsetof(TextureRecord, levelOffset) == 28);
// Level sizes: the largest side has floor(log2(TEXTURE_MAX_SIZE)) + 1 levels.
static_assert((1u << (TEXTURE_MAX_LEVELS - 1)) == TEXTURE_MAX_SIZE);
static_assert(sizeof(TextureSlot) == 36);
static_assert(sizeof(MaterialTextures) == 36 * TEXTURE_SLOT_COUNT + 8);
// lib/material_textures.glsl's texturedMaterial reads the slots before the
// emission slot, which must be the last (the emitters read it).
static_assert(TEXTURE_SLOT_EMISSION == TEXTURE_SLOT_NORMAL + 1 && TEXTURE_SLOT_COUNT == TEXTURE_SLOT_EMISSION + 1);
// ... and the pbr layers' slots in one run between the base's and the normal map's.
static_assert(TEXTURE_SLOT_SPECULAR_FACTOR == TEXTURE_SLOT_METALLIC + 1 &&
              TEXTURE_SLOT_CLEARCOAT_NORMAL + 1 == TEXTURE_SLOT_NORMAL);

} // namespace vkrt::gpu

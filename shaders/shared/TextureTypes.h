// GPU texture records (src/texture/TextureAtlas.h packs them). Every texture
// of a scene, every mip level, lives in ONE storage buffer of 32-bit words
// (`textureTexels`), so a scene's texture count never meets a descriptor
// limit; a table of TextureRecord says where each texture's levels start.
// Layout rule: GLSL `scalar` block layout, as shared/SceneTypes.h; the host
// static_asserts the size (src/gpu/TextureLayout.cpp).
//
// Texel formats (TextureRecord::format), texels row-major, rows top to bottom
// as stored in the file:
//   TEXTURE_FORMAT_RGBA8_SRGB : one word, R | G << 8 | B << 16 | A << 24
//                               (unpackUnorm4x8); RGB sRGB-encoded, A linear.
//   TEXTURE_FORMAT_RGBA8_UNORM: the same word, every channel linear.
//   TEXTURE_FORMAT_RGBA16F    : two words, packHalf2x16(R, G), packHalf2x16(B, A).
#ifndef VKRT_SHARED_TEXTURE_TYPES_H
#define VKRT_SHARED_TEXTURE_TYPES_H
#include "Bindings.h"
#include "Interop.h"

VKRT_BEGIN_NAMESPACE

// TextureRecord::wrapU / wrapV, applied to texel indices (lib/texture.glsl).
VKRT_CONSTANT(uint, TEXTURE_WRAP_REPEAT, 0) // i mod n
VKRT_CONSTANT(uint, TEXTURE_WRAP_CLAMP, 1)  // clamp(i, 0, n - 1): the edge texel continues
VKRT_CONSTANT(uint, TEXTURE_WRAP_MIRROR, 2) // reflected at each edge, period 2n (GL_MIRRORED_REPEAT)

// TextureRecord::format
VKRT_CONSTANT(uint, TEXTURE_FORMAT_RGBA8_SRGB, 0)
VKRT_CONSTANT(uint, TEXTURE_FORMAT_RGBA8_UNORM, 1)
VKRT_CONSTANT(uint, TEXTURE_FORMAT_RGBA16F, 2)

// The largest side accepted (2^14 texels), hence at most 15 mip levels.
VKRT_CONSTANT(uint, TEXTURE_MAX_SIZE, 16384)
VKRT_CONSTANT(uint, TEXTURE_MAX_LEVELS, 15)

// Placeholder binding indices just past the render kernels' own: the lead
// moves them into shared/Bindings.h when the render kernels bind textures.
VKRT_CONSTANT(uint, BINDING_TEXTURE_TEXELS, BINDING_COUNT)      // uint textureTexels[]
VKRT_CONSTANT(uint, BINDING_TEXTURE_RECORDS, BINDING_COUNT + 1) // TextureRecord textureRecords[]

/// One texture as the kernels see it. Level l is max(1, width >> l) x
/// max(1, height >> l) texels starting at word levelOffset[l] of textureTexels
/// (entries at and past `levels` are 0).
struct TextureRecord {
    uint width;
    uint height;
    uint levels;
    uint format;
    uint wrapU;
    uint wrapV;
    uint levelOffset[TEXTURE_MAX_LEVELS];
};

VKRT_END_NAMESPACE

#endif

// The two buffers lib/texture.glsl reads (shared/TextureTypes.h), declared only
// in variants with textures. Needs GL_EXT_scalar_block_layout.
#ifndef VKRT_TEXTURE_BINDINGS_GLSL
#define VKRT_TEXTURE_BINDINGS_GLSL

#include "shared/TextureTypes.h"

#ifdef VKRT_HAS_TEXTURES
layout(scalar, binding = BINDING_TEXTURE_TEXELS) readonly buffer TextureTexelBlock { uint textureTexels[]; };
layout(scalar, binding = BINDING_TEXTURE_RECORDS) readonly buffer TextureRecordBlock
{
    TextureRecord textureRecords[];
};
#endif

#endif

// The two buffers lib/texture.glsl reads (shared/TextureTypes.h), declared only
// in variants with textures. Needs GL_EXT_scalar_block_layout, and with
// VKRT_TEXTURE_CHUNKS GL_EXT_nonuniform_qualifier.
//
// textureWord(w) is word w of the texels' one address space. A scene whose
// texels fit one storage buffer binds them as one array (read through its
// device address in the render kernels, lib/scene_buffers.glsl); a larger one (render/KernelVariant: VKRT_TEXTURE_CHUNKS buffers of
// 2^VKRT_TEXTURE_CHUNK_SHIFT words, texture/TextureAtlas.h) binds an array of
// buffers, word w at index w & (2^shift - 1) of buffer w >> shift. Lanes of
// one subgroup may read different buffers: the index is nonuniformEXT.
#ifndef VKRT_TEXTURE_BINDINGS_GLSL
#define VKRT_TEXTURE_BINDINGS_GLSL

#include "shared/TextureTypes.h"
#include "lib/scene_buffers.glsl"

#ifdef VKRT_HAS_TEXTURES
#ifdef VKRT_TEXTURE_CHUNKS
layout(scalar, binding = BINDING_TEXTURE_TEXELS) readonly buffer TextureTexelBlock
{
    uint words[];
}
textureTexelChunks[VKRT_TEXTURE_CHUNKS];

uint textureWord(uint word)
{
    const uint mask = (1u << VKRT_TEXTURE_CHUNK_SHIFT) - 1u;
    return textureTexelChunks[nonuniformEXT(word >> VKRT_TEXTURE_CHUNK_SHIFT)].words[word & mask];
}
#else
VKRT_READ_BUFFER(BINDING_TEXTURE_TEXELS, TextureTexelBlock, uint, textureTexels)
#define textureTexels VKRT_READ_ITEMS(BINDING_TEXTURE_TEXELS, TextureTexelBlock, textureTexels)
#define textureWord(word) textureTexels[word]
#endif
VKRT_READ_BUFFER(BINDING_TEXTURE_RECORDS, TextureRecordBlock, TextureRecord, textureRecords)
#define textureRecords VKRT_READ_ITEMS(BINDING_TEXTURE_RECORDS, TextureRecordBlock, textureRecords)
#endif

#endif

// The two buffers lib/texture.glsl reads (shared/TextureTypes.h), declared only
// in variants with textures. Needs GL_EXT_scalar_block_layout, and with
// VKRT_TEXTURE_CHUNKS GL_EXT_nonuniform_qualifier.
//
// textureWord(w) is word w of the texels' one address space. A scene whose
// texels fit one storage buffer binds them as one array, as it always did;
// a larger one (render/KernelVariant: VKRT_TEXTURE_CHUNKS buffers of
// 2^VKRT_TEXTURE_CHUNK_SHIFT words, texture/TextureAtlas.h) binds an array of
// buffers, word w at index w & (2^shift - 1) of buffer w >> shift. Lanes of
// one subgroup may read different buffers: the index is nonuniformEXT.
#ifndef VKRT_TEXTURE_BINDINGS_GLSL
#define VKRT_TEXTURE_BINDINGS_GLSL

#include "shared/TextureTypes.h"

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
layout(scalar, binding = BINDING_TEXTURE_TEXELS) readonly buffer TextureTexelBlock { uint textureTexels[]; };
#ifdef VKRT_TEXEL_ADDRESS
// The render kernels read the words through the buffer's device address
// (SceneUniforms::texelAddress): lavapipe compiles a storage-buffer load
// whose offset differs between lanes into a loop over the lanes with a
// bounds check, a device-address load into one gather. ClearCoatTest's
// cold start on Mesa 25: 20.1 -> 14.8 s (docs/performance.md, "Staged
// kernels"). The probe kernels keep the storage buffer.
layout(buffer_reference, scalar, buffer_reference_align = 4) readonly buffer TexelWords { uint words[]; };
#define textureWord(word) TexelWords(u.texelAddress).words[word]
#else
// A macro, not a function: the one-buffer kernels' SPIR-V stays what it was.
#define textureWord(word) textureTexels[word]
#endif
#endif
layout(scalar, binding = BINDING_TEXTURE_RECORDS) readonly buffer TextureRecordBlock
{
    TextureRecord textureRecords[];
};
#endif

#endif

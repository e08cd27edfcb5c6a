// GPU texture records (src/texture/TextureAtlas.h packs them). Every texture
// of a scene, every mip level, lives in ONE address space of 32-bit words, so
// a scene's texture count never meets a descriptor limit; a table of
// TextureRecord says at which word each texture's levels start. The words are
// one storage buffer (`textureTexels`) unless they exceed the device's
// maxStorageBufferRange; then they are split into chunks of 2^k words, one
// buffer each (lib/texture_bindings.glsl, VKRT_TEXTURE_CHUNKS).
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

// TextureRecord::filters, bits (glTF's sampler magFilter and minFilter;
// lib/texture.glsl's sampleTexture). 0 is vkrt's default, glTF's LINEAR and
// LINEAR_MIPMAP_LINEAR: bilinear when magnified, trilinear when minified.
VKRT_CONSTANT(uint, TEXTURE_FILTER_MAG_NEAREST, 1) // magnified: the nearest texel of level 0
VKRT_CONSTANT(uint, TEXTURE_FILTER_MIN_NEAREST, 2) // minified: the nearest texel within a level
VKRT_CONSTANT(uint, TEXTURE_FILTER_MIP_NEAREST, 4) // minified: the nearest level (round(lod)), not two blended
VKRT_CONSTANT(uint, TEXTURE_FILTER_MIP_NONE, 8)    // minified: level 0 alone (no mip maps)

// TextureRecord::format
VKRT_CONSTANT(uint, TEXTURE_FORMAT_RGBA8_SRGB, 0)
VKRT_CONSTANT(uint, TEXTURE_FORMAT_RGBA8_UNORM, 1)
VKRT_CONSTANT(uint, TEXTURE_FORMAT_RGBA16F, 2)

// The largest side accepted (2^14 texels), hence at most 15 mip levels.
VKRT_CONSTANT(uint, TEXTURE_MAX_SIZE, 16384)
VKRT_CONSTANT(uint, TEXTURE_MAX_LEVELS, 15)

// The bindings (BINDING_TEXTURE_TEXELS: uint textureTexels[], or an array of
// chunks of it,
// BINDING_TEXTURE_RECORDS: TextureRecord textureRecords[],
// BINDING_MATERIAL_TEXTURES: MaterialTextures materialTextures[]) are in
// shared/Bindings.h.

/// One texture as the kernels see it. Level l is max(1, width >> l) x
/// max(1, height >> l) texels starting at word levelOffset[l] of the texel
/// words (entries at and past `levels` are 0). A level may straddle two
/// chunks; a texel never does (chunks hold an even number of words).
struct TextureRecord {
    uint width;
    uint height;
    uint levels;
    uint format;
    uint wrapU;
    uint wrapV;
    uint filters; // TEXTURE_FILTER_* bits
    uint levelOffset[TEXTURE_MAX_LEVELS];
};

// A material parameter without a texture.
VKRT_CONSTANT(uint, NO_TEXTURE, 4294967295u)

/// One textured parameter of a material: texture `record`, looked up at
/// uv * scale. Colours use the texel's rgb, scalars its component `channel`
/// (0 = r ... 3 = a). The texel multiplies the material's constant (which the
/// scene sets to 1, and a glTF file to its factor).
// The lookup is at uv' = R (uv * scale) + offset, R the rotation whose
// (cos, sin) is `rotation`: [c s; -s c] (glTF KHR_texture_transform).
struct TextureSlot {
    uint record; // NO_TEXTURE: the constant alone
    uint channel;
    vec2 scale;
    vec2 offset;
    vec2 rotation;
    uint texCoord; // the surface's uv set it reads: 0, or 1 (a mesh's second set, glTF TEXCOORD_1)
};

// MaterialTextures::slots, by parameter:
VKRT_CONSTANT(uint, TEXTURE_SLOT_COLOR, 0)     // diffuse / albedo / base_color (Material::diffuse)
VKRT_CONSTANT(uint, TEXTURE_SLOT_SPECULAR, 1)  // specular / reflectance / tint (Material::specular)
VKRT_CONSTANT(uint, TEXTURE_SLOT_ROUGHNESS, 2) // perceptual roughness: alpha scales by texel^2
VKRT_CONSTANT(uint, TEXTURE_SLOT_METALLIC, 3)  // pbr metallic
// The pbr material's glTF extension layers (variants with VKRT_PBR_LAYERS):
VKRT_CONSTANT(uint, TEXTURE_SLOT_SPECULAR_FACTOR, 4)        // KHR_materials_specular specularTexture (A)
VKRT_CONSTANT(uint, TEXTURE_SLOT_SHEEN_COLOR, 5)            // KHR_materials_sheen sheenColorTexture (sRGB)
VKRT_CONSTANT(uint, TEXTURE_SLOT_SHEEN_ROUGHNESS, 6)        // sheenRoughnessTexture (A)
VKRT_CONSTANT(uint, TEXTURE_SLOT_CLEARCOAT, 7)              // KHR_materials_clearcoat clearcoatTexture (R)
VKRT_CONSTANT(uint, TEXTURE_SLOT_CLEARCOAT_ROUGHNESS, 8)    // clearcoatRoughnessTexture (G): alpha scales by texel^2
VKRT_CONSTANT(uint, TEXTURE_SLOT_TRANSMISSION, 9)           // KHR_materials_transmission transmissionTexture (R)
VKRT_CONSTANT(uint, TEXTURE_SLOT_IRIDESCENCE, 10)           // KHR_materials_iridescence iridescenceTexture (R)
VKRT_CONSTANT(uint, TEXTURE_SLOT_IRIDESCENCE_THICKNESS, 11) // iridescenceThicknessTexture (G): mixes the
                                                            // thickness from its minimum (0) to its maximum (1)
VKRT_CONSTANT(uint, TEXTURE_SLOT_ANISOTROPY, 12)       // KHR_materials_anisotropy anisotropyTexture: RG the
                                                       // direction in the tangent frame ((d + 1) / 2), B strength
VKRT_CONSTANT(uint, TEXTURE_SLOT_CLEARCOAT_NORMAL, 13) // clearcoatNormalTexture: the coat's own normal map
VKRT_CONSTANT(uint, TEXTURE_SLOT_NORMAL, 14)           // tangent-space normal map (rgb = (n + 1) / 2)
VKRT_CONSTANT(uint, TEXTURE_SLOT_EMISSION, 15) // emitted radiance (glTF emissiveTexture, sRGB): read by the
                                               // emitters (lib/emitters.glsl), not by texturedMaterial
VKRT_CONSTANT(uint, TEXTURE_SLOT_COUNT, 16)

/// The textures of one material (one per Material, same index).
struct MaterialTextures {
    TextureSlot slots[TEXTURE_SLOT_COUNT];
    float normalStrength; // a normal map's tangent-plane components scale by this (glTF normalTexture.scale)
    float clearcoatNormalStrength; // ... the coat's normal map's (clearcoatNormalTexture.scale)
};

VKRT_END_NAMESPACE

#endif

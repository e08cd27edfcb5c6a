// Image texture lookups from the packed texel words (shared/TextureTypes.h,
// src/texture/TextureAtlas.h). Include lib/texture_bindings.glsl first, with
// VKRT_HAS_TEXTURES defined.
//
// Conventions:
// - uv follows OBJ (and OpenGL): u runs left to right, v from the BOTTOM of the
//   image as stored in the file up to its top, so uv (0, 0) is the bottom-left
//   corner of the image and (0, 1) its top-left. glTF's uvs start at the top,
//   but assimp converts them on import (its glTF importer stores 1 - v; vkrt
//   does not ask for aiProcess_FlipUVs, src/mesh/MeshLoader.cpp), so every
//   mesh format arrives in this convention (tests/texture: TextureUv*).
// - Texel (x, y) of a w x h level (row y = 0 the file's top row) has its
//   centre at uv ((x + 0.5) / w, 1 - (y + 0.5) / h): every level spans the
//   same uv square.
// - Filtering happens on linear values: 8-bit sRGB texels are decoded one by
//   one (exact piecewise sRGB EOTF) before they are weighted.
// - Wrap modes apply to texel indices, on each axis separately:
//   TEXTURE_WRAP_REPEAT (period n), _CLAMP (edge texel continues), _MIRROR
//   (period 2n, edge texels doubled as in GL_MIRRORED_REPEAT).
// - Filters (TextureRecord::filters, glTF's sampler filters): bilinear when
//   magnified and trilinear when minified unless the record says nearest
//   texels, the nearest mip level, or level 0 only (sampleTexture).
#ifndef VKRT_TEXTURE_GLSL
#define VKRT_TEXTURE_GLSL

#include "lib/texture_bindings.glsl"

/// The exact sRGB EOTF (IEC 61966-2-1).
vec3 srgbToLinear(vec3 encoded)
{
    vec3 low = encoded / 12.92;
    vec3 high = pow((encoded + 0.055) / 1.055, vec3(2.4));
    return mix(high, low, lessThanEqual(encoded, vec3(0.04045)));
}

/// Texel index i of a side of n texels after the wrap mode; i >= -n - 1 (see
/// wrapTextureCoordinate). The last clamp keeps even a NaN uv inside the level.
int wrapTexelIndex(int i, int n, uint wrap)
{
    if (wrap == TEXTURE_WRAP_MIRROR) {
        int j = (i + 2 * n) % (2 * n);
        i = j < n ? j : 2 * n - 1 - j;
    } else if (wrap == TEXTURE_WRAP_REPEAT) {
        i = (i + n) % n;
    }
    return clamp(i, 0, n - 1);
}

/// A texture coordinate (in units of the image, y down) moved by whole
/// periods of its wrap mode into a small range, so texel indices stay
/// non-negative after one period is added (GLSL's % is undefined for negative
/// operands) and never overflow an int; the lookup is unchanged.
float wrapTextureCoordinate(float s, uint wrap)
{
    if (wrap == TEXTURE_WRAP_REPEAT)
        return s - floor(s);
    if (wrap == TEXTURE_WRAP_MIRROR)
        return s - 2.0 * floor(0.5 * s);
    return clamp(s, -1.0, 2.0);
}

/// Texel (x, y) of a level starting at word `offset` with rows of `width`, linear RGBA.
vec4 fetchTexel(uint format, uint offset, uint width, uint x, uint y)
{
    uint index = y * width + x;
    if (format == TEXTURE_FORMAT_RGBA16F) {
        uint word = offset + 2u * index;
        return vec4(unpackHalf2x16(textureWord(word)), unpackHalf2x16(textureWord(word + 1u)));
    }
    vec4 texel = unpackUnorm4x8(textureWord(offset + index));
    if (format == TEXTURE_FORMAT_RGBA8_SRGB)
        texel.rgb = srgbToLinear(texel.rgb);
    return texel;
}

/// Lookup in one mip level: the nearest texel, or bilinear between the four nearest.
/// The taps are fetched in a loop (one pass for the nearest texel, four for
/// bilinear) so that a copy of this function inlines one texel fetch, not
/// four: lavapipe inlines every call, and each fetch (two wrapped indices, a
/// load and a decode by format) costs the driver's compile time in every
/// kernel that reads a texture (docs/performance.md, "One evaluation site").
/// The bilinear weights are applied after the loop, as a straight mix of the
/// four texels.
vec4 filterTextureLevel(uint textureIndex, vec2 uv, uint level, bool nearest)
{
    uint format = textureRecords[textureIndex].format;
    uint offset = textureRecords[textureIndex].levelOffset[level];
    ivec2 size = ivec2(max(uvec2(1u), uvec2(textureRecords[textureIndex].width, textureRecords[textureIndex].height)
                                          >> level));
    uint wrapU = textureRecords[textureIndex].wrapU, wrapV = textureRecords[textureIndex].wrapV;
    // Continuous texel coordinates, y down from the top row: texel i spans [i, i + 1).
    vec2 image = vec2(wrapTextureCoordinate(uv.x, wrapU), wrapTextureCoordinate(1.0 - uv.y, wrapV));
    uint w = uint(size.x);
    // Nearest: the texel containing the point. Bilinear: texel centres at integers.
    vec2 st = nearest ? image * vec2(size) : image * vec2(size) - 0.5;
    vec2 base = floor(st);
    ivec2 i0 = ivec2(base);
    vec4 topLeft, topRight, bottomLeft, bottomRight;
    uint taps = nearest ? 1u : 4u;
    for (uint tap = 0u; tap < taps; ++tap) {
        ivec2 at = i0 + ivec2(tap & 1u, tap >> 1u);
        vec4 texel = fetchTexel(format, offset, w, uint(wrapTexelIndex(at.x, size.x, wrapU)),
                                uint(wrapTexelIndex(at.y, size.y, wrapV)));
        if (tap == 0u)
            topLeft = texel;
        else if (tap == 1u)
            topRight = texel;
        else if (tap == 2u)
            bottomLeft = texel;
        else
            bottomRight = texel;
    }
    if (nearest)
        return topLeft;
    vec2 f = st - base;
    return mix(mix(topLeft, topRight, f.x), mix(bottomLeft, bottomRight, f.x), f.y);
}

/// Lookup in one mip level with the record's magnification filter (bilinear
/// unless TEXTURE_FILTER_MAG_NEAREST): for lookups without a footprint, read
/// at level 0 as a magnified texture is (the emitters', the alpha test's).
vec4 sampleTextureLevel(uint textureIndex, vec2 uv, uint level)
{
    bool nearest = (textureRecords[textureIndex].filters & TEXTURE_FILTER_MAG_NEAREST) != 0u;
    return filterTextureLevel(textureIndex, uv, level, nearest);
}

/// Lookup at level of detail `lod`, log2 of the footprint in level-0 texels
/// (see rayConeTextureLod), with the record's filters (shared/TextureTypes.h):
/// - magnified (lod <= 0; NaN counts as 0): level 0, bilinear or nearest;
/// - minified, by default trilinear: levels floor(lod) and floor(lod) + 1
///   mixed by the fraction (lod clamped to levels - 1), bilinear or nearest
///   within each; or the nearest level (round(lod)) alone; or level 0 alone.
/// The filters only choose the level(s), the in-level filter and the blend:
/// filterTextureLevel is called at one site, not once per filter mode or
/// level, because lavapipe inlines every call and each copy of it (four
/// texel fetches, each decoded by format) costs the driver's compile time.
vec4 sampleTexture(uint textureIndex, vec2 uv, float lod)
{
    uint filters = textureRecords[textureIndex].filters;
    uint level = 0u;
    float blend = 0.0; // weight of level + 1: nonzero only between two levels of a trilinear lookup
    bool nearest;
    if (!(lod > 0.0)) {
        nearest = (filters & TEXTURE_FILTER_MAG_NEAREST) != 0u;
    } else {
        nearest = (filters & TEXTURE_FILTER_MIN_NEAREST) != 0u;
        if ((filters & TEXTURE_FILTER_MIP_NONE) == 0u) {
            lod = min(lod, float(textureRecords[textureIndex].levels - 1u));
            if ((filters & TEXTURE_FILTER_MIP_NEAREST) != 0u) {
                level = uint(floor(lod + 0.5));
            } else {
                float level0 = floor(lod);
                level = uint(level0);
                blend = lod - level0;
            }
        }
    }
    // The finer level, then (trilinear) the coarser one, from one call site:
    // a loop whose passes the compiler cannot count, so it keeps one copy.
    vec4 fine = vec4(0.0);
    bool coarse = false;
    for (;;) {
        vec4 texel = filterTextureLevel(textureIndex, uv, coarse ? level + 1u : level, nearest);
        if (coarse)
            return mix(fine, texel, blend);
        if (blend == 0.0)
            return texel;
        fine = texel;
        coarse = true;
    }
    return fine; // not reached
}

/// Mip level from a ray cone (Akenine-Möller et al. 2019, "Texture Level of
/// Detail Strategies for Real-Time Ray Tracing", Ray Tracing Gems ch. 20,
/// ray cones): lod = 0.5 log2(w h * uvArea / worldArea) + log2(coneWidth / |cos|),
/// where w x h is level 0's size, uvAreaPerWorldArea the triangle's uv area
/// over its world area (the texel density term Delta), coneWidth the cone's
/// width at the hit and cosTheta the cosine between the ray and the normal.
/// |cos| is kept above 1e-4 so a grazing hit gives a large, finite lod; a
/// degenerate uv mapping (0 area) gives -infinity, which sampleTexture treats
/// as level 0. (Not called textureLod: GLSL has a built-in of that name.)
float rayConeTextureLod(uint textureIndex, float coneWidth, float cosTheta, float uvAreaPerWorldArea)
{
    float texels = float(textureRecords[textureIndex].width) * float(textureRecords[textureIndex].height);
    return 0.5 * log2(texels * uvAreaPerWorldArea) + log2(coneWidth / max(abs(cosTheta), 1e-4));
}

#endif

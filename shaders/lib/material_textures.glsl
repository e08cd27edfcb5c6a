// Textured material parameters (shared/TextureTypes.h: MaterialTextures):
// each textured slot's texel multiplies the material's constant at the hit's
// uv, filtered over the ray cone's footprint there, and a normal map tilts the
// shading normal in the hit's tangent frame. Variants with textures only.
//
// Footprint: a cone of the camera's pixel angle, its width the path length so
// far times that angle (Akenine-Möller et al. 2019 for the camera ray; after a
// bounce the cone keeps the camera's spread, as pbrt-v4 approximates ray
// differentials after the first hit: no blur beyond what a camera ray of the
// same length would have).
//
// The cone of one pixel is right for one sample per pixel; jittered samples
// already average over the pixel, and filtering each one over the whole
// pixel again blurs the converged image by about a pixel (textured test
// charts came out visibly softer than Cycles'). So a jittered sample's cone
// is 1/8 of the pixel's (pbrt-v4's floor for its scaled camera ray
// differentials): the converged image keeps the texture's own detail, and
// every sample of a pixel filters over the same footprint. That last part
// matters: with a cone that narrowed with the sample's index (1/sqrt(n), as
// once here), a 64-sample image was the texture filtered wider than a
// 1024-sample one, an error no variance estimate sees; it was most of the
// error per sample on textured models (docs/performance.md, round four).
#ifndef VKRT_MATERIAL_TEXTURES_GLSL
#define VKRT_MATERIAL_TEXTURES_GLSL

#include "lib/texture.glsl"

const float JITTERED_CONE_SCALE = 1.0 / 8.0;

// The angle one pixel subtends at the image centre, narrowed for jittered samples (above).
float pixelSpreadAngle()
{
    float scale = (u.flags & RENDER_FLAG_JITTER) != 0u ? JITTERED_CONE_SCALE : 1.0;
    return scale * 2.0 * length(u.cameraUp) / float(u.height);
}

// A slot's lookup coordinates of a surface uv: R (uv * scale) + offset
// (src/render/EmissionPower.cpp: slotUv, the host's copy).
vec2 slotUv(TextureSlot slot, vec2 uv)
{
    vec2 s = uv * slot.scale;
    return vec2(slot.rotation.x * s.x + slot.rotation.y * s.y, slot.rotation.x * s.y - slot.rotation.y * s.x) +
           slot.offset;
}

vec4 lookupSlot(TextureSlot slot, SurfaceHit hit, float coneWidth, float cosTheta)
{
    vec2 uv = hit.uv;
    float uvDensity = hit.uvDensity;
#ifdef VKRT_HAS_MESH_UVS1
    if (slot.texCoord == 1u) {
        uv = hit.uv1;
        uvDensity = hit.uvDensity1;
    }
#endif
    float density = uvDensity * abs(slot.scale.x * slot.scale.y);
    float lod = rayConeTextureLod(slot.record, coneWidth, cosTheta, density);
    return sampleTexture(slot.record, slotUv(slot, uv), lod);
}

#ifdef VKRT_HAS_EMISSION_TEXTURES
// The emission texture of material `material` at surface uv `uv`, linear RGB
// (>= 0; an HDR texture may exceed 1). Always level 0 (bilinear), whether the
// point was hit by a ray or sampled on the emitter: the two estimates MIS
// weighs against each other must see the same radiance there.
vec3 emissionTexel(uint material, vec2 uv)
{
    TextureSlot slot = materialTextures[material].slots[TEXTURE_SLOT_EMISSION];
    if (slot.record == NO_TEXTURE)
        return vec3(1.0);
    return max(sampleTextureLevel(slot.record, slotUv(slot, uv), 0u).rgb, vec3(0.0));
}
#endif

float channelOf(vec4 texel, uint channel) { return clamp(texel[channel], 0.0, 1.0); }

#ifdef VKRT_HAS_NORMAL_MAPS
// A tangent-space normal map's texel (rgb = (n + 1) / 2, n.xy scaled by
// `strength`) in the frame of the shading normal and the hit's tangent
// (Gram-Schmidt, MikkTSpace's convention: bitangent = w cross(n, t)). Keeps
// the unmapped normal where the frame or the result is degenerate or would
// face away from the geometric surface.
vec3 normalMapped(SurfaceHit hit, vec3 texel, float strength)
{
    vec3 n = hit.shading;
    vec3 local = 2.0 * texel - 1.0;
    local.xy *= strength;
    vec3 t = hit.tangent.xyz - n * dot(n, hit.tangent.xyz);
    float tLength = length(t);
    if (!(tLength > 1e-6))
        return n;
    t /= tLength;
    vec3 b = hit.tangent.w * cross(n, t);
    vec3 mapped = local.x * t + local.y * b + local.z * n;
    float len = length(mapped);
    if (!(len > 0.0) || isinf(len))
        return n;
    mapped /= len;
    return dot(mapped, hit.normal) > 1e-4 ? mapped : n;
}
#endif

#ifdef VKRT_PBR_ANISOTROPY
// KHR_materials_anisotropy at a hit: the direction `texel` encodes in the
// tangent frame (rg = (d + 1) / 2; b scales the strength), turned by the
// material's rotation and scaled by its strength (m.anisotropy.xy = strength x
// (cos, sin) of the rotation: a complex product), taken to world space in the
// frame of the hit's tangent about the unmapped shading normal n, as the
// specification's TBN. The base's alpha along it becomes mix(alpha, 1,
// strength^2) (alphaY keeps alpha); m.anisotropy becomes the world direction,
// or zero where the lobe stays isotropic.
Material withAnisotropy(Material m, SurfaceHit hit, vec3 n, vec3 texel)
{
    vec2 d = 2.0 * texel.xy - 1.0;
    float dLength = length(d);
    d = dLength > 0.0 ? d / dLength : vec2(1.0, 0.0);
    vec2 r = m.anisotropy.xy * clamp(texel.z, 0.0, 1.0);
    vec2 turned = vec2(r.x * d.x - r.y * d.y, r.x * d.y + r.y * d.x);
    float strength = min(length(turned), 1.0);
    vec3 t = hit.tangent.xyz - n * dot(n, hit.tangent.xyz);
    float tLength = length(t);
    m.anisotropy = vec3(0.0);
    if (!(strength > 0.0) || !(tLength > 1e-6))
        return m;
    t /= tLength;
    vec3 b = hit.tangent.w * cross(n, t);
    m.anisotropy = normalize(turned.x * t + turned.y * b);
    m.alphaX = mix(m.alphaY, 1.0, strength * strength);
    return m;
}
#endif

// The material at this hit: `m` with its textured parameters applied, and the
// hit's shading normal normal-mapped. `pathLength` is the distance travelled
// from the camera to this hit.
//
// One lookup for all slots, in a loop that is not unrolled: lavapipe inlines
// every call, and a lookup (two mip levels, each texel decoded by format)
// inlined once per slot multiplies the driver's compile time
// (docs/performance.md, round four). Its passes count against Mesa 22's loop
// budget like every loop's.
Material texturedMaterial(Material m, inout SurfaceHit hit, vec3 dir, float pathLength)
{
    float coneWidth = pixelSpreadAngle() * pathLength;
#ifdef VKRT_ORTHOGRAPHIC
    if ((u.flags & RENDER_FLAG_ORTHOGRAPHIC) != 0u)
        coneWidth = pixelSpreadAngle(); // parallel rays: one pixel's width at any distance
#endif
    float cosTheta = dot(dir, hit.normal);
    // The emission slot (last) is the emitters' (emissionTexel), not the BSDF's;
    // the pbr layers' slots (before the normal map's) only where the variant has them.
#ifdef VKRT_PBR_LAYERS
    const uint layerSlots = TEXTURE_SLOT_NORMAL - TEXTURE_SLOT_SPECULAR_FACTOR;
#else
    const uint layerSlots = 0u;
#endif
#ifdef VKRT_HAS_NORMAL_MAPS
    const uint slots = TEXTURE_SLOT_SPECULAR_FACTOR + layerSlots + 1u;
#else
    const uint slots = TEXTURE_SLOT_SPECULAR_FACTOR + layerSlots;
#endif
#ifdef VKRT_PBR_LAYERS
    vec3 anisotropyTexel = vec3(1.0, 0.5, 1.0); // without a texture: along the tangent, the full strength
#endif
#ifdef VKRT_PBR_ANISOTROPY
    vec3 unmapped = hit.shading;
#endif
    [[dont_unroll]] for (uint i = 0u; i < slots; ++i) {
        ++g_loopIterations;
        uint k = i < TEXTURE_SLOT_SPECULAR_FACTOR + layerSlots ? i : TEXTURE_SLOT_NORMAL;
        // Slots are read one by one: copying the whole MaterialTextures (a
        // struct with an array) out of the buffer makes glslang emit invalid SPIR-V.
        TextureSlot slot = materialTextures[hit.material].slots[k];
        if (slot.record == NO_TEXTURE)
            continue;
        vec4 texel = lookupSlot(slot, hit, coneWidth, cosTheta);
        if (k == TEXTURE_SLOT_COLOR) {
            m.diffuse *= clamp(texel.rgb, 0.0, 1.0);
        } else if (k == TEXTURE_SLOT_SPECULAR) {
            m.specular *= clamp(texel.rgb, 0.0, 1.0);
        } else if (k == TEXTURE_SLOT_ROUGHNESS) {
            // alpha = roughness^2: the texel's roughness scales both alphas by its square.
            float r = channelOf(texel, slot.channel);
            m.alphaX = max(m.alphaX * r * r, MIN_GGX_ALPHA);
            m.alphaY = max(m.alphaY * r * r, MIN_GGX_ALPHA);
        } else if (k == TEXTURE_SLOT_METALLIC) {
            m.metallic *= channelOf(texel, slot.channel);
        }
#ifdef VKRT_PBR_LAYERS
        else if (k == TEXTURE_SLOT_SPECULAR_FACTOR) {
            m.specularFactor *= channelOf(texel, slot.channel);
        }
#ifdef VKRT_PBR_SHEEN
        else if (k == TEXTURE_SLOT_SHEEN_COLOR) {
            m.sheenColor *= clamp(texel.rgb, 0.0, 1.0);
        } else if (k == TEXTURE_SLOT_SHEEN_ROUGHNESS) {
            m.sheenRoughness *= channelOf(texel, slot.channel);
        }
#endif
#ifdef VKRT_PBR_CLEARCOAT
        else if (k == TEXTURE_SLOT_CLEARCOAT) {
            m.clearcoat *= channelOf(texel, slot.channel);
        } else if (k == TEXTURE_SLOT_CLEARCOAT_ROUGHNESS) {
            float r = channelOf(texel, slot.channel);
            m.clearcoatAlpha = max(m.clearcoatAlpha * r * r, MIN_GGX_ALPHA);
        }
#endif
        else if (k == TEXTURE_SLOT_TRANSMISSION) {
            m.transmission *= channelOf(texel, slot.channel);
        } else if (k == TEXTURE_SLOT_IRIDESCENCE) {
            m.iridescence *= channelOf(texel, slot.channel);
        } else if (k == TEXTURE_SLOT_IRIDESCENCE_THICKNESS) {
            m.iridescenceThickness = mix(m.iridescenceThicknessMin, m.iridescenceThickness, channelOf(texel, slot.channel));
        } else if (k == TEXTURE_SLOT_ANISOTROPY) {
            anisotropyTexel = texel.rgb;
        }
#ifdef VKRT_HAS_NORMAL_MAPS
        else if (k == TEXTURE_SLOT_CLEARCOAT_NORMAL) {
#ifdef VKRT_PBR_CLEARCOAT
            // Before the base's normal map (a later slot) has tilted hit.shading.
            m.clearcoatNormal = normalMapped(hit, texel.rgb, materialTextures[hit.material].clearcoatNormalStrength);
#endif
        }
#endif
#endif
#ifdef VKRT_HAS_NORMAL_MAPS
        else {
#ifdef VKRT_PBR_CLEARCOAT
            // KHR_materials_clearcoat: a coat without a normal map of its own
            // keeps the normal the base's map does not tilt.
            if (m.clearcoat > 0.0 && m.clearcoatNormal == vec3(0.0))
                m.clearcoatNormal = hit.shading;
#endif
            hit.shading = normalMapped(hit, texel.rgb, materialTextures[hit.material].normalStrength);
        }
#endif
    }
#ifdef VKRT_PBR_ANISOTROPY
    m = withAnisotropy(m, hit, unmapped, anisotropyTexel);
#endif
    return m;
}

#endif

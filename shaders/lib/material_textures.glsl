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
#ifndef VKRT_MATERIAL_TEXTURES_GLSL
#define VKRT_MATERIAL_TEXTURES_GLSL

#include "lib/texture.glsl"

// The angle one pixel subtends at the image centre.
float pixelSpreadAngle() { return 2.0 * length(u.cameraUp) / float(u.height); }

vec4 lookupSlot(TextureSlot slot, SurfaceHit hit, float coneWidth, float cosTheta)
{
    float density = hit.uvDensity * abs(slot.scale.x * slot.scale.y);
    float lod = rayConeTextureLod(slot.record, coneWidth, cosTheta, density);
    vec2 s = hit.uv * slot.scale;
    vec2 uv = vec2(slot.rotation.x * s.x + slot.rotation.y * s.y, slot.rotation.x * s.y - slot.rotation.y * s.x);
    return sampleTexture(slot.record, uv + slot.offset, lod);
}

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

// The material at this hit: `m` with its textured parameters applied, and the
// hit's shading normal normal-mapped. `pathLength` is the distance travelled
// from the camera to this hit.
Material texturedMaterial(Material m, inout SurfaceHit hit, vec3 dir, float pathLength)
{
    // Slots are read one by one: copying the whole MaterialTextures (a struct
    // with an array) out of the buffer makes glslang emit invalid SPIR-V.
    float coneWidth = pixelSpreadAngle() * pathLength;
    float cosTheta = dot(dir, hit.normal);
    TextureSlot slot = materialTextures[hit.material].slots[TEXTURE_SLOT_COLOR];
    if (slot.record != NO_TEXTURE)
        m.diffuse *= clamp(lookupSlot(slot, hit, coneWidth, cosTheta).rgb, 0.0, 1.0);
    slot = materialTextures[hit.material].slots[TEXTURE_SLOT_SPECULAR];
    if (slot.record != NO_TEXTURE)
        m.specular *= clamp(lookupSlot(slot, hit, coneWidth, cosTheta).rgb, 0.0, 1.0);
    slot = materialTextures[hit.material].slots[TEXTURE_SLOT_ROUGHNESS];
    if (slot.record != NO_TEXTURE) {
        // alpha = roughness^2: the texel's roughness scales both alphas by its square.
        float r = channelOf(lookupSlot(slot, hit, coneWidth, cosTheta), slot.channel);
        m.alphaX = max(m.alphaX * r * r, MIN_GGX_ALPHA);
        m.alphaY = max(m.alphaY * r * r, MIN_GGX_ALPHA);
    }
    slot = materialTextures[hit.material].slots[TEXTURE_SLOT_METALLIC];
    if (slot.record != NO_TEXTURE)
        m.metallic *= channelOf(lookupSlot(slot, hit, coneWidth, cosTheta), slot.channel);
#ifdef VKRT_HAS_NORMAL_MAPS
    slot = materialTextures[hit.material].slots[TEXTURE_SLOT_NORMAL];
    if (slot.record != NO_TEXTURE)
        hit.shading = normalMapped(hit, lookupSlot(slot, hit, coneWidth, cosTheta).rgb, materialTextures[hit.material].normalStrength);
#endif
    return m;
}

#endif

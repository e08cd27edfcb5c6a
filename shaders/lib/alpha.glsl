// Alpha-tested mesh materials (glTF 2.0 alphaMode MASK and BLEND; variants
// with VKRT_HAS_ALPHA only). Both traversal backends call alphaKeeps at every
// candidate triangle hit of a mesh instance flagged MESH_FLAG_ALPHA, for
// camera, bounce and shadow rays alike, before the hit may count: the own
// BVH walk (lib/shapes/mesh.glsl: traverseMesh) and the driver's ray query
// (lib/ray_query.glsl, which confirms only the candidates kept here).
//
// alpha = MaterialAlpha::alpha (glTF baseColorFactor.a) x the vertex colour's
// A (COLOR_0, where the mesh has it) x the A channel of
// the material's colour texture (its TEXTURE_SLOT_COLOR slot: the same
// texture, uv transform and wrap modes the colour uses), read bilinearly at
// mip level 0: traversal has no ray cone, and the coverage of a cut-out must
// not blur with distance (a blurred mask would move the cut-out's edge).
//   MASK:  a surface where alpha >= cutoff; elsewhere the ray passes on as if
//          nothing were there.
//   BLEND: stochastic transparency: a surface with probability alpha, passed
//          through with probability 1 - alpha. The coin is a hash of the ray
//          (its origin and direction bits), the instance, the triangle and
//          the sample (g_alphaSample): independent between rays and samples,
//          and the same whenever one ray meets one triangle again (a driver
//          may report a candidate twice). A pixel's expected radiance is
//          alpha L_surface + (1 - alpha) L_behind, and a shadow ray through
//          the surface is blocked with probability alpha, so the expected
//          transmittance 1 - alpha is the same for every kind of ray.
#ifndef VKRT_ALPHA_GLSL
#define VKRT_ALPHA_GLSL

#ifdef VKRT_HAS_ALPHA
#include "lib/pcg.glsl"
#ifdef VKRT_HAS_MESH_UVS
#include "lib/texture.glsl"
#endif

VKRT_READ_BUFFER(BINDING_MATERIAL_ALPHA, MaterialAlphaBlock, MaterialAlpha, materialAlpha)
#define materialAlpha VKRT_READ_ITEMS(BINDING_MATERIAL_ALPHA, MaterialAlphaBlock, materialAlpha)

// The sample's part of every BLEND coin (render.comp sets it per sample).
uint g_alphaSample = 0u;

void alphaStartSample(uint pixelIndex, uint frameIndex, uint seed)
{
    g_alphaSample = pcg4d(uvec4(pixelIndex, frameIndex, seed, 0x616c7068u)).x;
}

// A uniform number in [0, 1) for (ray, instance, triangle, sample).
float alphaCoin(Ray r, uint instance, uint triangle)
{
    uvec3 o = floatBitsToUint(r.origin), d = floatBitsToUint(r.dir);
    uvec4 h = pcg4d(uvec4(o.x ^ d.y, o.y ^ d.z, o.z ^ d.x, g_alphaSample));
    h = pcg4d(h ^ uvec4(d.x, d.y, instance, triangle));
    return float(h.x >> 8u) * (1.0 / 16777216.0);
}

// The coverage at barycentrics `bary` (weights of v0, v1, v2) of triangle
// `slot` (its leaf slot) of `mesh`, material `material`.
float alphaAt(Mesh mesh, uint slot, uint material, vec3 bary)
{
    float alpha = materialAlpha[material].alpha;
#ifdef VKRT_HAS_MESH_UVS
    TextureSlot s = materialTextures[material].slots[TEXTURE_SLOT_COLOR];
    if (s.record != NO_TEXTURE) {
        vec2 uv = meshTriangleUv(mesh.firstTriangle + slot, s.texCoord, bary);
        // lib/material_textures.glsl: lookupSlot's transform.
        vec2 st = uv * s.scale;
        vec2 at = vec2(s.rotation.x * st.x + s.rotation.y * st.y, s.rotation.x * st.y - s.rotation.y * st.x);
        alpha *= clamp(sampleTextureLevel(s.record, at + s.offset, 0u).a, 0.0, 1.0);
    }
#endif
#ifdef VKRT_HAS_MESH_COLORS
    // glTF: COLOR_0's alpha multiplies the base colour's too.
    if ((mesh.flags & MESH_FLAG_COLORS) != 0u) {
        MeshColors c = meshColors[mesh.firstTriangle + slot];
        alpha *= clamp(bary.x * c.c0.a + bary.y * c.c1.a + bary.z * c.c2.a, 0.0, 1.0);
    }
#endif
    return alpha;
}

// The material of triangle `slot` (its leaf slot) of `mesh`.
uint alphaMaterial(Mesh mesh, uint slot)
{
    uint material = mesh.material;
#ifdef VKRT_HAS_MESH_MATERIALS
    if ((mesh.flags & MESH_FLAG_MATERIALS) != 0u)
        material = meshMaterials[mesh.firstTriangle + slot];
#endif
    return material;
}

// Whether a candidate hit on triangle `slot` of mesh instance `instance` is a
// surface for the (world-space) ray r.
bool alphaKeeps(Ray r, uint instance, Mesh mesh, uint slot, vec3 bary)
{
    if ((mesh.flags & MESH_FLAG_ALPHA) == 0u)
        return true;
    uint material = alphaMaterial(mesh, slot);
    uint mode = materialAlpha[material].mode;
    if (mode == ALPHA_MODE_OPAQUE)
        return true;
    float alpha = alphaAt(mesh, slot, material, bary);
    if (mode == ALPHA_MODE_MASK)
        return alpha >= materialAlpha[material].cutoff;
    return alphaCoin(r, instance, slot) < alpha;
}

#ifdef VKRT_HAS_EMITTERS
// Light sampling's view of the same coverage (lib/emitters.glsl:
// sampleEmitters): emitter `index` at barycentrics `bary` emits times 1 for
// a triangle light or a triangle of a mesh without alpha-tested materials; for
// an alpha-tested one, MASK's 0 or 1 and BLEND's alpha, the probability that
// a ray reaching that point counts the surface, so that a cut-out's holes do
// not emit and light sampling and BSDF hits (which meet the surface only
// where alphaKeeps does) estimate the same light. The mesh owning an emitter
// is the last one whose firstEmitter is not past it: every mesh record holds
// the running emitter count in firstEmitter (render/GpuScene.cpp), so the
// values never decrease and a mesh without emitters shares its value only
// with the records after it; a binary search finds it in O(log meshes).
float emitterCoverage(uint index, vec3 bary)
{
    uint low = 0u, high = u.meshCount; // the owner is in [low, high)
    while (high - low > 1u) {
        ++g_loopIterations;
        uint middle = (low + high) / 2u;
        if (meshes[middle].firstEmitter <= index)
            low = middle;
        else
            high = middle;
    }
    uint owner = low;
    if (u.meshCount == 0u || (meshes[owner].flags & (MESH_FLAG_ALPHA | MESH_FLAG_EMISSIVE)) !=
                                 (MESH_FLAG_ALPHA | MESH_FLAG_EMISSIVE) || index < meshes[owner].firstEmitter)
        return 1.0; // a triangle light, or an emitter of an opaque mesh
    Mesh mesh = meshes[owner];
    uint slot = index - mesh.firstEmitter;
    uint material = alphaMaterial(mesh, slot);
    uint mode = materialAlpha[material].mode;
    if (mode == ALPHA_MODE_OPAQUE)
        return 1.0;
    float alpha = alphaAt(mesh, slot, material, bary);
    if (mode == ALPHA_MODE_MASK)
        return alpha >= materialAlpha[material].cutoff ? 1.0 : 0.0;
    return alpha;
}
#endif
#endif

#endif

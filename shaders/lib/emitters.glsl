// Emitters: every emitting triangle, whether a triangle light or a triangle
// of an emissive mesh, in one array with one alias table (chosen in
// proportion to power, src/render/GpuScene.cpp), one sampling routine and one
// MIS weight (lib/path.glsl: emitterOnHit).
#ifndef VKRT_EMITTERS_GLSL
#define VKRT_EMITTERS_GLSL

#ifdef VKRT_HAS_EMITTERS
VKRT_READ_BUFFER(BINDING_EMITTERS, EmitterBlock, Emitter, emitters)
#define emitters VKRT_READ_ITEMS(BINDING_EMITTERS, EmitterBlock, emitters)

// Unit normal of an emitter: its counter-clockwise side.
vec3 emitterNormal(Emitter e) { return normalize(cross(e.v1 - e.v0, e.v2 - e.v0)); }

// Radiance an emitter sends towards direction `towards` (from the emitter)
// from its point of texture coordinates `uv` (emitterUvAtHit, emitterUvAt):
// the emission times its texture's texel there where it has one. Every site
// that reads an emitter's radiance passes the point's uv.
vec3 emitterRadiance(Emitter e, vec3 towards, vec2 uv)
{
    float facing = dot(emitterNormal(e), towards);
    if (!(facing > 0.0 || (e.twoSided != 0u && facing < 0.0)))
        return vec3(0.0);
#ifdef VKRT_HAS_EMISSION_TEXTURES
    if (e.textures != NO_EMISSION_TEXTURE)
        return e.radiance * emissionTexel(e.textures, uv);
#endif
    return e.radiance;
}

// The uv of a hit on an emitter (what emitterRadiance reads).
vec2 emitterUvAtHit(SurfaceHit hit)
{
#if defined(VKRT_HAS_EMISSION_TEXTURES) && defined(VKRT_HAS_MESH_UVS1)
    return materialTextures[hit.material].slots[TEXTURE_SLOT_EMISSION].texCoord == 1u ? hit.uv1 : hit.uv;
#elif defined(VKRT_HAS_EMISSION_TEXTURES)
    return hit.uv;
#else
    return vec2(0.0);
#endif
}

// The uv of the point of barycentrics b on emitter e: the mesh triangle's uvs
// interpolated as a hit there interpolates them (lib/surface.glsl: triangleUv).
vec2 emitterUvAt(Emitter e, vec3 b)
{
#ifdef VKRT_HAS_EMISSION_TEXTURES
    if (e.textures != NO_EMISSION_TEXTURE)
        return meshTriangleUv(e.uvs, materialTextures[e.textures].slots[TEXTURE_SLOT_EMISSION].texCoord, b);
#endif
    return vec2(0.0);
}

// Solid-angle density of choosing emitter e (in proportion to power) and
// then a uniform point on it, seen at squared distance distSq and |cos| cosLight.
float emitterPdf(Emitter e, float distSq, float cosLight) { return e.pdf * distSq / (cosLight * e.area); }

// Walker's alias method: slot from uSlot, then the slot or its alias by uAlias.
uint pickEmitter(float uSlot, float uAlias)
{
    uint slot = min(uint(uSlot * float(u.emitterCount)), u.emitterCount - 1u);
    return uAlias < emitters[slot].aliasThreshold ? slot : emitters[slot].alias;
}

// One emitter, chosen in proportion to power, through a uniformly sampled
// point on it: an unbiased estimate of the direct light from every emitter,
// with its solid-angle density for MIS against BSDF sampling (path integrator).
LightArrival sampleEmitters(vec4 u4, SurfaceHit hit, vec3 ns, vec3 origin)
{
#ifdef VKRT_HAS_ALPHA
    uint index = pickEmitter(u4.x, u4.y);
    Emitter e = emitters[index];
#else
    Emitter e = emitters[pickEmitter(u4.x, u4.y)];
#endif
    vec3 point = sampleTriangle(e.v0, e.v1, e.v2, u4.zw);
    float s = sqrt(u4.z); // sampleTriangle's barycentrics
    vec2 uv = emitterUvAt(e, vec3(1.0 - s, s * (1.0 - u4.w), s * u4.w));
    // Aim just short of the emitter so it does not shadow itself.
    vec3 target = mix(origin, point, 1.0 - 1.0 / 65536.0);
    vec3 toLight = point - hit.position;
    float distSq = dot(toLight, toLight);
    vec3 wi = toLight * inversesqrt(distSq);
    float cosSurface = dot(ns, wi);
    float cosLight = abs(dot(emitterNormal(e), wi));
    vec3 le = emitterRadiance(e, -wi, uv);
#ifdef VKRT_HAS_ALPHA
    // An alpha-tested mesh emits where its surface is (lib/alpha.glsl), at
    // sampleTriangle's barycentrics (1 - s, s (1 - u.w), s u.w).
    le *= emitterCoverage(index, vec3(1.0 - s, s * (1.0 - u4.w), s * u4.w));
#endif
    if (cosSurface <= 0.0 || cosLight == 0.0 || le == vec3(0.0) || !(e.pdf > 0.0) || distSq == 0.0)
        return noArrival(target);
    float lightPdf = emitterPdf(e, distSq, cosLight);
    return LightArrival(wi, target, le / lightPdf, lightPdf);
}
#endif

// All emitters as one more candidate of the path integrator's shadow ray: a
// power-proportional choice of one of them (unbiased for their sum), with
// the reservoir's number `pick`.
LightArrival emitterCandidate(SurfaceHit hit, vec3 ns, vec3 origin, inout Sampler rng, out float pick)
{
#ifdef VKRT_HAS_EMITTERS
    vec4 u4 = sampleNext4D(rng);
    LightArrival a = sampleEmitters(u4, hit, ns, origin);
    pick = sampleNext1D(rng);
    return a;
#else
    pick = 0.0;
    return noArrival(origin);
#endif
}

// 1 when the emitters are a candidate of the path integrator's shadow ray.
uint emitterCandidates()
{
#ifdef VKRT_HAS_EMITTERS
    return u.emitterCount > 0u ? 1u : 0u;
#else
    return 0u;
#endif
}

#endif

// Direct lighting from point and triangle lights, with shadow rays that pass
// through dielectrics (attenuated) and stop at anything else.
#ifndef VKRT_LIGHTS_GLSL
#define VKRT_LIGHTS_GLSL

// Fraction of light that travels from `origin` along `dir` for distance
// tMax, starting in the media `media`. Each dielectric interface passes
// 1 - F, and every stretch is attenuated by Beer-Lambert in the medium it
// lies in; any other surface blocks.
vec3 shadowTransmittance(vec3 origin, vec3 dir, float tMax, MediumStack media)
{
    // The path integrator treats glass physically: a shadow ray cannot see a
    // light through it (light arrives through glass by BSDF sampling).
#if !defined(VKRT_MATERIAL_DIELECTRIC) || defined(VKRT_INTEGRATOR_PATH)
    if (traceAny(Ray(origin, dir), tMax))
        return vec3(0.0);
    return beerLambert(mediumAbsorption(media), tMax);
#else
    vec3 target = origin + dir * tMax;
    vec3 transmittance = vec3(1.0);
    for (uint crossing = 0u; crossing < MAX_SHADOW_CROSSINGS; ++crossing) {
        ++g_loopIterations;
        SurfaceHit hit;
        if (!traceClosest(Ray(origin, dir), tMax, hit))
            return transmittance * beerLambert(mediumAbsorption(media), tMax);
        if (hitsLight(hit))
            return vec3(0.0);
        Material m = materials[hit.material];
        if (m.type != MATERIAL_DIELECTRIC)
            return vec3(0.0);
        transmittance *= beerLambert(mediumAbsorption(media), hit.t);
        // A shadow ray is a straight line, so its angle with the surface is
        // the one light has on the less dense side of this interface (for a
        // slab, the refracted ray inside meets the far side at the matching
        // angle). Fresnel reflectance is the same from either side at that
        // pair of angles, so evaluate it from the less dense side: (1 - F)^2
        // through a slab, and no spurious total internal reflection.
        float eta = surfaceEta(media, hit);
        transmittance *= 1.0 - dielectricReflectance(m.fresnel, abs(dot(dir, hit.normal)), min(eta, 1.0 / eta));
        media = crossInterface(media, hit.material, hit.front);
        vec3 towardsRay = hit.front ? hit.normal : -hit.normal;
        origin = offsetRayOrigin(hit.position, hit.error, -towardsRay);
        tMax = dot(target - origin, dir);
        if (tMax <= 0.0)
            return transmittance;
    }
    return vec3(0.0); // more interfaces than MAX_SHADOW_CROSSINGS: treated as blocked
#endif
}

// Transmittance from a spawned shadow-ray origin to a point. A point that
// lies within the surface's error bound (at or behind the offset origin) has
// nothing between it and the surface: fully visible, and no NaN direction.
vec3 transmittanceTo(vec3 point, vec3 origin, vec3 n, MediumStack media)
{
    vec3 shadowDir = point - origin;
    if (dot(shadowDir, n) <= 0.0)
        return vec3(1.0);
    float shadowDist = length(shadowDir);
    return shadowTransmittance(origin, shadowDir / shadowDist, shadowDist, media);
}

// Transmittance to a light sample from a surface with geometric normal n
// and shading normal ns (both on the side the ray arrived from). With
// shading normals a light above the shading plane can lie behind the
// geometric one: the surface itself is between them, so it is blocked
// (where ns == n such a point lies within the surface's error bound and is
// fully visible, as in transmittanceTo).
vec3 transmittanceFromSurface(SurfaceHit hit, vec3 n, vec3 ns, vec3 origin, vec3 target, MediumStack media)
{
    // transmittanceTo, written out so that the extra case stays inside its
    // rarely taken branch: kernels without it keep their exact arithmetic.
    vec3 shadowDir = target - origin;
    if (dot(shadowDir, n) <= 0.0) {
#ifdef VKRT_HAS_SHADING_NORMALS // only vertex normals and normal maps make ns differ from n
        if (ns != n)
            return vec3(0.0);
#endif
        return vec3(1.0);
    }
    float shadowDist = length(shadowDir);
    return shadowTransmittance(origin, shadowDir / shadowDist, shadowDist, media);
}

// A light's contribution to a surface point before visibility, and the point
// a shadow ray must reach for it to count.
struct LightSample {
    vec3 unshadowed;
    vec3 target;
};

#ifdef VKRT_HAS_POINT_LIGHTS
// Every light function takes the geometric normal n (the side the shadow ray
// leaves from, for offsets) and the shading normal ns on the same side (for
// the BSDF and its cosine); ns == n except on meshes with vertex normals.

// One point light: f * I * cos / d^2. Geometry from the surface point itself;
// only the shadow ray starts at the offset origin (measuring from it would
// bias 1/d^2 by the offset).
LightSample samplePointLight(PointLight light, Material m, SurfaceHit hit, vec3 ns, vec3 wo)
{
    vec3 toLight = light.position - hit.position;
    float distSq = dot(toLight, toLight);
    vec3 wi = toLight * inversesqrt(distSq);
    float cosTheta = dot(ns, wi);
    if (cosTheta <= 0.0)
        return LightSample(vec3(0.0), light.position);
    vec3 f = evalBsdf(m, ns, wo, wi);
    return LightSample(f * light.intensity * (cosTheta / distSq), light.position);
}
#endif

// Every point light (the Whitted integrator).
vec3 directFromPointLights(Material m, SurfaceHit hit, vec3 n, vec3 ns, vec3 wo, MediumStack media)
{
    vec3 radiance = vec3(0.0);
#ifdef VKRT_HAS_POINT_LIGHTS
    vec3 origin = offsetRayOrigin(hit.position, hit.error, n);
    for (uint i = 0u; i < u.pointLightCount; ++i) {
        ++g_loopIterations;
        LightSample s = samplePointLight(pointLights[i], m, hit, ns, wo);
        if (s.unshadowed != vec3(0.0))
            radiance += s.unshadowed * transmittanceFromSurface(hit, n, ns, origin, s.target, media);
    }
#endif
    return radiance;
}

#ifdef VKRT_HAS_TRIANGLE_LIGHTS
// Radiance a triangle light emits towards direction `towards` (from the light).
vec3 emittedRadiance(TriangleLight light, vec3 towards)
{
    float facing = dot(triangleLightNormal(light), towards);
    return (facing > 0.0 || (light.twoSided != 0u && facing < 0.0)) ? light.radiance : vec3(0.0);
}
#endif

// Power-heuristic weight (Veach 1997, eq. 9.13) of a strategy with density
// `pdf` against another with density `other`, one sample each.
// Written as 1 / (1 + (other / pdf)^2): squaring a huge pdf (a light seen
// almost edge-on) would overflow to inf / inf = NaN.
float powerHeuristic(float pdf, float other)
{
    if (!(pdf > 0.0))
        return 0.0;
    float ratio = other / pdf;
    return isinf(pdf) ? (isinf(other) ? 0.5 : 1.0) : 1.0 / (1.0 + ratio * ratio);
}

// Density in solid angle of sampling `light` uniformly by area, seen from a
// point at squared distance distSq along a direction with |cos| cosLight.
float triangleLightPdf(float area, float distSq, float cosLight) { return distSq / (cosLight * area); }

#ifdef VKRT_HAS_TRIANGLE_LIGHTS
// One triangle light through a uniformly sampled point on it (pdf = 1 / area,
// `u` its two coordinates): f * Le * cos_surface * cos_light / d^2 * area; the
// path integrator weighs it against BSDF sampling (MIS).
LightSample sampleTriangleLight(TriangleLight light, vec2 u, Material m, SurfaceHit hit, vec3 ns, vec3 wo, vec3 origin)
{
    vec3 point = sampleTriangle(light.v0, light.v1, light.v2, u);
    // Aim just short of the light so it does not shadow itself.
    vec3 target = mix(origin, point, 1.0 - 1.0 / 65536.0);
    vec3 toLight = point - hit.position;
    float distSq = dot(toLight, toLight);
    vec3 wi = toLight * inversesqrt(distSq);
    float cosSurface = dot(ns, wi);
    float cosLight = abs(dot(triangleLightNormal(light), wi));
    vec3 le = emittedRadiance(light, -wi);
    if (cosSurface <= 0.0 || cosLight == 0.0 || le == vec3(0.0))
        return LightSample(vec3(0.0), target);
    vec3 f = evalBsdf(m, ns, wo, wi);
    vec3 contribution = f * le * (cosSurface * cosLight * light.area / distSq);
#ifdef VKRT_INTEGRATOR_PATH
    contribution *= powerHeuristic(triangleLightPdf(light.area, distSq, cosLight), pdfBsdf(m, ns, wo, wi));
#endif
    return LightSample(contribution, target);
}
#endif

// One sampled point on every triangle light (the Whitted integrator).
vec3 directFromTriangleLights(Material m, SurfaceHit hit, vec3 n, vec3 ns, vec3 wo, MediumStack media,
                              inout Sampler rng)
{
    vec3 radiance = vec3(0.0);
#ifdef VKRT_HAS_TRIANGLE_LIGHTS
    vec3 origin = offsetRayOrigin(hit.position, hit.error, n);
    for (uint i = 0u; i < u.triangleLightCount; ++i) {
        ++g_loopIterations;
        LightSample s = sampleTriangleLight(triangleLights[i], sampleNext2D(rng), m, hit, ns, wo, origin);
        if (s.unshadowed != vec3(0.0))
            radiance += s.unshadowed * transmittanceFromSurface(hit, n, ns, origin, s.target, media);
    }
#endif
    return radiance;
}

#ifdef VKRT_HAS_EMITTERS
// Unit normal of an emissive mesh triangle: its counter-clockwise side.
vec3 emitterNormal(Emitter e) { return normalize(cross(e.v1 - e.v0, e.v2 - e.v0)); }

vec3 emitterRadiance(Emitter e, vec3 towards)
{
    float facing = dot(emitterNormal(e), towards);
    return (facing > 0.0 || (e.twoSided != 0u && facing < 0.0)) ? e.radiance : vec3(0.0);
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

// One emissive mesh triangle, chosen in proportion to power, through a
// uniformly sampled point on it: an unbiased estimate of the direct light
// from every emitter, MIS-weighted against BSDF sampling (path integrator).
LightSample sampleEmitters(vec4 u4, Material m, SurfaceHit hit, vec3 ns, vec3 wo, vec3 origin)
{
    Emitter e = emitters[pickEmitter(u4.x, u4.y)];
    vec3 point = sampleTriangle(e.v0, e.v1, e.v2, u4.zw);
    vec3 target = mix(origin, point, 1.0 - 1.0 / 65536.0);
    vec3 toLight = point - hit.position;
    float distSq = dot(toLight, toLight);
    vec3 wi = toLight * inversesqrt(distSq);
    float cosSurface = dot(ns, wi);
    float cosLight = abs(dot(emitterNormal(e), wi));
    vec3 le = emitterRadiance(e, -wi);
    if (cosSurface <= 0.0 || cosLight == 0.0 || le == vec3(0.0) || !(e.pdf > 0.0) || distSq == 0.0)
        return LightSample(vec3(0.0), target);
    float lightPdf = emitterPdf(e, distSq, cosLight);
    vec3 contribution = evalBsdf(m, ns, wo, wi) * le * (cosSurface / lightPdf);
#ifdef VKRT_INTEGRATOR_PATH
    contribution *= powerHeuristic(lightPdf, pdfBsdf(m, ns, wo, wi));
#endif
    return LightSample(contribution, target);
}
#endif

// One sample of the emissive meshes (the Whitted integrator).
vec3 directFromEmitters(Material m, SurfaceHit hit, vec3 n, vec3 ns, vec3 wo, MediumStack media, inout Sampler rng)
{
#ifdef VKRT_HAS_EMITTERS
    if (u.emitterCount == 0u)
        return vec3(0.0);
    vec3 origin = offsetRayOrigin(hit.position, hit.error, n);
    LightSample s = sampleEmitters(sampleNext4D(rng), m, hit, ns, wo, origin);
    if (s.unshadowed != vec3(0.0))
        return s.unshadowed * transmittanceFromSurface(hit, n, ns, origin, s.target, media);
#endif
    return vec3(0.0);
}

// Picks one of a stream of light samples with probability proportional to its
// weight (weighted reservoir sampling: candidate i replaces the kept one with
// probability w_i / (w_1 + ... + w_i), decided by its own uniform number).
struct LightReservoir {
    LightSample kept;
    float keptWeight;
    float totalWeight;
};

void offerLightSample(inout LightReservoir r, LightSample s, float u)
{
    // The largest component: zero only for a sample that adds nothing, and
    // finite whenever the sample is.
    float w = max(s.unshadowed.r, max(s.unshadowed.g, s.unshadowed.b));
    if (!(w > 0.0))
        return;
    r.totalWeight += w;
    // The first sample is always kept (u * w < w could round to equality).
    if (r.keptWeight == 0.0 || u * r.totalWeight < w) {
        r.kept = s;
        r.keptWeight = w;
    }
}

// Next-event estimation from every point and triangle light with one shadow
// ray (the path integrator). Each light gets its sample as in the Whitted
// sums above, but only one is tested for visibility: sample i with
// probability p_i = w_i / W, its unshadowed weight over their total, and
// scaled by 1 / p_i. The expectation is the sum of every sample times its
// visibility, so the estimate stays unbiased; where all lights are visible
// it equals that sum up to the lights' colour differences (no added
// variance), and under partial occlusion it adds some: measured as a whole,
// 1.09-1.27x more efficient on the validation scenes (docs/performance.md).
vec3 directFromLightsOneShadowRay(Material m, SurfaceHit hit, vec3 n, vec3 ns, vec3 wo, MediumStack media,
                                  inout Sampler rng)
{
    vec3 origin = offsetRayOrigin(hit.position, hit.error, n);
    LightReservoir r = LightReservoir(LightSample(vec3(0.0), vec3(0.0)), 0.0, 0.0);
#ifdef VKRT_HAS_POINT_LIGHTS
    for (uint i = 0u; i < u.pointLightCount; ++i) {
        ++g_loopIterations;
        offerLightSample(r, samplePointLight(pointLights[i], m, hit, ns, wo), sampleNext1D(rng));
    }
#endif
#ifdef VKRT_HAS_TRIANGLE_LIGHTS
    for (uint i = 0u; i < u.triangleLightCount; ++i) {
        ++g_loopIterations;
        vec3 u3 = sampleNext4D(rng).xyz;
        offerLightSample(r, sampleTriangleLight(triangleLights[i], u3.xy, m, hit, ns, wo, origin), u3.z);
    }
#endif
#ifdef VKRT_HAS_EMITTERS
    // All emissive meshes are one more candidate: a power-proportional
    // choice of one of their triangles (its estimate is unbiased for their sum).
    if (u.emitterCount > 0u) {
        vec4 u4 = sampleNext4D(rng);
        offerLightSample(r, sampleEmitters(u4, m, hit, ns, wo, origin), sampleNext1D(rng));
    }
#endif
    if (r.totalWeight == 0.0)
        return vec3(0.0);
    return r.kept.unshadowed * (r.totalWeight / r.keptWeight) *
           transmittanceFromSurface(hit, n, ns, origin, r.kept.target, media);
}

#endif

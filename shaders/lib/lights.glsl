// Direct lighting: shadow rays that pass through dielectrics (attenuated) and
// stop at anything else, and every light kind's sampling (lib/lights/*.glsl)
// combined for the two integrators.
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
        media = mediaAtSurface(media, hit);
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

// The shadow ray from a surface with geometric normal n and shading normal
// ns (both on the side the ray arrived from) to a light sample at `target`,
// or (false) none, when the sample lies behind the geometric plane: then
// `visibility` is the whole transmittance. With shading normals a light
// above the shading plane can lie behind the geometric one: the surface
// itself is between them, so it is blocked (where ns == n such a point lies
// within the surface's error bound and is fully visible, as in
// transmittanceTo).
bool shadowRayFromSurface(vec3 n, vec3 ns, vec3 origin, vec3 target, out vec3 dir, out float dist, out vec3 visibility)
{
    // transmittanceTo's test, written out so that the extra case stays inside
    // its rarely taken branch: kernels without it keep their exact arithmetic.
    vec3 shadowDir = target - origin;
    if (dot(shadowDir, n) <= 0.0) {
        visibility = vec3(1.0);
#ifdef VKRT_HAS_SHADING_NORMALS // only vertex normals and normal maps make ns differ from n
        if (ns != n)
            visibility = vec3(0.0);
#endif
        return false;
    }
    dist = length(shadowDir);
    dir = shadowDir / dist;
    return true;
}

// Transmittance to a light sample from a surface (shadowRayFromSurface).
vec3 transmittanceFromSurface(SurfaceHit hit, vec3 n, vec3 ns, vec3 origin, vec3 target, MediumStack media)
{
    vec3 dir, visibility;
    float dist;
    if (!shadowRayFromSurface(n, ns, origin, target, dir, dist, visibility))
        return visibility;
    return shadowTransmittance(origin, dir, dist, media);
}

// A light's contribution to a surface point before visibility, and the point
// a shadow ray must reach for it to count.
struct LightSample {
    vec3 unshadowed;
    vec3 target;
};

// What one sample of a light brings to a surface point, before the BSDF and
// visibility: the direction towards it (unit), the point a shadow ray must
// reach, its radiance over the density of the sample (for a delta light,
// its irradiance at normal incidence over its selection density), and the
// sample's solid-angle density for MIS against BSDF sampling (0 for a delta
// light, which BSDF sampling cannot find). A light kind gives arrivals; the
// BSDF is evaluated for them at one site (litBy, or the path integrator's
// scatterAtVertex): lavapipe inlines every call, and a copy of the BSDF per
// light kind made the kernels of lit scenes compile far slower
// (docs/performance.md, "One evaluation site").
struct LightArrival {
    vec3 wi;
    vec3 target;
    vec3 radiance;
    float pdf;
};

LightArrival noArrival(vec3 target) { return LightArrival(vec3(0.0, 0.0, 1.0), target, vec3(0.0), 0.0); }

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

// Whether an arrival lights the surface at all: radiance, from above the
// shading plane. Only then is the BSDF evaluated for it (f, and its pdf
// where `mis` weighs the light against BSDF sampling).
bool arrivalLights(LightArrival a, vec3 ns) { return a.radiance != vec3(0.0) && dot(ns, a.wi) > 0.0; }
bool arrivalWantsPdf(LightArrival a, vec3 ns, bool mis) { return mis && a.pdf > 0.0 && arrivalLights(a, ns); }

// The light sample of an arrival, with v = evaluateBsdf at a.wi (f where
// arrivalLights, the pdf where arrivalWantsPdf): f cos times its radiance,
// MIS-weighted against BSDF sampling where `mis` and the light has a density.
LightSample lightSampleOf(LightArrival a, vec3 ns, BsdfValue v, bool mis)
{
    if (!arrivalLights(a, ns) || v.f == vec3(0.0))
        return LightSample(vec3(0.0), a.target);
    vec3 contribution = v.f * a.radiance * dot(ns, a.wi);
    if (mis && a.pdf > 0.0)
        contribution *= powerHeuristic(a.pdf, v.pdf);
    return LightSample(contribution, a.target);
}

// The light sample of an arrival with the BSDF evaluated here (the Whitted
// integrator's sites; the path integrator has one of its own).
LightSample litBy(Material m, vec3 ns, vec3 wo, LightArrival a, bool mis)
{
    BsdfValue v = evaluateBsdf(m, ns, wo, a.wi, arrivalLights(a, ns), arrivalWantsPdf(a, ns, mis));
    return lightSampleOf(a, ns, v, mis);
}

// Picks one of a stream of light samples with probability proportional to its
// weight (weighted reservoir sampling: candidate i replaces the kept one with
// probability w_i / (w_1 + ... + w_i), decided by its own uniform number).
struct LightReservoir {
    LightSample kept;
    float keptWeight;
    float totalWeight;
};

LightReservoir emptyReservoir() { return LightReservoir(LightSample(vec3(0.0), vec3(0.0)), 0.0, 0.0); }

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

// Every light kind's sampling (the functions lib/surface.glsl lists, and
// whittedCandidate, lightCandidate), then the emitters all area lights share.
// Every light function takes the geometric normal n (the side the shadow ray
// leaves from, for offsets) and the shading normal ns on the same side (for
// the BSDF and its cosine); ns == n except on meshes with vertex normals.
#include "emitters.glsl"
#define VKRT_LIGHT_SAMPLING
#include "lights/point.glsl"
#include "lights/triangle.glsl"
#include "lights/directional.glsl"
#include "lights/spot.glsl"

// Every kind of light sampled one by one (point, spot and directional
// lights; triangle lights have none of their own: they are emitters) gives
// tableEntries<Type> (how many), whittedSample<Type> and candidate<Type>
// (lib/lights/*.glsl); forgetting one fails the build. The Whitted
// integrator draws whittedSample<Type> through whittedCandidate, the path
// integrator candidate<Type> through lightCandidate.

// ------------------------------------------------------------ the light table
// Scenes with more point, spot and directional lights than the host lets the
// kernel test one by one (src/render/LightTable.h) get VKRT_LIGHT_TABLE: every
// such light and all emitters together are entries of one table chosen in
// proportion to power (Walker's alias method), and a shading point draws
// u.lightCandidates entries from it, of which one, chosen in proportion to its
// unshadowed contribution, gets the shadow ray (resampled importance sampling,
// Talbot et al. 2005: each candidate's sample divided by M times its table
// probability, then LightReservoir). The cost no longer grows with the lights.
// A light found by BSDF sampling (a soft sun, an emitter) is weighted with
// the same M-times density: the host scales every emitter's pdf by M times
// the emitters' entry (LightTable.cpp), so emitterOnHit needs no change.
#ifdef VKRT_LIGHT_TABLE
VKRT_READ_BUFFER(BINDING_LIGHT_TABLE, LightTableBlock, LightPick, lightTable)
#define lightTable VKRT_READ_ITEMS(BINDING_LIGHT_TABLE, LightTableBlock, lightTable)

// The density of choosing one entry among the candidates: M times its probability.
float tableSelection(uint entry) { return float(u.lightCandidates) * lightTable[entry].pdf; }

// Walker's alias method over the table, as pickEmitter over the emitters.
uint pickTableEntry(float uSlot, float uAlias)
{
    uint slot = min(uint(uSlot * float(u.lightTableCount)), u.lightTableCount - 1u);
    return uAlias < lightTable[slot].aliasThreshold ? slot : lightTable[slot].alias;
}

// The table entry of light i of a kind: after the entries of every kind
// before it in the registry (shared/Kinds.h).
#define VKRT_TABLE_ENTRY_OF_KIND(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    if (kind == LIGHT_##KIND)                                                                \
        return first + i;                                                                    \
    first += tableEntries##Type();
uint tableEntry(int kind, uint i)
{
    uint first = 0u;
    VKRT_LIGHT_KINDS(VKRT_TABLE_ENTRY_OF_KIND)
    return first + i;
}

// One entry's light sample, divided by the density of having drawn it; the
// last entry samples every emitter (their pdfs carry that density already).
#define VKRT_SAMPLE_TABLE_KIND(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    if (i < tableEntries##Type())                                                          \
        return sampleTable##Type(i, selection, hit, ns, origin, rnd);                      \
    i -= tableEntries##Type();
LightArrival sampleTableEntry(uint entry, SurfaceHit hit, vec3 ns, vec3 origin, vec4 rnd)
{
    float selection = tableSelection(entry);
    if (!(selection > 0.0))
        return noArrival(origin); // a light of no power: never drawn but by rounding
    uint i = entry;
    VKRT_LIGHT_KINDS(VKRT_SAMPLE_TABLE_KIND)
#ifdef VKRT_HAS_EMITTERS
    return sampleEmitters(rnd, hit, ns, origin);
#else
    return noArrival(origin);
#endif
}

// One candidate drawn from the table, with the reservoir's number `pick`.
LightArrival tableCandidate(SurfaceHit hit, vec3 ns, vec3 origin, inout Sampler rng, out float pick)
{
    vec4 draw = sampleNext4D(rng); // table slot, alias, the reservoir's choice
    pick = draw.z;
    return sampleTableEntry(pickTableEntry(draw.x, draw.y), hit, ns, origin, sampleNext4D(rng));
}
#endif

float lightSelection(int kind, uint i)
{
#ifdef VKRT_LIGHT_TABLE
    return tableSelection(tableEntry(kind, i));
#else
    return 1.0;
#endif
}

#ifdef VKRT_ENVIRONMENT_SAMPLING
bool constantEnvironment() { return (u.flags & RENDER_FLAG_CONSTANT_ENVIRONMENT) != 0u; }

// A constant map's light samples follow the cosine lobe about the shading
// normal, the map times the cosine, rather than the map's own distribution
// (uniform over the sphere for it): a diffuse surface in the open then gets
// the same value from every sample, where uniform directions gave a smooth
// dielectric 70x a sample's variance, and an occluded one still gets a second
// visibility sample beside its BSDF ray (docs/performance.md).
float constantEnvironmentPdf(vec3 ns, vec3 dir) { return max(dot(ns, dir), 0.0) * INV_PI; }

// One direction drawn from the environment map (a constant one: from the
// cosine lobe about ns, constantEnvironmentPdf) and its light, with its
// density for MIS against BSDF sampling (which finds the same light when a
// ray escapes: environmentOnEscape). The shadow ray's target is far along
// the direction (FAR_LIGHT_DISTANCE).
LightArrival sampleEnvironmentLight(vec3 ns, vec3 origin, vec3 rnd)
{
    float pdf;
    vec3 wi;
    if (constantEnvironment()) {
        wi = sampleCosineHemisphere(ns, rnd.xy);
        pdf = constantEnvironmentPdf(ns, wi);
    } else {
        wi = sampleEnvironment(rnd, pdf);
    }
    vec3 target = origin + wi * FAR_LIGHT_DISTANCE;
    // Below the shading plane it lights nothing: no look-up (a sky model's
    // costs as much as the rest of the sample).
    if (!(pdf > 0.0) || dot(ns, wi) <= 0.0)
        return noArrival(target);
    return LightArrival(wi, target, environmentRadiance(wi) / pdf, pdf);
}
#endif

// Environment radiance found by a ray that escaped after a scattering of
// solid-angle density bsdfPdf (`specular`: a delta event, or the camera),
// MIS-weighted when the environment is also sampled directly; cosinePdf is
// the direction's density in the cosine lobe about the scattering vertex's
// shading normal (constantEnvironmentPdf), how a constant map is sampled.
vec3 environmentOnEscape(vec3 dir, bool specular, float bsdfPdf, float cosinePdf)
{
    vec3 le = environmentRadiance(dir);
#ifdef VKRT_ENVIRONMENT_SAMPLING
    if (!specular)
        le *= powerHeuristic(bsdfPdf, constantEnvironment() ? cosinePdf : environmentPdf(dir));
#endif
    return le;
}

// ------------------------------------------------ the Whitted integrator's lights
// Direct light with a shadow ray per light sample (the Whitted integrator):
// every light of every kind in the registry's order, one sample of the
// emitters, and one direction of the environment map (MIS-weighted against
// BSDF sampling when `bsdfFollows`: false at a vertex no ray leaves, the
// integrator's last, where the light sample is all the estimate has). They
// are the passes of one loop, so that the kernel holds one copy of the BSDF
// evaluation and one of the shadow ray's trace (lavapipe inlines every call;
// a copy per light kind made the Whitted kernels, the uber kernel most of
// all, compile far slower: docs/performance.md, "One evaluation site").
// With the light table, its candidates, one of them with a shadow ray,
// emitters included, come first.
// The lights sampled one by one, each a candidate of both integrators: every
// light of every kind and one sample of the emitters (none with the light
// table, whose entries they are); then the environment map, one more.
#define VKRT_PLUS_ENTRIES_OF_KIND(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) +tableEntries##Type()

uint enumeratedCandidates()
{
#ifdef VKRT_LIGHT_TABLE
    return 0u;
#else
    return 0u VKRT_LIGHT_KINDS(VKRT_PLUS_ENTRIES_OF_KIND) + emitterCandidates();
#endif
}

uint environmentCandidates()
{
#ifdef VKRT_ENVIRONMENT_SAMPLING
    return 1u;
#else
    return 0u;
#endif
}

uint whittedCandidateCount() { return enumeratedCandidates() + environmentCandidates(); }

#define VKRT_WHITTED_CANDIDATE_OF_KIND(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    if (c < tableEntries##Type())                                                                  \
        return whittedSample##Type(c, hit, ns, origin, rng);                                       \
    c -= tableEntries##Type();
LightArrival whittedCandidate(uint c, SurfaceHit hit, vec3 ns, vec3 origin, bool bsdfFollows, inout Sampler rng,
                              out bool mis)
{
    mis = false;
#ifndef VKRT_LIGHT_TABLE
    VKRT_LIGHT_KINDS(VKRT_WHITTED_CANDIDATE_OF_KIND)
#ifdef VKRT_HAS_EMITTERS
    if (c < emitterCandidates())
        return sampleEmitters(sampleNext4D(rng), hit, ns, origin);
#endif
#endif
#ifdef VKRT_ENVIRONMENT_SAMPLING
    mis = bsdfFollows;
    return sampleEnvironmentLight(ns, origin, sampleNext4D(rng).xyz);
#else
    return noArrival(origin);
#endif
}

vec3 whittedDirectLight(Material m, SurfaceHit hit, vec3 n, vec3 ns, vec3 wo, MediumStack media, bool bsdfFollows,
                        inout Sampler rng)
{
    vec3 origin = offsetRayOrigin(hit.position, hit.error, n);
    vec3 radiance = vec3(0.0);
#ifdef VKRT_LIGHT_TABLE
    LightReservoir r = emptyReservoir();
    for (uint c = 0u; c < u.lightCandidates; ++c) {
        ++g_loopIterations;
        float pick;
        LightArrival a = tableCandidate(hit, ns, origin, rng, pick);
        offerLightSample(r, litBy(m, ns, wo, a, false), pick);
    }
    if (r.totalWeight != 0.0)
        radiance = r.kept.unshadowed * (r.totalWeight / r.keptWeight) *
                   transmittanceFromSurface(hit, n, ns, origin, r.kept.target, media);
#endif
    uint count = whittedCandidateCount();
    for (uint c = 0u; c < count; ++c) {
        ++g_loopIterations;
        bool mis;
        LightArrival a = whittedCandidate(c, hit, ns, origin, bsdfFollows, rng, mis);
        LightSample s = litBy(m, ns, wo, a, mis);
        if (s.unshadowed != vec3(0.0))
            radiance += s.unshadowed * transmittanceFromSurface(hit, n, ns, origin, s.target, media);
    }
    return radiance;
}

// ------------------------------------------- the path integrator's candidates
// Next-event estimation from every light kind, the emitters and the
// environment map with one shadow ray (the path integrator). Each light
// offers its sample as in the Whitted sums above, but only one is tested for
// visibility: sample i with probability p_i = w_i / W, its unshadowed weight
// over their total, and scaled by 1 / p_i. The expectation is the sum of
// every sample times its visibility, so the estimate stays unbiased; where
// all lights are visible it equals that sum up to the lights' colour
// differences (no added variance), and under partial occlusion it adds some,
// less than the shadow rays it saves cost (docs/performance.md has the
// efficiency measured). The candidates are numbered, so that one loop
// (lib/path.glsl: scatterAtVertex) draws them all and evaluates the BSDF for
// each at one site: every light of every kind in the registry's order (or
// u.lightCandidates draws from the light table), the emitters, then the
// environment map.
uint lightCandidateCount()
{
#ifdef VKRT_LIGHT_TABLE
    return u.lightCandidates + environmentCandidates();
#else
    return enumeratedCandidates() + environmentCandidates();
#endif
}

// Candidate c (< lightCandidateCount()), drawing its numbers from rng in
// the candidates' order, with the reservoir's number `pick`.
#define VKRT_CANDIDATE_OF_KIND(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    if (c < tableEntries##Type())                                                          \
        return candidate##Type(c, hit, ns, origin, rng, pick);                             \
    c -= tableEntries##Type();
LightArrival lightCandidate(uint c, SurfaceHit hit, vec3 ns, vec3 origin, inout Sampler rng, out float pick)
{
#ifdef VKRT_LIGHT_TABLE
    if (c < u.lightCandidates)
        return tableCandidate(hit, ns, origin, rng, pick);
#else
    VKRT_LIGHT_KINDS(VKRT_CANDIDATE_OF_KIND)
    if (c < emitterCandidates())
        return emitterCandidate(hit, ns, origin, rng, pick);
#endif
#ifdef VKRT_ENVIRONMENT_SAMPLING
    // The environment map is one more candidate: one shadow ray for all light.
    vec4 u4 = sampleNext4D(rng);
    pick = u4.w;
    return sampleEnvironmentLight(ns, origin, u4.xyz);
#else
    pick = 0.0;
    return noArrival(origin);
#endif
}

#endif

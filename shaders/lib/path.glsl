// Unbiased path tracing (`integrator = "path"`). At each non-specular vertex:
// next-event estimation for every point light and one area-sampled point on
// one emitter (triangle lights and emissive mesh triangles, chosen in
// proportion to power) and one direction of a sampled environment map, with
// one shadow ray for all of them (chosen by unshadowed contribution),
// weighted against BSDF sampling with the power heuristic; then one
// BSDF-sampled continuation. A continuation that hits an emitter adds its
// emission with the complementary MIS weight (full weight after a specular
// bounce or from the camera); one that escapes adds the environment.
// Russian roulette from the fourth vertex on keeps long paths unbiased.
// max_depth counts surface interactions with light sampling, so the longest
// path has max_depth + 1 segments (Mitsuba's max_depth = ours + 1).
#ifndef VKRT_PATH_GLSL
#define VKRT_PATH_GLSL

struct PathVertexState {
    vec3 radiance;
    vec3 throughput;
    MediumStack media;     // the dielectrics the ray travels in
    bool specular;         // the last scattering was a delta event (or the camera)
    float bsdfPdf;         // solid-angle pdf of the last BSDF sample
    float cosinePdf;       // ... and its density in the cosine lobe about that vertex's shading normal
};

vec3 emitterOnHit(PathVertexState path, Ray ray, SurfaceHit hit)
{
#ifdef VKRT_HAS_EMITTERS
    Emitter e = emitters[hit.emitter];
    vec3 le = emitterRadiance(e, -ray.dir, emitterUvAtHit(hit));
    if (path.specular || le == vec3(0.0))
        return le;
    float cosLight = abs(dot(emitterNormal(e), ray.dir));
    return le * powerHeuristic(path.bsdfPdf, emitterPdf(e, hit.t * hit.t, cosLight));
#else
    return vec3(0.0);
#endif
}

// Russian roulette: continue with probability q = min(1, max throughput
// component) and divide by q, so the estimate stays unbiased.
bool survivesRoulette(inout PathVertexState path, uint depth, float u)
{
    if (depth < 4u)
        return true;
    float q = min(1.0, max(path.throughput.x, max(path.throughput.y, path.throughput.z)));
    if (u >= q)
        return false;
    path.throughput /= q;
    return true;
}

// A path under way: its state between two segments, so that a kernel can
// advance one segment at a time and start a lane's next sample as soon as its
// path ends (render.comp: path regeneration).
struct PathTracer {
    PathVertexState path;
    Ray ray;     // the next segment to trace
    uint depth;  // surface interactions so far + 1
#ifdef VKRT_HAS_TEXTURES
    float pathLength; // from the camera, for the textures' ray cones
#endif
};

PathTracer startPath(Ray cameraRay)
{
    PathTracer p;
    p.path = PathVertexState(vec3(0.0), vec3(1.0), cameraMedia(), true, 0.0, 0.0);
    p.ray = cameraRay;
    p.depth = 1u;
#ifdef VKRT_HAS_TEXTURES
    p.pathLength = 0.0;
#endif
    return p;
}

// The shadow ray of a vertex's next-event estimate, traced after the vertex
// has scattered (advancePath), and what it adds when nothing blocks it.
struct ShadowTest {
    bool pending;
    Ray ray;
    float dist;
    vec3 weight;      // the path's sample weight at the vertex
    vec3 light;       // the kept light sample over its selection probability
    vec3 absorption;  // of the medium the shadow ray travels in
};

#ifdef VKRT_HAS_MATERIALS
// Adds a non-specular vertex's next-event estimate (its light candidates'
// reservoir r, lightCandidate) where no ray need be traced, else sets up its
// shadow ray for advancePath to trace.
void estimateDirectLight(inout PathTracer p, LightReservoir r, vec3 n, vec3 ns, vec3 origin, inout ShadowTest shadow)
{
    vec3 weight = sampleWeight(p.path.throughput, p.path.media);
    if (r.totalWeight == 0.0) {
        p.path.radiance += weight * vec3(0.0); // as before: NaN for a NaN weight
        return;
    }
    vec3 light = r.kept.unshadowed * (r.totalWeight / r.keptWeight);
    vec3 dir, visibility;
    float dist;
    if (!shadowRayFromSurface(n, ns, origin, r.kept.target, dir, dist, visibility)) {
        p.path.radiance += weight * (light * visibility);
        return;
    }
    shadow = ShadowTest(true, Ray(origin, dir), dist, weight, light, mediumAbsorption(p.path.media));
}

// A vertex's light candidates (lib/lights.glsl: lightCandidate; none for a
// material that scatters into deltas only) and then its BSDF sample, in one
// loop whose every pass evaluates the BSDF at the same call site. lavapipe
// inlines every call, so each site that evaluates the BSDF is a copy of every
// material's eval and pdf, and the driver's compile time grows far faster
// than the inlined size (docs/performance.md, "One evaluation site"). The
// candidates draw their numbers first and the sample after them, as when
// each had its own site. Returns the sample with its weight and sets
// `bsdfPdf` (0 for a delta) and the reservoir.
BsdfSample scatterAtVertex(Material m, SurfaceHit hit, vec3 ns, vec3 wo, vec3 origin, float eta, bool lit,
                           inout Sampler rng, out LightReservoir r, out float bsdfPdf, out float roulette)
{
    r = emptyReservoir();
    // Every lane makes the same passes (the count is uniform), so that lanes
    // whose materials have no light samples (deltas: `lit` false) reach the
    // BSDF sample in the same pass as the others: with as many passes as
    // candidates of its own, a lane of a mirror sampled its BSDF while its
    // neighbours drew light candidates, and the sampling code ran twice per
    // subgroup (docs/performance.md, "Lanes in step").
    uint candidates = lightCandidateCount();
    for (uint c = 0u;; ++c) {
        bool sampling = c == candidates; // the last pass: the BSDF sample
        LightArrival a;
        BsdfSample s;
        float pick;
        bool wantF, wantPdf;
        if (!sampling) {
            if (!lit)
                continue; // draws nothing: as before, no light numbers for a delta material
            ++g_loopIterations;
            a = lightCandidate(c, hit, ns, origin, rng, pick);
            wantF = arrivalLights(a, ns);
            wantPdf = arrivalWantsPdf(a, ns, true);
        } else {
            vec4 u4 = sampleNext4D(rng);
            roulette = u4.w;
            s = sampleBsdf(m, ns, wo, eta, u4.xyz);
            a.wi = s.dir;
            wantF = sampleWantsF(s);
            wantPdf = sampleWantsPdf(s);
        }
        BsdfValue v = evaluateBsdf(m, ns, wo, a.wi, wantF, wantPdf);
        if (!sampling) {
            offerLightSample(r, lightSampleOf(a, ns, v, true), pick);
            continue;
        }
        bsdfPdf = v.pdf;
        return completedSample(s, ns, v);
    }
    return noScatter(); // not reached
}
#endif

// What the path finds at the end of segment p.ray (`hit`, unless `found` is
// false): adds its emission or the sky's light, then at a surface sets up
// the next-event estimate's shadow ray and samples the next segment; false
// once the path has ended.
bool scatterAtHit(inout PathTracer p, bool found, SurfaceHit hit, inout Sampler rng, inout ShadowTest shadow)
{
    bool missed = !found;
    p.path.throughput *= beerLambert(mediumAbsorption(p.path.media), missed ? FLT_MAX : hit.t);
    if (missed) {
        aovEnd();
        p.path.radiance += sampleWeight(p.path.throughput, p.path.media) *
                           (environmentOnEscape(p.ray.dir, p.path.specular, p.path.bsdfPdf, p.path.cosinePdf) +
                            directionalOnEscape(p.ray.dir, p.path.specular, p.path.bsdfPdf));
        return false;
    }
#ifdef VKRT_HAS_EMITTERS
    if (hit.emitter != NO_EMITTER)
        p.path.radiance += sampleWeight(p.path.throughput, p.path.media) * emitterOnHit(p.path, p.ray, hit);
#endif
    aovSurfaceHit(hit);
    if (hitsLight(hit)) {
        aovEnd();
        return false; // a light is black: its emission, just added, is all it gives
    }
    if (p.depth == u.maxDepth + 1u)
        return false; // a light or the sky could still end this path, a surface cannot
#ifdef VKRT_HAS_MATERIALS
    p.path.media = mediaAtSurface(p.path.media, hit);
    Material m = withVertexColor(materials[hit.material], hit);
#ifdef VKRT_HAS_TEXTURES
    p.pathLength += hit.t;
    m = texturedMaterial(m, hit, p.ray.dir, p.pathLength);
#endif
    vec3 n = hit.front ? hit.normal : -hit.normal;
    vec3 ns = shadingSide(hit, n);
    vec3 wo = -p.ray.dir;
#if defined(VKRT_MATERIAL_ROUGH_DIELECTRIC) || defined(VKRT_PBR_TRANSMISSION)
    m = withInterfaceEta(m, surfaceEta(p.path.media, hit)); // its eval and pdf need the crossing's eta
#endif
    aovScatter(m, ns);
    bool lit = !scattersIntoDeltasOnly(m);
    vec3 origin = offsetRayOrigin(hit.position, hit.error, n);
    LightReservoir r;
    float bsdfPdf, roulette;
    BsdfSample s = scatterAtVertex(m, hit, ns, wo, origin, surfaceEta(p.path.media, hit), lit, rng, r, bsdfPdf, roulette);
    if (lit)
        estimateDirectLight(p, r, n, ns, origin, shadow);
    if (s.weight == vec3(0.0))
        return false;
    p.path.throughput *= s.weight;
    p.path.specular = s.specular;
    p.path.bsdfPdf = s.specular ? 0.0 : bsdfPdf;
    p.path.cosinePdf = max(dot(ns, s.dir), 0.0) * INV_PI;
    if (s.transmitted && boundsMedium(m))
        p.path.media = refractThrough(p.path.media, hit);
    if (!survivesRoulette(p.path, p.depth, roulette))
        return false;
    p.ray = Ray(offsetRayOrigin(hit.position, hit.error, continuationSide(n, ns, s)), s.dir);
    ++p.depth;
    return true;
#else
    return false; // no surfaces: every ray escapes or finds a light above
#endif
}

// Adds the light of the vertex's shadow ray, which found something (blocked) or not.
void addShadowedLight(inout PathTracer p, ShadowTest shadow, bool blocked)
{
    // shadowTransmittance's opaque case (lib/lights.glsl), with the vertex's values.
    vec3 transmittance = blocked ? vec3(0.0) : beerLambert(shadow.absorption, shadow.dist);
    p.path.radiance += shadow.weight * (shadow.light * transmittance);
}

// Kernels that walk vkrt's own BVH trace the segment and the shadow ray from
// one call site (a loop of one or two passes): a driver that inlines every
// call, as lavapipe does, then compiles the walk once instead of twice
// (tests/gpu/inline_copies_test.cpp). The others trace each ray at its own
// site: without meshes the records' loop is short and the loop's own cost
// outweighed the smaller kernel, and a ray query compiled no faster from one
// site while its samples/s fell (docs/performance.md, round four, has the
// figures).
#if defined(VKRT_HAS_MESHES) && !defined(VKRT_ACCEL_DRIVER)
#define VKRT_ONE_TRACE_SITE
#endif

// Traces the path's next segment, adds what it finds and scatters, then
// traces the vertex's shadow ray and adds its light; false once the path has
// ended (p.path.radiance is then its sample). The shadow ray is traced after
// the vertex has scattered: it uses no random numbers, and its light is
// added before anything the next segment finds, so the sample is the same
// bit for bit as when it was traced first.
bool advancePath(inout PathTracer p, inout Sampler rng)
{
    ++g_loopIterations;
    ShadowTest shadow;
    shadow.pending = false;
#ifdef VKRT_ONE_TRACE_SITE
    bool tracingShadow = false;
    bool continues = false;
    for (;;) {
        Ray ray = tracingShadow ? shadow.ray : p.ray;
        HitId id;
        bool found = findHit(ray, tracingShadow ? shadow.dist : FLT_MAX, tracingShadow, id);
        if (tracingShadow) {
            addShadowedLight(p, shadow, found);
            return continues;
        }
        SurfaceHit hit;
        if (found)
            hit = describeHit(ray, id);
        continues = scatterAtHit(p, found, hit, rng, shadow);
        if (!shadow.pending)
            return continues;
        tracingShadow = true;
    }
    return false; // not reached
#else
    HitId id;
    bool found = findHit(p.ray, FLT_MAX, false, id);
    SurfaceHit hit;
    if (found)
        hit = describeHit(p.ray, id);
    bool continues = scatterAtHit(p, found, hit, rng, shadow);
    if (shadow.pending) {
        HitId unused;
        addShadowedLight(p, shadow, findHit(shadow.ray, shadow.dist, true, unused));
    }
    return continues;
#endif
}

#endif

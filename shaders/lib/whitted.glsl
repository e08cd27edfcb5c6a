// Whitted-style integrator, faithful to the seed renderer: at every surface,
// direct light from point lights (hard shadows) and emitters (triangle lights
// and emissive meshes: one sample of one emitter, chosen in proportion to
// power, per frame: soft shadows converge over frames), then one
// continuation ray chosen by the material's scattering model (perfect
// specular, Lambert, glossy, Fresnel-weighted dielectric reflection or
// refraction), up to max_depth. A light is seen only along purely specular
// chains from the camera (in mirrors and through glass); after any diffuse or
// glossy bounce light arrives only through shadow rays, as in the seed, so
// there are no caustics. Also as in the seed, refraction carries no
// radiance scaling by eta^2 (the path integrator's does: lib/media.glsl).
// Documented in docs/whitted.md.
#ifndef VKRT_WHITTED_GLSL
#define VKRT_WHITTED_GLSL

struct PathState {
    vec3 radiance;
    vec3 throughput;
    MediumStack media; // the dielectrics the ray travels in
    bool countEmission;
#ifdef VKRT_ENVIRONMENT_SAMPLING
    bool specular;     // the last scattering was a delta event (or the camera)
    float bsdfPdf;     // solid-angle pdf of the last BSDF sample
    float cosinePdf;   // ... and its density in the cosine lobe about that vertex's shading normal
#endif
};

// An emitter (triangle light or emissive mesh) seen along a specular chain
// from the camera.
void addEmitterRadiance(inout PathState path, Ray ray, SurfaceHit hit)
{
#ifdef VKRT_HAS_EMITTERS
    if (path.countEmission && hit.emitter != NO_EMITTER) {
        Emitter e = emitters[hit.emitter];
        path.radiance += path.throughput * emitterRadiance(e, -ray.dir, emitterUvAtHit(hit));
    }
#endif
}

vec3 traceWhitted(Ray ray, inout Sampler rng)
{
#ifdef VKRT_ENVIRONMENT_SAMPLING
    PathState path = PathState(vec3(0.0), vec3(1.0), cameraMedia(), true, true, 0.0, 0.0);
#else
    PathState path = PathState(vec3(0.0), vec3(1.0), cameraMedia(), true);
#endif
#ifdef VKRT_HAS_TEXTURES
    float pathLength = 0.0; // from the camera, for the textures' ray cones
#endif
    for (uint depth = 1u; depth <= u.maxDepth; ++depth) {
        ++g_loopIterations;
        SurfaceHit hit;
        bool missed = !traceClosest(ray, FLT_MAX, hit);
        // Beer-Lambert over the segment just travelled inside a dielectric.
        path.throughput *= beerLambert(mediumAbsorption(path.media), missed ? FLT_MAX : hit.t);
        if (missed) {
            aovEnd();
#ifdef VKRT_ENVIRONMENT_SAMPLING
            // The map is also sampled at every vertex: MIS as in the path integrator.
            path.radiance +=
                path.throughput * environmentOnEscape(ray.dir, path.specular, path.bsdfPdf, path.cosinePdf);
#else
            path.radiance += path.throughput * environmentRadiance(ray.dir);
#endif
            // A soft sun is seen only along specular chains, as emitters are.
            if (path.countEmission)
                path.radiance += path.throughput * directionalOnEscape(ray.dir, true, 0.0);
            break;
        }
        addEmitterRadiance(path, ray, hit);
        aovSurfaceHit(hit);
        if (hitsLight(hit)) {
            aovEnd();
            break;
        }
#ifdef VKRT_HAS_MATERIALS
        path.media = mediaAtSurface(path.media, hit);
        Material m = withVertexColor(materials[hit.material], hit);
#ifdef VKRT_HAS_TEXTURES
        pathLength += hit.t;
        m = texturedMaterial(m, hit, ray.dir, pathLength);
#endif
        vec3 n = hit.front ? hit.normal : -hit.normal;
        vec3 ns = shadingSide(hit, n);
        vec3 wo = -ray.dir;
#if defined(VKRT_MATERIAL_ROUGH_DIELECTRIC) || defined(VKRT_PBR_TRANSMISSION)
        m = withInterfaceEta(m, surfaceEta(path.media, hit)); // its eval and pdf need the crossing's eta
#endif
        aovScatter(m, ns);
        if (!scattersIntoDeltasOnly(m))
            path.radiance +=
                path.throughput * whittedDirectLight(m, hit, n, ns, wo, path.media, depth < u.maxDepth, rng);
        if (depth == u.maxDepth)
            break;
        float eta = surfaceEta(path.media, hit);
        float bsdfPdf; // for MIS against the environment's samples only
#ifdef VKRT_ENVIRONMENT_SAMPLING
        const bool wantPdf = true;
#else
        const bool wantPdf = false;
#endif
        BsdfSample s = sampleBsdfWeighted(m, ns, wo, eta, sampleNext4D(rng).xyz, wantPdf, bsdfPdf);
        if (s.weight == vec3(0.0))
            break;
        path.throughput *= s.weight;
        path.countEmission = path.countEmission && s.specular;
#ifdef VKRT_ENVIRONMENT_SAMPLING
        path.specular = s.specular;
        path.bsdfPdf = s.specular ? 0.0 : bsdfPdf;
        path.cosinePdf = max(dot(ns, s.dir), 0.0) * INV_PI;
#endif
        if (s.transmitted && boundsMedium(m))
            path.media = crossInterface(path.media, hit.material, hit.front);
        ray = Ray(offsetRayOrigin(hit.position, hit.error, continuationSide(n, ns, s)), s.dir);
#endif
    }
    return path.radiance;
}

#endif

// Point lights (`type = "point"`): no area, so never hit (no records to
// intersect); each is sampled on its own, with its own shadow ray in the
// Whitted integrator and as one candidate of the path integrator's reservoir.
// Included twice: by lib/scene.glsl for what rays hit, and by lib/lights.glsl
// (VKRT_LIGHT_SAMPLING) for the sampling, which needs the BSDFs and media.
#ifndef VKRT_LIGHT_POINT_HITS
#define VKRT_LIGHT_POINT_HITS

#ifdef VKRT_HAS_POINT_LIGHTS
VKRT_SCENE_ARRAY(BINDING_POINT_LIGHTS, PointLightBlock, PointLight, pointLights, UNIFORM_POINT_LIGHTS)
#define pointLights VKRT_SCENE_ITEMS(BINDING_POINT_LIGHTS, PointLightBlock, pointLights)
#endif

bool hitOnePointLight(Ray r, TriangleRay tr, uint i, bool anyHit, float tMax, inout HitId hit) { return false; }
VKRT_NO_RECORDS(PointLight)
void describePointLight(Ray r, HitId id, inout SurfaceHit hit) {}

#endif

#if defined(VKRT_LIGHT_SAMPLING) && !defined(VKRT_LIGHT_POINT_SAMPLING)
#define VKRT_LIGHT_POINT_SAMPLING

#ifdef VKRT_HAS_POINT_LIGHTS
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

// The point lights' entries in the light table (VKRT_LIGHT_TABLE): one each.
uint tableEntriesPointLight()
{
#ifdef VKRT_HAS_POINT_LIGHTS
    return u.pointLightCount;
#else
    return 0u;
#endif
}

// Point light i drawn from the light table with density `selection`
// (lib/lights.glsl: tableSelection): its sample divided by it.
LightSample sampleTablePointLight(uint i, float selection, Material m, SurfaceHit hit, vec3 ns, vec3 wo, vec3 origin,
                                  vec4 rnd)
{
#ifdef VKRT_HAS_POINT_LIGHTS
    LightSample s = samplePointLight(pointLights[i], m, hit, ns, wo);
    s.unshadowed /= selection;
    return s;
#else
    return LightSample(vec3(0.0), origin);
#endif
}

// Point light i as the Whitted integrator samples it (its own shadow ray)
// and as a candidate of the path integrator's one shadow ray, with the
// reservoir's number `pick` (lib/lights.glsl: VKRT_LIGHT_LOOPS).
LightSample whittedSamplePointLight(uint i, Material m, SurfaceHit hit, vec3 ns, vec3 wo, vec3 origin, inout Sampler rng)
{
#ifdef VKRT_HAS_POINT_LIGHTS
    return samplePointLight(pointLights[i], m, hit, ns, wo);
#else
    return LightSample(vec3(0.0), origin);
#endif
}

LightSample candidatePointLight(uint i, Material m, SurfaceHit hit, vec3 ns, vec3 wo, vec3 origin, inout Sampler rng,
                                out float pick)
{
    LightSample s = whittedSamplePointLight(i, m, hit, ns, wo, origin, rng);
    pick = sampleNext1D(rng);
    return s;
}

#endif

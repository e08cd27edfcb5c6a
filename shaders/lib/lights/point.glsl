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
// One point light: I / d^2 from its direction (a delta: no density).
// Geometry from the surface point itself; only the shadow ray starts at the
// offset origin (measuring from it would bias 1/d^2 by the offset).
LightArrival arrivalFromPointLight(PointLight light, SurfaceHit hit)
{
    vec3 toLight = light.position - hit.position;
    float distSq = dot(toLight, toLight);
    return LightArrival(toLight * inversesqrt(distSq), light.position, light.intensity / distSq, 0.0);
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
LightArrival sampleTablePointLight(uint i, float selection, SurfaceHit hit, vec3 ns, vec3 origin, vec4 rnd)
{
#ifdef VKRT_HAS_POINT_LIGHTS
    LightArrival a = arrivalFromPointLight(pointLights[i], hit);
    a.radiance /= selection;
    return a;
#else
    return noArrival(origin);
#endif
}

// Point light i as the Whitted integrator samples it (its own shadow ray)
// and as a candidate of the path integrator's one shadow ray, with the
// reservoir's number `pick` (lib/lights.glsl: whittedCandidate, lightCandidate).
LightArrival whittedSamplePointLight(uint i, SurfaceHit hit, vec3 ns, vec3 origin, inout Sampler rng)
{
#ifdef VKRT_HAS_POINT_LIGHTS
    return arrivalFromPointLight(pointLights[i], hit);
#else
    return noArrival(origin);
#endif
}

LightArrival candidatePointLight(uint i, SurfaceHit hit, vec3 ns, vec3 origin, inout Sampler rng, out float pick)
{
    LightArrival a = whittedSamplePointLight(i, hit, ns, origin, rng);
    pick = sampleNext1D(rng);
    return a;
}

#endif

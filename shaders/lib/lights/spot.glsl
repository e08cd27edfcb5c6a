// Spot lights (`type = "spot"`): point lights whose intensity falls off away
// from their axis (glTF KHR_lights_punctual's falloff, shared/SceneTypes.h).
// No area, so never hit; each is sampled on its own, like a point light.
// Included twice: by lib/scene.glsl for what rays hit, and by lib/lights.glsl
// (VKRT_LIGHT_SAMPLING) for the sampling, which needs the BSDFs and media.
#ifndef VKRT_LIGHT_SPOT_HITS
#define VKRT_LIGHT_SPOT_HITS

#ifdef VKRT_HAS_SPOT_LIGHTS
VKRT_SCENE_ARRAY(BINDING_SPOT_LIGHTS, SpotLightBlock, SpotLight, spotLights, UNIFORM_SPOT_LIGHTS)
#define spotLights VKRT_SCENE_ITEMS(BINDING_SPOT_LIGHTS, SpotLightBlock, spotLights)
#endif

bool hitOneSpotLight(Ray r, TriangleRay tr, uint i, bool anyHit, float tMax, inout HitId hit) { return false; }
VKRT_NO_RECORDS(SpotLight)
void describeSpotLight(Ray r, HitId id, inout SurfaceHit hit) {}

#endif

#if defined(VKRT_LIGHT_SAMPLING) && !defined(VKRT_LIGHT_SPOT_SAMPLING)
#define VKRT_LIGHT_SPOT_SAMPLING

#ifdef VKRT_HAS_SPOT_LIGHTS
// The fraction of the axis intensity emitted towards `toPoint` (unit, from the light).
float spotFalloff(SpotLight light, vec3 toPoint)
{
    float cosAngle = dot(light.axis, toPoint);
    if (light.falloffScale == 0.0)
        return cosAngle >= light.cosOuter ? 1.0 : 0.0;
    float t = clamp((cosAngle - light.cosOuter) * light.falloffScale, 0.0, 1.0);
    return t * t;
}

// One spot light: I * falloff / d^2, as a point light (lib/lights/point.glsl:
// geometry from the surface point itself).
LightArrival arrivalFromSpotLight(SpotLight light, SurfaceHit hit)
{
    vec3 toLight = light.position - hit.position;
    float distSq = dot(toLight, toLight);
    vec3 wi = toLight * inversesqrt(distSq);
    float falloff = spotFalloff(light, -wi);
    if (falloff == 0.0)
        return noArrival(light.position);
    return LightArrival(wi, light.position, light.intensity * (falloff / distSq), 0.0);
}
#endif

// The spot lights' entries in the light table (VKRT_LIGHT_TABLE): one each.
uint tableEntriesSpotLight()
{
#ifdef VKRT_HAS_SPOT_LIGHTS
    return u.spotLightCount;
#else
    return 0u;
#endif
}

// Spot light i drawn from the light table with density `selection`.
LightArrival sampleTableSpotLight(uint i, float selection, SurfaceHit hit, vec3 ns, vec3 origin, vec4 rnd)
{
#ifdef VKRT_HAS_SPOT_LIGHTS
    LightArrival a = arrivalFromSpotLight(spotLights[i], hit);
    a.radiance /= selection;
    return a;
#else
    return noArrival(origin);
#endif
}

// Spot light i for the Whitted integrator and as a candidate of the path
// integrator's one shadow ray (lib/lights.glsl: whittedCandidate, lightCandidate).
LightArrival whittedSampleSpotLight(uint i, SurfaceHit hit, vec3 ns, vec3 origin, inout Sampler rng)
{
#ifdef VKRT_HAS_SPOT_LIGHTS
    return arrivalFromSpotLight(spotLights[i], hit);
#else
    return noArrival(origin);
#endif
}

LightArrival candidateSpotLight(uint i, SurfaceHit hit, vec3 ns, vec3 origin, inout Sampler rng, out float pick)
{
    LightArrival a = whittedSampleSpotLight(i, hit, ns, origin, rng);
    pick = sampleNext1D(rng);
    return a;
}

#endif

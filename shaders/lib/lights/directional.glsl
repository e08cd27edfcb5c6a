// Directional lights (`type = "directional"`, a sun): infinitely far away,
// so never hit by a ray that has a surface to find (no records to
// intersect). A delta sun is sampled on its own; a soft sun (a cone of
// directions) is sampled uniformly in its cone and also found by rays that
// escape towards it (directionalOnEscape), weighted against BSDF sampling
// with the power heuristic in the path integrator.
// Included twice: by lib/scene.glsl for what rays hit, and by lib/lights.glsl
// (VKRT_LIGHT_SAMPLING) for the sampling, which needs the BSDFs and media.
#ifndef VKRT_LIGHT_DIRECTIONAL_HITS
#define VKRT_LIGHT_DIRECTIONAL_HITS

#ifdef VKRT_HAS_DIRECTIONAL_LIGHTS
VKRT_SCENE_ARRAY(BINDING_DIRECTIONAL_LIGHTS, DirectionalLightBlock, DirectionalLight, directionalLights,
                 UNIFORM_DIRECTIONAL_LIGHTS)
#define directionalLights VKRT_SCENE_ITEMS(BINDING_DIRECTIONAL_LIGHTS, DirectionalLightBlock, directionalLights)
#endif

bool hitOneDirectionalLight(Ray r, TriangleRay tr, uint i, bool anyHit, float tMax, inout HitId hit) { return false; }
VKRT_NO_RECORDS(DirectionalLight)
void describeDirectionalLight(Ray r, HitId id, inout SurfaceHit hit) {}

#endif

#if defined(VKRT_LIGHT_SAMPLING) && !defined(VKRT_LIGHT_DIRECTIONAL_SAMPLING)
#define VKRT_LIGHT_DIRECTIONAL_SAMPLING

#ifdef VKRT_HAS_DIRECTIONAL_LIGHTS
// Solid-angle density of uniform sampling of a soft sun's cone.
float sunConePdf(DirectionalLight light) { return 1.0 / (2.0 * PI * light.oneMinusCos); }

// Whether `dir` lies in a soft sun's cone: sin^2 of the angle to its axis,
// from a cross product (accurate for small angles, where 1 - cos is not).
bool insideSunCone(DirectionalLight light, vec3 dir)
{
    vec3 c = cross(dir, light.toLight);
    return light.oneMinusCos > 0.0 && dot(dir, light.toLight) > 0.0 && dot(c, c) <= light.sin2Alpha;
}

// A direction uniform in the cone of half angle alpha around `axis`, with
// t = 1 - cos(theta) drawn uniformly in [0, 1 - cos(alpha)].
vec3 sampleSunCone(DirectionalLight light, vec2 rnd)
{
    float t = rnd.x * light.oneMinusCos;
    float sinTheta = sqrt(max(0.0, t * (2.0 - t)));
    float phi = 2.0 * PI * rnd.y;
    return fromLocal(vec3(sinTheta * cos(phi), sinTheta * sin(phi), 1.0 - t), light.toLight);
}

// One sun's light at a surface point: E for a delta sun (no density), L /
// pdf for a direction drawn in a soft sun's cone (pdf: its density, for MIS
// in the path integrator); both divided by `selection`, the density of
// having chosen this sun (1 where every sun is sampled; lib/lights.glsl:
// tableSelection). The shadow ray's target is far along the direction
// (FAR_LIGHT_DISTANCE).
LightArrival sampleDirectionalLight(DirectionalLight light, float selection, vec3 origin, vec2 rnd)
{
    bool soft = light.oneMinusCos > 0.0;
    vec3 wi = soft ? sampleSunCone(light, rnd) : light.toLight;
    vec3 target = origin + wi * FAR_LIGHT_DISTANCE;
    if (!soft)
        return LightArrival(wi, target, light.radiance / selection, 0.0);
    float lightPdf = sunConePdf(light) * selection;
    return LightArrival(wi, target, light.radiance / lightPdf, lightPdf);
}
#endif

// The suns' entries in the light table (VKRT_LIGHT_TABLE): one each.
uint tableEntriesDirectionalLight()
{
#ifdef VKRT_HAS_DIRECTIONAL_LIGHTS
    return u.directionalLightCount;
#else
    return 0u;
#endif
}

// Sun i drawn from the light table with density `selection`.
LightArrival sampleTableDirectionalLight(uint i, float selection, SurfaceHit hit, vec3 ns, vec3 origin, vec4 rnd)
{
#ifdef VKRT_HAS_DIRECTIONAL_LIGHTS
    return sampleDirectionalLight(directionalLights[i], selection, origin, rnd.xy);
#else
    return noArrival(origin);
#endif
}

// The density of having chosen light i of a kind (lib/lights.glsl).
float lightSelection(int kind, uint i);

// Sun i for the Whitted integrator (its cone sampled with 2 numbers) and as
// a candidate of the path integrator's one shadow ray (4 numbers: the cone's
// 2 and the reservoir's; lib/lights.glsl: whittedCandidate, lightCandidate).
LightArrival whittedSampleDirectionalLight(uint i, SurfaceHit hit, vec3 ns, vec3 origin, inout Sampler rng)
{
#ifdef VKRT_HAS_DIRECTIONAL_LIGHTS
    return sampleDirectionalLight(directionalLights[i], 1.0, origin, sampleNext2D(rng));
#else
    return noArrival(origin);
#endif
}

LightArrival candidateDirectionalLight(uint i, SurfaceHit hit, vec3 ns, vec3 origin, inout Sampler rng, out float pick)
{
#ifdef VKRT_HAS_DIRECTIONAL_LIGHTS
    vec4 u4 = sampleNext4D(rng);
    pick = u4.z;
    return sampleDirectionalLight(directionalLights[i], 1.0, origin, u4.xy);
#else
    pick = 0.0;
    return noArrival(origin);
#endif
}

// The soft suns a ray that escaped along `dir` sees: each with weight 1 after
// a specular bounce or from the camera (`specular`), else its MIS weight
// against the BSDF sample of density bsdfPdf (path integrator). The soft
// suns come first (SceneUniforms::softDirectionalLightCount): a delta sun is
// never seen, so a scene of many of them costs an escaped ray nothing.
vec3 directionalOnEscape(vec3 dir, bool specular, float bsdfPdf)
{
    vec3 radiance = vec3(0.0);
#ifdef VKRT_HAS_DIRECTIONAL_LIGHTS
    for (uint i = 0u; i < u.softDirectionalLightCount; ++i) {
        ++g_loopIterations;
        DirectionalLight light = directionalLights[i];
        if (!insideSunCone(light, dir))
            continue;
        float weight =
            specular ? 1.0 : powerHeuristic(bsdfPdf, sunConePdf(light) * lightSelection(LIGHT_DIRECTIONAL, i));
        radiance += light.radiance * weight;
    }
#endif
    return radiance;
}

#endif

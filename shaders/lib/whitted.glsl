// Whitted-style shading: direct light from point lights with hard shadows.
#ifndef VKRT_WHITTED_GLSL
#define VKRT_WHITTED_GLSL

// Radiance leaving a Lambert surface towards the viewer from all point lights:
// sum of (albedo / pi) * I * cos(theta) / d^2 over unshadowed lights.
vec3 directPointLights(SurfaceHit hit, vec3 facingNormal, vec3 albedo)
{
    vec3 radiance = vec3(0.0);
#ifdef VKRT_HAS_POINT_LIGHTS
    vec3 origin = offsetRayOrigin(hit.position, facingNormal);
    for (uint i = 0u; i < u.pointLightCount; ++i) {
        ++g_loopIterations;
        PointLight light = pointLights[i];
        vec3 toLight = light.position - origin;
        float distSq = dot(toLight, toLight);
        float dist = sqrt(distSq);
        vec3 wi = toLight / dist;
        float cosTheta = dot(facingNormal, wi);
        if (cosTheta <= 0.0 || occluded(Ray(origin, wi), dist))
            continue;
        radiance += albedo * INV_PI * light.intensity * (cosTheta / distSq);
    }
#endif
    return radiance;
}

vec3 traceWhitted(Ray ray, inout Sampler rng)
{
#ifndef VKRT_HAS_MATERIALS
    return u.backgroundColor; // a scene without objects
#else
    SurfaceHit hit;
    if (!traceClosest(ray, FLT_MAX, hit))
        return u.backgroundColor;
    vec3 facingNormal = dot(hit.normal, ray.dir) < 0.0 ? hit.normal : -hit.normal;
    Material m = materials[hit.material];
    return directPointLights(hit, facingNormal, m.diffuse);
#endif
}

#endif

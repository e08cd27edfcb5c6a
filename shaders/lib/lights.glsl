// Direct lighting from point and triangle lights, with shadow rays that pass
// through dielectrics (attenuated) and stop at anything else.
#ifndef VKRT_LIGHTS_GLSL
#define VKRT_LIGHTS_GLSL

// Fraction of light that travels from `origin` along `dir` for distance
// tMax. Each dielectric interface passes 1 - F, and the stretch inside a
// dielectric is attenuated by Beer-Lambert; any other surface blocks.
vec3 shadowTransmittance(vec3 origin, vec3 dir, float tMax)
{
#ifndef VKRT_MATERIAL_DIELECTRIC
    return findClosest(Ray(origin, dir), tMax).shape == SHAPE_NONE ? vec3(1.0) : vec3(0.0);
#else
    vec3 target = origin + dir * tMax;
    vec3 transmittance = vec3(1.0);
    for (uint crossing = 0u; crossing < MAX_SHADOW_CROSSINGS; ++crossing) {
        ++g_loopIterations;
        Ray ray = Ray(origin, dir);
        HitId id = findClosest(ray, tMax);
        if (id.shape == SHAPE_NONE)
            return transmittance;
        if (id.shape == SHAPE_LIGHT)
            return vec3(0.0);
        SurfaceHit hit = describeHit(ray, id);
        Material m = materials[hit.material];
        if (m.type != MATERIAL_DIELECTRIC)
            return vec3(0.0);
        bool exiting = dot(dir, hit.normal) > 0.0;
        vec3 n = exiting ? -hit.normal : hit.normal; // faces the arriving ray
        // A shadow ray is a straight line, so its angle with the surface is
        // the one light has on the outside of this interface (for a slab, the
        // refracted ray inside meets the far side at the matching angle).
        // Fresnel reflectance is the same from either side at that pair of
        // angles, so evaluate it as entering from outside: (1 - F(theta))^2
        // through a slab, and no spurious total internal reflection.
        transmittance *= 1.0 - dielectricReflectance(m.fresnel, -dot(dir, n), 1.0 / m.ior, m.ior);
        if (exiting)
            transmittance *= beerLambert(m.absorption, hit.t);
        origin = offsetRayOrigin(hit.position, -n);
        tMax = dot(target - origin, dir);
        if (tMax <= 0.0)
            return transmittance;
    }
    return vec3(0.0); // more interfaces than MAX_SHADOW_CROSSINGS: treated as blocked
#endif
}

// Point lights: f * I * cos / d^2 * transmittance.
vec3 directFromPointLights(Material m, vec3 position, vec3 n, vec3 wo)
{
    vec3 radiance = vec3(0.0);
#ifdef VKRT_HAS_POINT_LIGHTS
    vec3 origin = offsetRayOrigin(position, n);
    for (uint i = 0u; i < u.pointLightCount; ++i) {
        ++g_loopIterations;
        PointLight light = pointLights[i];
        vec3 toLight = light.position - origin;
        float distSq = dot(toLight, toLight);
        float dist = sqrt(distSq);
        vec3 wi = toLight / dist;
        float cosTheta = dot(n, wi);
        if (cosTheta <= 0.0)
            continue;
        vec3 f = evalBsdf(m, n, wo, wi);
        radiance += f * light.intensity * (cosTheta / distSq) * shadowTransmittance(origin, wi, dist);
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

// Triangle lights: one uniformly sampled point per light (pdf = 1 / area):
// f * Le * cos_surface * cos_light / d^2 * area * transmittance.
vec3 directFromTriangleLights(Material m, vec3 position, vec3 n, vec3 wo, inout Sampler rng)
{
    vec3 radiance = vec3(0.0);
#ifdef VKRT_HAS_TRIANGLE_LIGHTS
    vec3 origin = offsetRayOrigin(position, n);
    for (uint i = 0u; i < u.triangleLightCount; ++i) {
        ++g_loopIterations;
        TriangleLight light = triangleLights[i];
        vec3 point = sampleTriangle(light.v0, light.v1, light.v2, sampleNext2D(rng));
        vec3 toLight = point - origin;
        float distSq = dot(toLight, toLight);
        float dist = sqrt(distSq);
        vec3 wi = toLight / dist;
        float cosSurface = dot(n, wi);
        float cosLight = abs(dot(triangleLightNormal(light), wi));
        vec3 le = emittedRadiance(light, -wi);
        if (cosSurface <= 0.0 || cosLight == 0.0 || le == vec3(0.0))
            continue;
        vec3 f = evalBsdf(m, n, wo, wi);
        // Stop just short of the light so it does not shadow itself.
        float tMax = dist * (1.0 - 1.0 / 65536.0);
        radiance += f * le * (cosSurface * cosLight * light.area / distSq) * shadowTransmittance(origin, wi, tMax);
    }
#endif
    return radiance;
}

#endif

// Direct lighting from point and triangle lights, with shadow rays that pass
// through dielectrics (attenuated) and stop at anything else.
#ifndef VKRT_LIGHTS_GLSL
#define VKRT_LIGHTS_GLSL

// Fraction of light that travels from `origin` along `dir` for distance
// tMax. Each dielectric interface passes 1 - F, and the stretch inside a
// dielectric is attenuated by Beer-Lambert; any other surface blocks.
vec3 shadowTransmittance(vec3 origin, vec3 dir, float tMax)
{
    // The path integrator treats glass physically: a shadow ray cannot see a
    // light through it (light arrives through glass by BSDF sampling).
#if !defined(VKRT_MATERIAL_DIELECTRIC) || defined(VKRT_INTEGRATOR_PATH)
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
        // Geometry from the surface point itself; only the shadow ray starts
        // at the offset origin (measuring from it would bias 1/d^2 by the offset).
        vec3 toLight = light.position - position;
        float distSq = dot(toLight, toLight);
        vec3 wi = toLight * inversesqrt(distSq);
        float cosTheta = dot(n, wi);
        if (cosTheta <= 0.0)
            continue;
        vec3 f = evalBsdf(m, n, wo, wi);
        vec3 shadowDir = light.position - origin;
        float shadowDist = length(shadowDir);
        radiance += f * light.intensity * (cosTheta / distSq) * shadowTransmittance(origin, shadowDir / shadowDist, shadowDist);
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
float powerHeuristic(float pdf, float other)
{
    float a = pdf * pdf, b = other * other;
    return a > 0.0 ? a / (a + b) : 0.0;
}

// Density in solid angle of sampling `light` uniformly by area, seen from a
// point at squared distance distSq along a direction with |cos| cosLight.
float triangleLightPdf(float area, float distSq, float cosLight) { return distSq / (cosLight * area); }

// Triangle lights: one uniformly sampled point per light (pdf = 1 / area):
// f * Le * cos_surface * cos_light / d^2 * area * transmittance; the path
// integrator also weighs it against BSDF sampling (MIS).
vec3 directFromTriangleLights(Material m, vec3 position, vec3 n, vec3 wo, inout Sampler rng)
{
    vec3 radiance = vec3(0.0);
#ifdef VKRT_HAS_TRIANGLE_LIGHTS
    vec3 origin = offsetRayOrigin(position, n);
    for (uint i = 0u; i < u.triangleLightCount; ++i) {
        ++g_loopIterations;
        TriangleLight light = triangleLights[i];
        vec3 point = sampleTriangle(light.v0, light.v1, light.v2, sampleNext2D(rng));
        vec3 toLight = point - position;
        float distSq = dot(toLight, toLight);
        vec3 wi = toLight * inversesqrt(distSq);
        float cosSurface = dot(n, wi);
        float cosLight = abs(dot(triangleLightNormal(light), wi));
        vec3 le = emittedRadiance(light, -wi);
        if (cosSurface <= 0.0 || cosLight == 0.0 || le == vec3(0.0))
            continue;
        vec3 f = evalBsdf(m, n, wo, wi);
        // Stop just short of the light so it does not shadow itself.
        vec3 shadowDir = point - origin;
        float shadowDist = length(shadowDir);
        float tMax = shadowDist * (1.0 - 1.0 / 65536.0);
        vec3 contribution = f * le * (cosSurface * cosLight * light.area / distSq);
#ifdef VKRT_INTEGRATOR_PATH
        contribution *= powerHeuristic(triangleLightPdf(light.area, distSq, cosLight), pdfBsdf(m, n, wo, wi));
#endif
        radiance += contribution * shadowTransmittance(origin, shadowDir / shadowDist, tMax);
    }
#endif
    return radiance;
}

#endif

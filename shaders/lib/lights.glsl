// Direct lighting from point and triangle lights, with shadow rays that pass
// through dielectrics (attenuated) and stop at anything else.
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
    if (findClosest(Ray(origin, dir), tMax).shape != SHAPE_NONE)
        return vec3(0.0);
    return beerLambert(mediumAbsorption(media), tMax);
#else
    vec3 target = origin + dir * tMax;
    vec3 transmittance = vec3(1.0);
    for (uint crossing = 0u; crossing < MAX_SHADOW_CROSSINGS; ++crossing) {
        ++g_loopIterations;
        Ray ray = Ray(origin, dir);
        HitId id = findClosest(ray, tMax);
        if (id.shape == SHAPE_NONE)
            return transmittance * beerLambert(mediumAbsorption(media), tMax);
        if (id.shape == SHAPE_LIGHT)
            return vec3(0.0);
        SurfaceHit hit = describeHit(ray, id);
        Material m = materials[hit.material];
        if (m.type != MATERIAL_DIELECTRIC)
            return vec3(0.0);
        transmittance *= beerLambert(mediumAbsorption(media), hit.t);
        // A shadow ray is a straight line, so its angle with the surface is
        // the one light has on the less dense side of this interface (for a
        // slab, the refracted ray inside meets the far side at the matching
        // angle). Fresnel reflectance is the same from either side at that
        // pair of angles, so evaluate it from the less dense side: (1 - F)^2
        // through a slab, and no spurious total internal reflection.
        float eta = interfaceEta(media, hit.material, hit.front);
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

// Point lights: f * I * cos / d^2 * transmittance.
vec3 directFromPointLights(Material m, SurfaceHit hit, vec3 n, vec3 wo, MediumStack media)
{
    vec3 radiance = vec3(0.0);
#ifdef VKRT_HAS_POINT_LIGHTS
    vec3 position = hit.position;
    vec3 origin = offsetRayOrigin(position, hit.error, n);
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
        radiance += f * light.intensity * (cosTheta / distSq) * transmittanceTo(light.position, origin, n, media);
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
// Written as 1 / (1 + (other / pdf)^2): squaring a huge pdf (a light seen
// almost edge-on) would overflow to inf / inf = NaN.
float powerHeuristic(float pdf, float other)
{
    if (!(pdf > 0.0))
        return 0.0;
    float ratio = other / pdf;
    return isinf(pdf) ? (isinf(other) ? 0.5 : 1.0) : 1.0 / (1.0 + ratio * ratio);
}

// Density in solid angle of sampling `light` uniformly by area, seen from a
// point at squared distance distSq along a direction with |cos| cosLight.
float triangleLightPdf(float area, float distSq, float cosLight) { return distSq / (cosLight * area); }

// Triangle lights: one uniformly sampled point per light (pdf = 1 / area):
// f * Le * cos_surface * cos_light / d^2 * area * transmittance; the path
// integrator also weighs it against BSDF sampling (MIS).
vec3 directFromTriangleLights(Material m, SurfaceHit hit, vec3 n, vec3 wo, MediumStack media, inout Sampler rng)
{
    vec3 radiance = vec3(0.0);
#ifdef VKRT_HAS_TRIANGLE_LIGHTS
    vec3 position = hit.position;
    vec3 origin = offsetRayOrigin(position, hit.error, n);
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
        vec3 contribution = f * le * (cosSurface * cosLight * light.area / distSq);
#ifdef VKRT_INTEGRATOR_PATH
        contribution *= powerHeuristic(triangleLightPdf(light.area, distSq, cosLight), pdfBsdf(m, n, wo, wi));
#endif
        // Aim just short of the light so it does not shadow itself.
        vec3 target = mix(origin, point, 1.0 - 1.0 / 65536.0);
        radiance += contribution * transmittanceTo(target, origin, n, media);
    }
#endif
    return radiance;
}

#endif

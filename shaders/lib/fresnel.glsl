// Fresnel reflectance. Cosines are clamped to [0, 1], so inputs a rounding
// step outside the range still give finite results.
#ifndef VKRT_FRESNEL_GLSL
#define VKRT_FRESNEL_GLSL

// R0 = ((n - 1) / (n + 1))^2, divided before squaring so huge IORs stay finite.
float schlickR0(float ior)
{
    float r = (ior - 1.0) / (ior + 1.0);
    return r * r;
}

// Schlick's approximation R = R0 + (1 - R0)(1 - cos)^5.
float fresnelSchlick(float cosTheta, float r0)
{
    float m = 1.0 - clamp(cosTheta, 0.0, 1.0);
    float m2 = m * m;
    return r0 + (1.0 - r0) * (m2 * m2 * m);
}

// sin^2 of the transmitted angle, (eta sin_i)^2: formed from sin_i so that a
// huge eta at normal incidence gives 0, not inf * 0 = NaN.
float transmittedSin2(float cosI, float eta)
{
    float sinT = eta * sqrt(max(0.0, 1.0 - cosI * cosI));
    return sinT * sinT;
}

// Exact unpolarized Fresnel reflectance of a dielectric interface. `eta` is
// n_incident / n_transmitted, cosI the incident cosine; 1 under total
// internal reflection.
float fresnelExact(float cosI, float eta)
{
    if (eta == 1.0)
        return 0.0; // index-matched: no interface (the formula would round to up to 1 near grazing)
    cosI = clamp(cosI, 0.0, 1.0);
    float sin2T = transmittedSin2(cosI, eta);
    if (sin2T >= 1.0)
        return 1.0;
    float cosT = sqrt(1.0 - sin2T);
    float rs = (eta * cosI - cosT) / (eta * cosI + cosT);
    float rp = (cosI - eta * cosT) / (cosI + eta * cosT);
    return 0.5 * (rs * rs + rp * rp);
}

// Schlick for a dielectric interface: R0 from the ratio of the two indices
// ((1 - eta) / (1 + eta))^2, the same from either side; the angle on the less
// dense side enters the formula (the transmitted angle when light leaves the
// denser medium), and total internal reflection gives 1.
float fresnelSchlickDielectric(float cosI, float eta)
{
    cosI = clamp(cosI, 0.0, 1.0);
    float sin2T = transmittedSin2(cosI, eta);
    if (sin2T >= 1.0)
        return 1.0;
    float cosT = sqrt(1.0 - sin2T);
    return fresnelSchlick(eta > 1.0 ? cosT : cosI, schlickR0(eta));
}

// A dielectric interface's reflectance in the material's mode (eta = n_i / n_t).
float dielectricReflectance(uint mode, float cosI, float eta)
{
    float f = 0.0;
    if (mode == FRESNEL_EXACT)
        f = fresnelExact(cosI, eta);
    if (mode == FRESNEL_SCHLICK)
        f = fresnelSchlickDielectric(cosI, eta);
#ifdef VKRT_TEST_FRESNEL_SCALE
    // Test hook: a deliberately wrong Fresnel term, to prove the statistical
    // tests catch a small bias.
    f = min(1.0, f * VKRT_TEST_FRESNEL_SCALE);
#endif
    return f;
}

// Snell refraction of the incident direction -wo at unit normal n (on the side
// of wo), eta = n_i / n_t; returns vec3(0) under total internal reflection.
// Built from the tangential part eta (-wo + cos_i n), whose length sin_t is
// below 1, so no term overflows for any finite eta (GLSL's refract forms eta^2).
vec3 refractDirection(vec3 wo, vec3 n, float eta)
{
    float cosI = clamp(dot(n, wo), 0.0, 1.0);
    float sin2T = transmittedSin2(cosI, eta);
    if (sin2T >= 1.0)
        return vec3(0.0);
    vec3 tangential = eta * (cosI * n - wo);
    return normalize(tangential - sqrt(1.0 - sin2T) * n);
}

// Reflection strength of mirror and glossy surfaces (R0 from their IOR).
float conductorLikeReflectance(uint mode, float cosTheta, float ior)
{
    return mode == FRESNEL_SCHLICK ? fresnelSchlick(cosTheta, schlickR0(ior)) : 1.0;
}

// Beer-Lambert transmittance exp(-kappa t). kappa = 0 gives 1 even when
// t = inf (0 * inf would be NaN); exp(-huge) underflows to exactly 0.
vec3 beerLambert(vec3 kappa, float t)
{
    return vec3(kappa.x > 0.0 ? exp(-kappa.x * t) : 1.0,
                kappa.y > 0.0 ? exp(-kappa.y * t) : 1.0,
                kappa.z > 0.0 ? exp(-kappa.z * t) : 1.0);
}

#endif

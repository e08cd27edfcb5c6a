// Scattering models shared by the integrators. Radiometric conventions: f is
// the BRDF (1/sr); `n` is the unit normal on the side of wo. Every material's
// code is compiled only when the scene uses that material type.
#ifndef VKRT_BSDF_GLSL
#define VKRT_BSDF_GLSL

struct BsdfSample {
    vec3 dir;
    vec3 weight;      // f * cos / pdf (or the specular reflectance / transmittance)
    bool specular;    // a delta direction: lights cannot be sampled for it
    bool transmitted; // crossed the surface
};

bool isDeltaMaterial(uint type) { return type == MATERIAL_MIRROR || type == MATERIAL_DIELECTRIC; }

// Normalized Phong lobe (Lafortune & Willems 1994): (e + 2) / (2 pi) cos^e(alpha),
// alpha between wi and the mirror direction of wo.
float phongLobe(vec3 n, vec3 wo, vec3 wi, float exponent)
{
    float cosAlpha = dot(reflect(-wo, n), wi);
    return (exponent + 2.0) * (0.5 * INV_PI) * powSafe(cosAlpha, exponent);
}

float phongDiffuseProbability(Material m)
{
    float d = luminance(m.diffuse), s = luminance(m.specular);
    return d + s > 0.0 ? d / (d + s) : 1.0;
}

// f(wo, wi) of the non-delta materials.
vec3 evalBsdf(Material m, vec3 n, vec3 wo, vec3 wi)
{
    if (dot(n, wi) <= 0.0 || dot(n, wo) <= 0.0)
        return vec3(0.0);
#ifdef VKRT_MATERIAL_LAMBERT
    if (m.type == MATERIAL_LAMBERT)
        return m.diffuse * INV_PI;
#endif
#ifdef VKRT_MATERIAL_PHONG
    if (m.type == MATERIAL_PHONG)
        return m.diffuse * INV_PI + m.specular * phongLobe(n, wo, wi, m.exponent);
#endif
#ifdef VKRT_MATERIAL_GLOSSY
    if (m.type == MATERIAL_GLOSSY)
        return m.specular * conductorLikeReflectance(m.fresnel, dot(n, wo), m.ior) * phongLobe(n, wo, wi, m.exponent);
#endif
    return vec3(0.0);
}

// Solid-angle density with which sampleBsdf picks wi (non-delta materials);
// multiple importance sampling weighs light samples against it.
float pdfBsdf(Material m, vec3 n, vec3 wo, vec3 wi)
{
    float cosI = dot(n, wi);
    if (cosI <= 0.0 || dot(n, wo) <= 0.0)
        return 0.0;
#ifdef VKRT_MATERIAL_LAMBERT
    if (m.type == MATERIAL_LAMBERT)
        return cosI * INV_PI;
#endif
#ifdef VKRT_MATERIAL_PHONG
    if (m.type == MATERIAL_PHONG) {
        float pd = phongDiffuseProbability(m);
        return pd * cosI * INV_PI + (1.0 - pd) * phongLobePdf(dot(reflect(-wo, n), wi), m.exponent);
    }
#endif
#ifdef VKRT_MATERIAL_GLOSSY
    if (m.type == MATERIAL_GLOSSY)
        return phongLobePdf(dot(reflect(-wo, n), wi), m.exponent);
#endif
    return 0.0;
}

BsdfSample noScatter() { return BsdfSample(vec3(0.0, 0.0, 1.0), vec3(0.0), false, false); }

#ifdef VKRT_MATERIAL_PHONG
// One-sample mixture of the diffuse and lobe densities; weight = f cos / pdf.
BsdfSample samplePhong(Material m, vec3 n, vec3 wo, vec3 u)
{
    float pd = phongDiffuseProbability(m);
    vec3 r = reflect(-wo, n);
    vec3 wi = u.z < pd ? sampleCosineHemisphere(n, u.xy) : samplePhongLobe(r, m.exponent, u.xy);
    float cosI = dot(n, wi);
    if (cosI <= 0.0)
        return noScatter();
    float pdf = pd * cosI * INV_PI + (1.0 - pd) * phongLobePdf(dot(r, wi), m.exponent);
    if (!(pdf > 0.0))
        return noScatter(); // a lobe sample rounded onto the lobe's edge
    return BsdfSample(wi, evalBsdf(m, n, wo, wi) * cosI / pdf, false, false);
}
#endif

#ifdef VKRT_MATERIAL_GLOSSY
// Samples the lobe exactly: f cos / pdf = F ks (e + 2) / (e + 1) cos(theta_i).
BsdfSample sampleGlossy(Material m, vec3 n, vec3 wo, vec2 u)
{
    vec3 wi = samplePhongLobe(reflect(-wo, n), m.exponent, u);
    float cosI = dot(n, wi);
    if (cosI <= 0.0)
        return noScatter(); // the lobe dips below the surface: absorbed
    float fresnel = conductorLikeReflectance(m.fresnel, dot(n, wo), m.ior);
    return BsdfSample(wi, m.specular * fresnel * ((m.exponent + 2.0) / (m.exponent + 1.0)) * cosI, false, false);
}
#endif

#ifdef VKRT_MATERIAL_DIELECTRIC
// Reflects with probability F, else refracts (Snell's law); each branch
// carries weight 1 because its probability equals its Fresnel factor.
// eta = n_incident / n_transmitted for this crossing (lib/media.glsl).
BsdfSample sampleDielectric(Material m, vec3 n, vec3 wo, float eta, float u)
{
    float reflectance = dielectricReflectance(m.fresnel, dot(n, wo), eta);
    vec3 refracted = refractDirection(wo, n, eta);
    if (u < reflectance || refracted == vec3(0.0))
        return BsdfSample(reflect(-wo, n), vec3(1.0), true, false);
    return BsdfSample(refracted, vec3(1.0), true, true);
}
#endif

// eta: n_incident / n_transmitted, used by dielectrics only.
BsdfSample sampleBsdf(Material m, vec3 n, vec3 wo, float eta, vec3 u)
{
#ifdef VKRT_MATERIAL_LAMBERT
    if (m.type == MATERIAL_LAMBERT)
        return BsdfSample(sampleCosineHemisphere(n, u.xy), m.diffuse, false, false);
#endif
#ifdef VKRT_MATERIAL_PHONG
    if (m.type == MATERIAL_PHONG)
        return samplePhong(m, n, wo, u);
#endif
#ifdef VKRT_MATERIAL_MIRROR
    if (m.type == MATERIAL_MIRROR)
        return BsdfSample(reflect(-wo, n), m.specular * conductorLikeReflectance(m.fresnel, dot(n, wo), m.ior), true,
                          false);
#endif
#ifdef VKRT_MATERIAL_GLOSSY
    if (m.type == MATERIAL_GLOSSY)
        return sampleGlossy(m, n, wo, u.xy);
#endif
#ifdef VKRT_MATERIAL_DIELECTRIC
    if (m.type == MATERIAL_DIELECTRIC)
        return sampleDielectric(m, n, wo, eta, u.z);
#endif
    return noScatter();
}

#endif

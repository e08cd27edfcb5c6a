// Scattering models shared by the integrators. Radiometric conventions: f is
// the BRDF (1/sr); `n` is the unit normal on the side of wo. Every material's
// code is compiled only when the scene uses that material type.
// Each material kind of the registry (shared/Kinds.h) has three functions
// named after its Type, which evalBsdf, pdfBsdf and sampleBsdf dispatch to:
//   evalType(m, n, wo, wi)          f(wo, wi) (0 for a delta material)
//   pdfType(m, n, wo, wi, cosI)     the solid-angle density of sampleType
//   sampleType(m, n, wo, eta, u)    a sampled direction and its weight
// Both sides of the surface test are done by the dispatchers. A material
// the variant lacks gets empty ones (VKRT_ABSENT_MATERIAL).
#ifndef VKRT_BSDF_GLSL
#define VKRT_BSDF_GLSL

struct BsdfSample {
    vec3 dir;
    vec3 weight;      // f * cos / pdf (or the specular reflectance / transmittance)
    bool specular;    // a delta direction: lights cannot be sampled for it
    bool transmitted; // crossed the surface
};

// The side of the surface a continuation ray leaves from (its offset
// direction): the one the sampled direction points into. With shading
// normals (ns != n) a reflection about ns can point below the geometric
// surface, or a refraction above it; the ray then leaves through that side,
// as Mitsuba's spawn_ray does, instead of re-hitting the surface at once.
vec3 continuationSide(vec3 n, vec3 ns, BsdfSample s)
{
    vec3 side = s.transmitted ? -n : n;
#ifdef VKRT_HAS_MESH_NORMALS // only meshes' vertex normals make ns differ from n
    if (ns != n && dot(s.dir, side) < 0.0)
        side = -side;
#endif
    return side;
}

#define VKRT_IS_DELTA_KIND(KIND, Type, name, value, delta) || (delta != 0 && type == MATERIAL_##KIND)
bool isDeltaMaterial(uint type) { return false VKRT_MATERIAL_KINDS(VKRT_IS_DELTA_KIND); }

vec3 evalBsdf(Material m, vec3 n, vec3 wo, vec3 wi);

BsdfSample noScatter() { return BsdfSample(vec3(0.0, 0.0, 1.0), vec3(0.0), false, false); }

#define VKRT_ABSENT_MATERIAL(Type)                                                                  \
    vec3 eval##Type(Material m, vec3 n, vec3 wo, vec3 wi) { return vec3(0.0); }                     \
    float pdf##Type(Material m, vec3 n, vec3 wo, vec3 wi, float cosI) { return 0.0; }              \
    BsdfSample sample##Type(Material m, vec3 n, vec3 wo, float eta, vec3 u) { return noScatter(); }

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

// ------------------------------------------------------------------ lambert

#ifdef VKRT_MATERIAL_LAMBERT
vec3 evalLambert(Material m, vec3 n, vec3 wo, vec3 wi) { return m.diffuse * INV_PI; }
float pdfLambert(Material m, vec3 n, vec3 wo, vec3 wi, float cosI) { return cosI * INV_PI; }
BsdfSample sampleLambert(Material m, vec3 n, vec3 wo, float eta, vec3 u)
{
    return BsdfSample(sampleCosineHemisphere(n, u.xy), m.diffuse, false, false);
}
#else
VKRT_ABSENT_MATERIAL(Lambert)
#endif

// -------------------------------------------------------------------- phong

#ifdef VKRT_MATERIAL_PHONG
vec3 evalPhong(Material m, vec3 n, vec3 wo, vec3 wi)
{
    return m.diffuse * INV_PI + m.specular * phongLobe(n, wo, wi, m.exponent);
}

float pdfPhong(Material m, vec3 n, vec3 wo, vec3 wi, float cosI)
{
    float pd = phongDiffuseProbability(m);
    return pd * cosI * INV_PI + (1.0 - pd) * phongLobePdf(dot(reflect(-wo, n), wi), m.exponent);
}

// One-sample mixture of the diffuse and lobe densities; weight = f cos / pdf.
BsdfSample samplePhong(Material m, vec3 n, vec3 wo, float eta, vec3 u)
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
#else
VKRT_ABSENT_MATERIAL(Phong)
#endif

// ------------------------------------------------------------------- mirror

#ifdef VKRT_MATERIAL_MIRROR
vec3 evalMirror(Material m, vec3 n, vec3 wo, vec3 wi) { return vec3(0.0); }  // a delta: never evaluated
float pdfMirror(Material m, vec3 n, vec3 wo, vec3 wi, float cosI) { return 0.0; }
BsdfSample sampleMirror(Material m, vec3 n, vec3 wo, float eta, vec3 u)
{
    return BsdfSample(reflect(-wo, n), m.specular * conductorLikeReflectance(m.fresnel, dot(n, wo), m.ior), true,
                      false);
}
#else
VKRT_ABSENT_MATERIAL(Mirror)
#endif

// ------------------------------------------------------------------- glossy

#ifdef VKRT_MATERIAL_GLOSSY
vec3 evalGlossy(Material m, vec3 n, vec3 wo, vec3 wi)
{
    return m.specular * conductorLikeReflectance(m.fresnel, dot(n, wo), m.ior) * phongLobe(n, wo, wi, m.exponent);
}

float pdfGlossy(Material m, vec3 n, vec3 wo, vec3 wi, float cosI)
{
    return phongLobePdf(dot(reflect(-wo, n), wi), m.exponent);
}

// Samples the lobe exactly: f cos / pdf = F ks (e + 2) / (e + 1) cos(theta_i).
BsdfSample sampleGlossy(Material m, vec3 n, vec3 wo, float eta, vec3 u)
{
    vec3 wi = samplePhongLobe(reflect(-wo, n), m.exponent, u.xy);
    float cosI = dot(n, wi);
    if (cosI <= 0.0)
        return noScatter(); // the lobe dips below the surface: absorbed
    float fresnel = conductorLikeReflectance(m.fresnel, dot(n, wo), m.ior);
    return BsdfSample(wi, m.specular * fresnel * ((m.exponent + 2.0) / (m.exponent + 1.0)) * cosI, false, false);
}
#else
VKRT_ABSENT_MATERIAL(Glossy)
#endif

// --------------------------------------------------------------- dielectric

#ifdef VKRT_MATERIAL_DIELECTRIC
vec3 evalDielectric(Material m, vec3 n, vec3 wo, vec3 wi) { return vec3(0.0); } // a delta: never evaluated
float pdfDielectric(Material m, vec3 n, vec3 wo, vec3 wi, float cosI) { return 0.0; }

// Reflects with probability F, else refracts (Snell's law); each branch
// carries weight 1 because its probability equals its Fresnel factor.
// eta = n_incident / n_transmitted for this crossing (lib/media.glsl).
BsdfSample sampleDielectric(Material m, vec3 n, vec3 wo, float eta, vec3 u)
{
    float reflectance = dielectricReflectance(m.fresnel, dot(n, wo), eta);
    vec3 refracted = refractDirection(wo, n, eta);
    if (u.z < reflectance || refracted == vec3(0.0))
        return BsdfSample(reflect(-wo, n), vec3(1.0), true, false);
    return BsdfSample(refracted, vec3(1.0), true, true);
}
#else
VKRT_ABSENT_MATERIAL(Dielectric)
#endif

// ------------------------------------------------------------- dispatchers

#define VKRT_EVAL_OF_KIND(KIND, Type, name, value, delta) \
    if (m.type == MATERIAL_##KIND)                         \
        return eval##Type(m, n, wo, wi);
#define VKRT_PDF_OF_KIND(KIND, Type, name, value, delta) \
    if (m.type == MATERIAL_##KIND)                        \
        return pdf##Type(m, n, wo, wi, cosI);
#define VKRT_SAMPLE_OF_KIND(KIND, Type, name, value, delta) \
    if (m.type == MATERIAL_##KIND)                           \
        return sample##Type(m, n, wo, eta, u);

// f(wo, wi) of the non-delta materials.
vec3 evalBsdf(Material m, vec3 n, vec3 wo, vec3 wi)
{
    if (dot(n, wi) <= 0.0 || dot(n, wo) <= 0.0)
        return vec3(0.0);
    VKRT_MATERIAL_KINDS(VKRT_EVAL_OF_KIND)
    return vec3(0.0);
}

// Solid-angle density with which sampleBsdf picks wi (non-delta materials);
// multiple importance sampling weighs light samples against it.
float pdfBsdf(Material m, vec3 n, vec3 wo, vec3 wi)
{
    float cosI = dot(n, wi);
    if (cosI <= 0.0 || dot(n, wo) <= 0.0)
        return 0.0;
    VKRT_MATERIAL_KINDS(VKRT_PDF_OF_KIND)
    return 0.0;
}

// eta: n_incident / n_transmitted, used by dielectrics only.
BsdfSample sampleBsdf(Material m, vec3 n, vec3 wo, float eta, vec3 u)
{
    VKRT_MATERIAL_KINDS(VKRT_SAMPLE_OF_KIND)
    return noScatter();
}

#endif

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

#ifdef VKRT_PBR_IRIDESCENCE
#include "lib/iridescence.glsl"
#endif

struct BsdfSample {
    vec3 dir;
    vec3 weight;      // f * cos / pdf (or the specular reflectance / transmittance)
    bool specular;    // a delta direction: lights cannot be sampled for it
    bool transmitted; // crossed the surface
    bool evaluate;    // weight left to the caller: f * cos / pdf at dir (completedSample)
};

// The side of the surface a continuation ray leaves from (its offset
// direction): the one the sampled direction points into. With shading
// normals (ns != n) a reflection about ns can point below the geometric
// surface, or a refraction above it; the ray then leaves through that side,
// as Mitsuba's spawn_ray does, instead of re-hitting the surface at once.
vec3 continuationSide(vec3 n, vec3 ns, BsdfSample s)
{
    vec3 side = s.transmitted ? -n : n;
#ifdef VKRT_HAS_SHADING_NORMALS // only vertex normals and normal maps make ns differ from n
    if (ns != n && dot(s.dir, side) < 0.0)
        side = -side;
#endif
    return side;
}

#define VKRT_IS_DELTA_KIND(KIND, Type, name, value, delta) || (delta != 0 && type == MATERIAL_##KIND)
bool isDeltaMaterial(uint type) { return false VKRT_MATERIAL_KINDS(VKRT_IS_DELTA_KIND); }

vec3 evalBsdf(Material m, vec3 n, vec3 wo, vec3 wi);

// No light sampling for it: a delta kind, or a conductor of roughness 0 (a
// mirror with the conductor's Fresnel term).
bool scattersIntoDeltasOnly(Material m)
{
#ifdef VKRT_MATERIAL_CONDUCTOR
    if (m.type == MATERIAL_CONDUCTOR && m.alphaX == 0.0)
        return true;
#endif
    return isDeltaMaterial(m.type);
}

BsdfSample noScatter() { return BsdfSample(vec3(0.0, 0.0, 1.0), vec3(0.0), false, false, false); }

// A sampled direction whose weight f cos / pdf the caller computes, from the
// one evaluation of the BSDF it shares with the light samples
// (completedSample; lib/path.glsl: scatterAtVertex). lavapipe inlines every
// call, so each call of evalBsdf or pdfBsdf is a whole copy of every
// material's code: a sampler that evaluated its own sample doubled it
// (docs/performance.md, "One evaluation site").
BsdfSample sampleToEvaluate(vec3 wi) { return BsdfSample(wi, vec3(0.0), false, false, true); }

// The materials whose surfaces bound a medium (lib/media.glsl): a sample
// they transmit enters or leaves it. A thin-walled pbr surface transmits
// into no medium.
bool boundsMedium(Material m)
{
#ifdef VKRT_PBR_TRANSMISSION
    if (m.type == MATERIAL_PBR)
        return (m.pbrFlags & PBR_FLAG_VOLUME) != 0u;
#endif
    return true;
}

// The rough interfaces' eval and pdf need the crossing's eta = n_i / n_t,
// which only the integrator knows: it stores it in m.exponent.
#if defined(VKRT_MATERIAL_ROUGH_DIELECTRIC) || defined(VKRT_PBR_TRANSMISSION)
Material withInterfaceEta(Material m, float eta)
{
    if (m.type == MATERIAL_ROUGH_DIELECTRIC || m.type == MATERIAL_PBR)
        m.exponent = eta;
    return m;
}
#endif

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
    return BsdfSample(sampleCosineHemisphere(n, u.xy), m.diffuse, false, false, false);
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

// One-sample mixture of the diffuse and lobe densities; weight = f cos / pdf
// (the caller's: sampleToEvaluate).
BsdfSample samplePhong(Material m, vec3 n, vec3 wo, float eta, vec3 u)
{
    float pd = phongDiffuseProbability(m);
    vec3 r = reflect(-wo, n);
    vec3 wi = u.z < pd ? sampleCosineHemisphere(n, u.xy) : samplePhongLobe(r, m.exponent, u.xy);
    return sampleToEvaluate(wi);
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
                      false, false);
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
    return BsdfSample(wi, m.specular * fresnel * ((m.exponent + 2.0) / (m.exponent + 1.0)) * cosI, false, false, false);
}
#else
VKRT_ABSENT_MATERIAL(Glossy)
#endif

// --------------------------------------------------------------- dielectric

#ifdef VKRT_MATERIAL_DIELECTRIC
vec3 evalDielectric(Material m, vec3 n, vec3 wo, vec3 wi) { return vec3(0.0); } // a delta: never evaluated
float pdfDielectric(Material m, vec3 n, vec3 wo, vec3 wi, float cosI) { return 0.0; }

// Reflects with probability F, else refracts (Snell's law); each branch
// carries weight 1 because its probability equals its Fresnel factor. The
// path integrator scales radiance by eta^2 across the crossing itself
// (refractThrough and radianceScale, lib/media.glsl), so that a path in and
// out of glass carries exactly 1.
// eta = n_incident / n_transmitted for this crossing (lib/media.glsl).
BsdfSample sampleDielectric(Material m, vec3 n, vec3 wo, float eta, vec3 u)
{
    float reflectance = dielectricReflectance(m.fresnel, dot(n, wo), eta);
    vec3 refracted = refractDirection(wo, n, eta);
    if (u.z < reflectance || refracted == vec3(0.0))
        return BsdfSample(reflect(-wo, n), vec3(1.0), true, false, false);
    return BsdfSample(refracted, vec3(1.0), true, true, false);
}
#else
VKRT_ABSENT_MATERIAL(Dielectric)
#endif

// ------------------------------------------------------ microfacet helpers

#if defined(VKRT_MATERIAL_CONDUCTOR) || defined(VKRT_MATERIAL_ROUGH_DIELECTRIC) || defined(VKRT_MATERIAL_PLASTIC) || \
    defined(VKRT_MATERIAL_PBR)
vec2 ggxAlpha(Material m) { return vec2(m.alphaX, m.alphaY); }

// D G / (4 cosO cosI) of the GGX lobe at the half vector h (local frame).
float ggxSpecular(vec3 lo, vec3 li, vec3 h, vec2 alpha)
{
    return ggxD(h, alpha) * ggxG1(lo, h, alpha) * ggxG1(li, h, alpha) / (4.0 * lo.z * li.z);
}

#ifdef VKRT_MATERIAL_PBR
// D G / (4 cosO cosI) with the height-correlated G = 1 / (1 + Lambda(wo) +
// Lambda(wi)) that glTF 2.0 specifies (Appendix B, V_GGX); the other rough
// materials keep the separable G of Mitsuba 3, their reference. At roughness
// 1 the two differ by up to 30 % where both directions are far from the
// normal (separable is darker: fully rough glTF metals at grazing angles).
float ggxSpecularCorrelated(vec3 lo, vec3 li, vec3 h, vec2 alpha)
{
    if (dot(lo, h) * lo.z <= 0.0 || dot(li, h) * li.z <= 0.0)
        return 0.0;
    float g = 1.0 / (1.0 + ggxLambdaOf(lo, alpha) + ggxLambdaOf(li, alpha));
    return ggxD(h, alpha) * g / (4.0 * lo.z * li.z);
}
#endif

float pow5(float x)
{
    float x2 = x * x;
    return x2 * x2 * x;
}
#endif

// ---------------------------------------------------------------- conductor
// GGX microfacets with the exact conductor Fresnel term (Mitsuba's
// roughconductor, ggx, visible-normal sampling): f = tint F(wo.h) D G / (4 cosO cosI).

#ifdef VKRT_MATERIAL_CONDUCTOR
// alphaX = 0: a smooth conductor, a delta (sampled only).
vec3 evalConductor(Material m, vec3 n, vec3 wo, vec3 wi)
{
    if (m.alphaX == 0.0)
        return vec3(0.0);
    LocalFrame f = frameAround(n);
    vec3 lo = toFrame(f, wo), li = toFrame(f, wi);
    vec3 h = normalize(lo + li);
    return m.specular * fresnelConductor(dot(lo, h), m.eta, m.k) * ggxSpecular(lo, li, h, ggxAlpha(m));
}

float pdfConductor(Material m, vec3 n, vec3 wo, vec3 wi, float cosI)
{
    if (m.alphaX == 0.0)
        return 0.0;
    LocalFrame f = frameAround(n);
    vec3 lo = toFrame(f, wo);
    return ggxReflectionPdf(lo, normalize(lo + toFrame(f, wi)), ggxAlpha(m));
}

// Visible normals, reflected: weight = tint F G1(wi, h).
BsdfSample sampleConductor(Material m, vec3 n, vec3 wo, float eta, vec3 u)
{
    LocalFrame f = frameAround(n);
    vec3 lo = toFrame(f, wo);
    if (lo.z <= 0.0)
        return noScatter();
    if (m.alphaX == 0.0)
        return BsdfSample(reflect(-wo, n), m.specular * fresnelConductor(lo.z, m.eta, m.k), true, false, false);
    vec2 alpha = ggxAlpha(m);
    vec3 h = sampleGgxVisibleNormal(lo, alpha, u.xy);
    vec3 li = reflect(-lo, h);
    if (li.z <= 0.0)
        return noScatter();
    vec3 weight = m.specular * fresnelConductor(dot(lo, h), m.eta, m.k) * ggxG1(li, h, alpha);
    return BsdfSample(fromFrame(f, li), weight, false, false, false);
}
#else
VKRT_ABSENT_MATERIAL(Conductor)
#endif

// --------------------------------------------------------- rough dielectric
// Walter et al. 2007 with visible-normal sampling (Mitsuba's roughdielectric,
// ggx): reflect with probability F(wo.m), else refract about m. Like the
// smooth dielectric, refraction's radiance scaling by eta^2 is the
// integrator's (lib/media.glsl), so roughness -> 0 tends to its image. Light
// sampling covers the reflection side only: a refracted sample is marked
// `specular`, so that a light it reaches counts in full (no light sample
// competes for that direction).
// eval and pdf need the interface's eta = n_i / n_t, which only the
// integrator knows: it stores it in m.exponent (withInterfaceEta).

#ifdef VKRT_MATERIAL_ROUGH_DIELECTRIC
vec3 evalRoughDielectric(Material m, vec3 n, vec3 wo, vec3 wi)
{
    LocalFrame f = frameAround(n);
    vec3 lo = toFrame(f, wo), li = toFrame(f, wi);
    vec3 h = normalize(lo + li);
    float fresnel = dielectricReflectance(m.fresnel, dot(lo, h), m.exponent);
    return vec3(fresnel * ggxSpecular(lo, li, h, ggxAlpha(m)));
}

float pdfRoughDielectric(Material m, vec3 n, vec3 wo, vec3 wi, float cosI)
{
    LocalFrame f = frameAround(n);
    vec3 lo = toFrame(f, wo);
    vec3 h = normalize(lo + toFrame(f, wi));
    return dielectricReflectance(m.fresnel, dot(lo, h), m.exponent) * ggxReflectionPdf(lo, h, ggxAlpha(m));
}

// Either branch's weight is G1(wi, m): its probability is its Fresnel factor.
BsdfSample sampleRoughDielectric(Material m, vec3 n, vec3 wo, float eta, vec3 u)
{
    LocalFrame f = frameAround(n);
    vec3 lo = toFrame(f, wo);
    if (lo.z <= 0.0)
        return noScatter();
    vec2 alpha = ggxAlpha(m);
    vec3 h = sampleGgxVisibleNormal(lo, alpha, u.xy);
    float fresnel = dielectricReflectance(m.fresnel, dot(lo, h), eta);
    vec3 refracted = refractDirection(lo, h, eta);
    if (u.z < fresnel || refracted == vec3(0.0)) {
        vec3 li = reflect(-lo, h);
        if (li.z <= 0.0)
            return noScatter();
        return BsdfSample(fromFrame(f, li), vec3(ggxG1(li, h, alpha)), false, false, false);
    }
    if (refracted.z >= 0.0)
        return noScatter();
    return BsdfSample(fromFrame(f, refracted), vec3(ggxG1(refracted, h, alpha)), true, true, false);
}
#else
VKRT_ABSENT_MATERIAL(RoughDielectric)
#endif

// ------------------------------------------------------------------ plastic
// A Lambert base under a dielectric coating of index ior (Mitsuba's plastic
// and roughplastic, nonlinear = false):
//   f = F(wo.h) D G / (4 cosO cosI)                      (rough coating only)
//     + diffuse / (1 - Fdr) / ior^2 * T(cosO) T(cosI) / pi,
// T = 1 - F for a smooth coating, else 1 - the rough coating's albedo,
// tabulated by the host (src/material/MicrofacetAlbedo.h); Fdr is the
// coating's internal diffuse reflectance. A smooth coating's reflection is a
// delta: sampled (marked specular), never evaluated.

#ifdef VKRT_MATERIAL_PLASTIC
float coatingTransmittance(Material m, float mu)
{
#ifdef VKRT_HAS_MATERIAL_TABLES
    if (m.table != NO_MATERIAL_TABLE) {
        float x = clamp(mu, 0.0, 1.0) * float(MATERIAL_TABLE_SIZE - 1u);
        uint i = min(uint(x), MATERIAL_TABLE_SIZE - 2u);
        float w1 = x - float(i);
        return (1.0 - w1) * materialTables[m.table + i] + w1 * materialTables[m.table + i + 1u];
    }
#endif
    return 1.0 - fresnelExact(mu, 1.0 / m.ior);
}

bool roughCoating(Material m) { return m.table != NO_MATERIAL_TABLE; }

// Probability of sampling the coating rather than the base (Mitsuba's rule).
float coatingProbability(Material m, float cosO)
{
    float t = coatingTransmittance(m, cosO);
    float specular = (1.0 - t) * m.lobeWeight;
    float diffuse = t * (1.0 - m.lobeWeight);
    return specular + diffuse > 0.0 ? specular / (specular + diffuse) : 0.0;
}

vec3 plasticBase(Material m, float cosO, float cosI)
{
    float transmitted = coatingTransmittance(m, cosO) * coatingTransmittance(m, cosI);
    return m.diffuse * (INV_PI * transmitted / ((1.0 - m.internalReflectance) * m.ior * m.ior));
}

vec3 evalPlastic(Material m, vec3 n, vec3 wo, vec3 wi)
{
    LocalFrame f = frameAround(n);
    vec3 lo = toFrame(f, wo), li = toFrame(f, wi);
    vec3 value = plasticBase(m, lo.z, li.z);
    if (roughCoating(m)) {
        vec3 h = normalize(lo + li);
        value += vec3(fresnelExact(dot(lo, h), 1.0 / m.ior) * ggxSpecular(lo, li, h, ggxAlpha(m)));
    }
    return value;
}

float pdfPlastic(Material m, vec3 n, vec3 wo, vec3 wi, float cosI)
{
    LocalFrame f = frameAround(n);
    vec3 lo = toFrame(f, wo), li = toFrame(f, wi);
    float ps = coatingProbability(m, lo.z);
    float pdf = (1.0 - ps) * li.z * INV_PI;
    if (roughCoating(m))
        pdf += ps * ggxReflectionPdf(lo, normalize(lo + li), ggxAlpha(m));
    return pdf;
}

BsdfSample samplePlastic(Material m, vec3 n, vec3 wo, float eta, vec3 u)
{
    LocalFrame f = frameAround(n);
    vec3 lo = toFrame(f, wo);
    if (lo.z <= 0.0)
        return noScatter();
    float ps = coatingProbability(m, lo.z);
    vec3 li;
    if (u.z < ps) {
        if (!roughCoating(m)) // the smooth coating's mirror reflection, weight F / ps
            return BsdfSample(reflect(-wo, n), vec3(fresnelExact(lo.z, 1.0 / m.ior) / ps), true, false, false);
        li = reflect(-lo, sampleGgxVisibleNormal(lo, ggxAlpha(m), u.xy));
    } else {
        li = toFrame(f, sampleCosineHemisphere(n, u.xy));
    }
    if (li.z <= 0.0)
        return noScatter();
    return sampleToEvaluate(fromFrame(f, li));
}
#else
VKRT_ABSENT_MATERIAL(Plastic)
#endif

// ---------------------------------------------------------------------- pbr
// glTF 2.0 metallic-roughness (the specification's Appendix B):
//   f = (1 - metallic) [(1 - Fs) base / pi + Fs S] + metallic Fm S,
// S = D G / (4 cosO cosI) with the height-correlated G, Fs = 0.04 + 0.96 (1 - wo.h)^5 and
// Fm = base + (1 - base)(1 - wo.h)^5 (Schlick). Sampled as a mixture of the
// visible-normal lobe and the cosine lobe.

#ifdef VKRT_MATERIAL_PBR
// The diffuse lobe's weight 1 - F(V.H) follows the half vector of each
// cosine-sampled direction, and over that lobe it is far above 1 - F(N.V) at
// grazing views (0.93 against 0.53 at N.V = 0.15 for F0 = 0.04). This is the
// cosine c whose Schlick weight (1 - c)^5 is that lobe's mean of (1 - V.H)^5:
// a quadratic fit, within 0.013, of its NumPy quadrature over N.V in [0, 1].
// Lobe probabilities weigh the diffuse with F at this cosine (or at N.V
// where that is smaller), so a smooth dielectric seen at grazing is not
// sampled as if it were mostly mirror: the variance of a smooth pink
// dielectric's BSDF-sample weights is 4x lower at N.V = 0.3, 20x at 0.15 and
// 110x at 0.05 (a NumPy model of this sampler; the probe test
// MicrofacetProbe.ASmoothDielectricSeenAtGrazingHasSteadyWeights measures it).
float diffuseMeanHalfCosine(float cosO)
{
    float c = clamp(cosO, 0.0, 1.0);
    return 0.5147 + c * (0.2320 + 0.0879 * c);
}

#ifdef VKRT_PBR_LAYERS
// The glTF extension layers (src/scene/Scene.h: PbrLayers), as the Khronos
// specifications define them, from the inside out:
//   dielectric (KHR_materials_specular, KHR_materials_ior): per channel
//     Fd = f0 + (f90 - f0)(1 - wo.h)^5, f0 = min(((ior - 1) / (ior + 1))^2
//     specularColor, 1) specular, f90 = specular; Fd S + (1 - max(Fd)) base / pi;
//   metal: Fm S, Fm = base + (1 - base)(1 - wo.h)^5; the two mixed by metallic;
//   sheen (KHR_materials_sheen): sheenColor Charlie(wo, wi) + base layers x
//     min(1 - max(sheenColor) E(cosO), 1 - max(sheenColor) E(cosI)), E the
//     Charlie lobe's directional albedo (the sheen table);
//   clearcoat (KHR_materials_clearcoat): (1 - c Fc) below + c Fc Scoat, with
//     Fc = 0.04 + 0.96 (1 - cosO)^5 at the normal, not at h, as the
//     specification says (so the coat is not reciprocal; it never adds energy);
//     the coat has its own shading normal (clearcoatNormalTexture): its Fc and
//     lobe are taken about it;
//   anisotropy (KHR_materials_anisotropy): the base's GGX lobes (metal,
//     dielectric, transmission) stretch their alpha to mix(alpha, 1,
//     strength^2) along a direction in the tangent plane.
// S is the GGX lobe with the height-correlated G. Sampled as a mixture: the
// coat's and the base's visible-normal lobes and the cosine lobe (diffuse and
// sheen), each chosen in proportion to its reflectance seen from wo.

float max3(vec3 v) { return max(v.x, max(v.y, v.z)); }

#ifdef VKRT_PBR_TRANSMISSION
bool pbrVolumetric(Material m) { return (m.pbrFlags & PBR_FLAG_VOLUME) != 0u; }
// n_i / n_t across the surface: the integrator's at a volume's boundary
// (withInterfaceEta), from air into the material's index otherwise.
float pbrEta(Material m) { return pbrVolumetric(m) ? m.exponent : 1.0 / m.ior; }
float pbrTransmission(Material m) { return m.transmission; }
#else
float pbrEta(Material m) { return 1.0 / m.ior; }
float pbrTransmission(Material m) { return 0.0; }
#endif

// KHR_materials_iridescence: a thin film over the layer whose Fresnel is
// `fresnel` (normal-incidence reflectance f0) mixes in the film's
// reflectance (lib/iridescence.glsl) by the iridescence factor, at cosine c.
vec3 withIridescence(Material m, vec3 fresnel, float c, vec3 f0)
{
#ifdef VKRT_PBR_IRIDESCENCE
    if (m.iridescence > 0.0)
        // The film's reflectance is clamped to 1: its spectral fit can overshoot,
        // and the dielectric's diffuse takes 1 - F.
        return mix(fresnel, min(iridescenceFresnel(1.0, m.iridescenceIor, c, m.iridescenceThickness, f0), vec3(1.0)),
                   m.iridescence);
#endif
    return fresnel;
}

// The dielectric's Fresnel (KHR_materials_specular with KHR_materials_ior) at
// cosine c between wo and the microfacet normal, crossing from index n_i to
// n_t (eta = n_i / n_t; from air, 1 / ior). The specification writes it from
// outside, with F0 of ((ior - 1) / (ior + 1))^2; a ray inside a volume meets
// the same interface, so Schlick's form takes the cosine on the side of the
// lower index (the same pair of angles seen from either side), and past the
// critical angle all is reflected.
vec3 pbrDielectricFresnel(Material m, float c)
{
    float eta = pbrEta(m);
    c = clamp(c, 0.0, 1.0);
    if (eta > 1.0) {
        float sin2t = eta * eta * (1.0 - c * c);
        if (sin2t >= 1.0)
            return vec3(1.0);
        c = sqrt(1.0 - sin2t);
    }
    float r = (1.0 - eta) / (1.0 + eta);
    vec3 f0 = min(r * r * m.specular, vec3(1.0)) * m.specularFactor;
    vec3 fresnel = f0 + (vec3(m.specularFactor) - f0) * pow5(1.0 - c);
    return withIridescence(m, fresnel, c, f0);
}

// The metal's Fresnel at cosine c: Schlick's with the base colour as F0.
vec3 pbrMetalFresnel(Material m, float c)
{
    c = clamp(c, 0.0, 1.0);
    return withIridescence(m, m.diffuse + (vec3(1.0) - m.diffuse) * pow5(1.0 - c), c, m.diffuse);
}

#ifdef VKRT_PBR_SHEEN
// The Charlie sheen (Estevez and Kulla 2017, the form KHR_materials_sheen
// gives): D and the visibility's Lambda fit.
float sheenAlpha(Material m) { return max(m.sheenRoughness * m.sheenRoughness, MIN_SHEEN_ALPHA); }

float charlieD(float cosH, float alpha)
{
    float sin2h = max(1.0 - cosH * cosH, 0.0);
    return (2.0 + 1.0 / alpha) * pow(sin2h, 0.5 / alpha) * (0.5 * INV_PI);
}

float charlieL(float x, float alpha)
{
    float t = (1.0 - alpha) * (1.0 - alpha);
    float a = mix(21.5473, 25.3245, t), b = mix(3.82987, 3.32435, t), c = mix(0.19823, 0.16801, t);
    float d = mix(-1.97760, -1.27393, t), e = mix(-4.32054, -4.85967, t);
    return a / (1.0 + b * pow(x, c)) + d * x + e;
}

float charlieLambda(float cosTheta, float alpha)
{
    float c = abs(cosTheta);
    return c < 0.5 ? exp(charlieL(c, alpha)) : exp(2.0 * charlieL(0.5, alpha) - charlieL(1.0 - c, alpha));
}

// The sheen lobe, sheenColor excluded.
float sheenBrdf(vec3 lo, vec3 li, vec3 h, float alpha)
{
    return charlieD(h.z, alpha) / ((1.0 + charlieLambda(lo.z, alpha) + charlieLambda(li.z, alpha)) * 4.0 * lo.z * li.z);
}

// E(mu) of the sheen table (bilinear in roughness and sqrt(cosine)).
float sheenAlbedo(Material m, float mu)
{
#ifdef VKRT_HAS_MATERIAL_TABLES
    const float last = float(SHEEN_TABLE_SIDE - 1u);
    float x = sqrt(clamp(mu, 0.0, 1.0)) * last, y = clamp(m.sheenRoughness, 0.0, 1.0) * last;
    uint i = min(uint(x), SHEEN_TABLE_SIDE - 2u), j = min(uint(y), SHEEN_TABLE_SIDE - 2u);
    float wx = x - float(i), wy = y - float(j);
    uint at = m.table + j * SHEEN_TABLE_SIDE + i;
    float low = mix(materialTables[at], materialTables[at + 1u], wx);
    float high = mix(materialTables[at + SHEEN_TABLE_SIDE], materialTables[at + SHEEN_TABLE_SIDE + 1u], wx);
    return mix(low, high, wy);
#else
    return 0.0;
#endif
}
#endif

#ifdef VKRT_PBR_CLEARCOAT
// The coat's Fresnel weight seen from cosine cosO: clearcoat x Fc, with the
// specification's |N.V| (wo can be below a coat's own normal: its lobe is then
// 0, and the layers below keep 1 - clearcoat Fc).
float pbrCoatWeight(Material m, float cosO)
{
    return m.clearcoat * (0.04 + 0.96 * pow5(1.0 - min(abs(cosO), 1.0)));
}
#endif

// The Fresnel weight the dielectric's diffuse loses: max3(Fd(wo.h)) as the
// specification's fresnel_mix has it. Seen from inside a volume (which the
// specification does not describe) it is also at least Fd at wo's own
// cosine: past the critical angle total internal reflection gives the
// specular lobe all the light near the mirror direction, and a diffuse that
// kept 1 - Fd(wo.h) elsewhere gained energy (1.6 % at cosO 0.3, roughness
// 0.5, transmission 0.5: tests/gpu/pbr_transmission_probe_test.cpp); with
// Fd(cosO) = 1 there it keeps nothing.
float pbrDiffuseFresnel(Material m, vec3 fd, float cosO)
{
#ifdef VKRT_PBR_TRANSMISSION
    if (pbrEta(m) > 1.0)
        return max(max3(fd), max3(pbrDielectricFresnel(m, cosO)));
#endif
    return max3(fd);
}

#ifdef VKRT_PBR_SHEEN
// What the sheen leaves of the layers below it between cosines cosO and cosI
// (both of the sheen's side). The extension's visibility fit puts E above 1
// for smooth sheen near grazing (roughness <= 0.25, cosines below ~0.05): the
// base then keeps nothing there, never a negative share.
float sheenScaling(Material m, float cosO, float cosI)
{
    if (!(max3(m.sheenColor) > 0.0))
        return 1.0;
    float strength = max3(m.sheenColor);
    return max(min(1.0 - strength * sheenAlbedo(m, cosO), 1.0 - strength * sheenAlbedo(m, cosI)), 0.0);
}
#else
float sheenScaling(Material m, float cosO, float cosI) { return 1.0; }
#endif

// The base's frame about n: its x axis the direction the anisotropy stretches
// (KHR_materials_anisotropy, resolved at the hit by withAnisotropy), any
// frame where the lobe is isotropic.
LocalFrame pbrFrame(Material m, vec3 n)
{
#ifdef VKRT_PBR_ANISOTROPY
    vec3 t = m.anisotropy - n * dot(n, m.anisotropy);
    float len = length(t);
    if (len > 1e-6) {
        LocalFrame f;
        f.n = n;
        f.t = t / len;
        f.b = cross(n, f.t);
        return f;
    }
#endif
    return frameAround(n);
}

#ifdef VKRT_PBR_CLEARCOAT
// The clear coat's frame: about its own shading normal (clearcoatNormalTexture,
// or the normal a base normal map leaves untilted), turned to n's side, or
// about n. Its lobe is isotropic: any frame around it.
LocalFrame pbrCoatFrame(Material m, vec3 n)
{
    vec3 c = m.clearcoatNormal;
    if (c == vec3(0.0))
        return frameAround(n);
    return frameAround(dot(c, n) < 0.0 ? -c : c);
}

// The coat's lobe as a term of f (which the integrator weighs by the base's
// cosine li.z): S(co, ci) ci.z / li.z, the coat's GGX with its own cosine, as
// the Khronos sample viewer lights the coat with its clearcoat N.L. Zero where
// either direction is below the coat's normal.
float pbrCoatLobe(Material m, vec3 co, vec3 ci, float baseCosI)
{
    if (!(co.z > 0.0) || !(ci.z > 0.0))
        return 0.0;
    return ggxSpecularCorrelated(co, ci, normalize(co + ci), vec2(m.clearcoatAlpha)) * (ci.z / baseCosI);
}
#endif

// f(wo, wi) of the reflection lobes. Transmission (KHR_materials_transmission)
// takes its share of the dielectric's diffuse lobe: the specification's
// mix(diffuse, baseColor x the specular BTDF, transmission) below the
// dielectric's Fresnel; its BTDF is only ever sampled (samplePbr).
vec3 evalPbr(Material m, vec3 n, vec3 wo, vec3 wi)
{
    LocalFrame f = pbrFrame(m, n);
    vec3 lo = toFrame(f, wo), li = toFrame(f, wi);
    vec3 h = normalize(lo + li);
    float s = ggxSpecularCorrelated(lo, li, h, ggxAlpha(m));
    vec3 fd = pbrDielectricFresnel(m, dot(lo, h));
    vec3 dielectric = fd * s + (1.0 - pbrDiffuseFresnel(m, fd, lo.z)) * (1.0 - pbrTransmission(m)) * m.diffuse * INV_PI;
    vec3 value = mix(dielectric, pbrMetalFresnel(m, dot(lo, h)) * s, m.metallic);
#ifdef VKRT_PBR_SHEEN
    if (max3(m.sheenColor) > 0.0)
        value = m.sheenColor * sheenBrdf(lo, li, h, sheenAlpha(m)) + value * sheenScaling(m, lo.z, li.z);
#endif
#ifdef VKRT_PBR_CLEARCOAT
    if (m.clearcoat > 0.0) {
        LocalFrame fc = pbrCoatFrame(m, n);
        vec3 co = toFrame(fc, wo);
        float coat = pbrCoatWeight(m, co.z);
        value = (1.0 - coat) * value + coat * pbrCoatLobe(m, co, toFrame(fc, wi), li.z);
    }
#endif
    return value;
}

// wo's cosine about the coat's normal; 0 without a coat.
float pbrCoatCosine(Material m, vec3 n, vec3 wo)
{
#ifdef VKRT_PBR_CLEARCOAT
    return m.clearcoat > 0.0 ? toFrame(pbrCoatFrame(m, n), wo).z : 0.0;
#else
    return 0.0;
#endif
}

// The lobe probabilities seen from cosO (the coat's lobe from coatCosO, wo's
// cosine about the coat's normal), summing to 1: x the coat, y the base's GGX
// reflection, z the cosine lobe (diffuse and sheen), w transmission.
vec4 pbrLobeProbabilities(Material m, float cosO, float coatCosO)
{
#ifdef VKRT_PBR_CLEARCOAT
    float coat = m.clearcoat > 0.0 && coatCosO > 0.0 ? pbrCoatWeight(m, coatCosO) : 0.0;
#else
    const float coat = 0.0;
#endif
    float fd = max3(pbrDielectricFresnel(m, cosO));
    float specular = m.metallic + (1.0 - m.metallic) * fd;
    float below = (1.0 - m.metallic) * luminance(m.diffuse);
    // Never above fd: inside a volume the mean cosine can lie past the
    // critical angle (F = 1) where the diffuse still keeps 1 - Fd(cosO).
    float fdDiffuse = min(max3(pbrDielectricFresnel(m, diffuseMeanHalfCosine(cosO))), fd);
    // Past the critical angle inside a volume Fd(cosO) is 1, yet microfacets
    // tilted towards wo still transmit: transmission keeps some probability.
    float transmitted = below * pbrTransmission(m) * max(1.0 - fd, 0.1);
#ifdef VKRT_PBR_SHEEN
    float sheen = max3(m.sheenColor) > 0.0 ? max3(m.sheenColor) * sheenAlbedo(m, cosO) : 0.0;
#else
    const float sheen = 0.0;
#endif
    float cosine = below * (1.0 - fdDiffuse) * (1.0 - pbrTransmission(m)) + sheen;
    float base = specular + cosine + transmitted;
    if (!(base > 0.0))
        return vec4(coat, 1.0 - coat, 0.0, 0.0);
    return vec4(coat, (1.0 - coat) / base * vec3(specular, cosine, transmitted));
}

float pdfPbr(Material m, vec3 n, vec3 wo, vec3 wi, float cosI)
{
    LocalFrame f = pbrFrame(m, n);
    vec3 lo = toFrame(f, wo), li = toFrame(f, wi);
    vec4 p = pbrLobeProbabilities(m, lo.z, pbrCoatCosine(m, n, wo));
    vec3 h = normalize(lo + li);
    float pdf = p.y * ggxReflectionPdf(lo, h, ggxAlpha(m)) + p.z * li.z * INV_PI;
#ifdef VKRT_PBR_CLEARCOAT
    if (p.x > 0.0) {
        LocalFrame fc = pbrCoatFrame(m, n);
        vec3 co = toFrame(fc, wo);
        pdf += p.x * ggxReflectionPdf(co, normalize(co + toFrame(fc, wi)), vec2(m.clearcoatAlpha));
    }
#endif
    return pdf;
}

#ifdef VKRT_PBR_TRANSMISSION
// The transmission lobe, sampled with probability `chosen` from the base's
// visible normals: baseColor x (1 - max3(Fd(wo.h))) x the GGX BTDF, under the
// sheen's scaling and the coat's (1 - clearcoat Fc). Its weight f |cosI| / pdf
// is that product times G2(wo, wi) / G1(wo) (height-correlated, as the
// reflection's). Across a volume's boundary wi refracts about h by eta (the
// integrator scales radiance by eta^2 and tracks the medium); a thin-walled
// surface passes the reflected direction mirrored through its plane, the
// specification's unrefracted thin-walled BTDF. Marked specular, as a rough
// dielectric's refraction: no light sample competes for it.
// A volume's boundary tints by sqrt(baseColor) at each crossing, so that light
// through a closed object takes baseColor once: the colour the Khronos sample
// viewer shows (KHR_materials_volume: "as if the object is covered with a
// coloured, transparent foil") and Cycles' Principled BSDF renders; baseColor
// at each crossing made TransmissionRoughnessTest's glass samples (base
// colour (0.5, 0.7, 0.9)) darker than Cycles by that colour again.
BsdfSample samplePbrTransmission(Material m, LocalFrame f, vec3 lo, float coatCosO, float eta, float chosen, vec2 u)
{
    vec2 alpha = ggxAlpha(m);
    vec3 h = sampleGgxVisibleNormal(lo, alpha, u);
    // Refraction's zero vector (total internal reflection) and a reflection
    // below the surface both fail the test.
    vec3 li = pbrVolumetric(m) ? refractDirection(lo, h, eta) : reflect(-lo, h) * vec3(1.0, 1.0, -1.0);
    if (!(li.z < 0.0))
        return noScatter();
    float lambdaO = ggxLambdaOf(lo, alpha);
    float shadowing = (1.0 + lambdaO) / (1.0 + lambdaO + ggxLambdaOf(-li, alpha));
    float layers = (1.0 - m.metallic) * m.transmission * (1.0 - max3(pbrDielectricFresnel(m, dot(lo, h))));
    float coatKeeps = 1.0;
#ifdef VKRT_PBR_CLEARCOAT
    coatKeeps = 1.0 - (m.clearcoat > 0.0 ? pbrCoatWeight(m, coatCosO) : 0.0);
#endif
    layers *= sheenScaling(m, lo.z, -li.z) * coatKeeps;
    vec3 tint = pbrVolumetric(m) ? sqrt(m.diffuse) : m.diffuse;
    return BsdfSample(fromFrame(f, li), tint * (layers * shadowing / chosen), true, true, false);
}
#endif

BsdfSample samplePbr(Material m, vec3 n, vec3 wo, float eta, vec3 u)
{
    LocalFrame f = pbrFrame(m, n);
    vec3 lo = toFrame(f, wo);
    if (lo.z <= 0.0)
        return noScatter();
    float coatCosO = pbrCoatCosine(m, n, wo);
    vec4 p = pbrLobeProbabilities(m, lo.z, coatCosO);
    vec3 li;
#ifdef VKRT_PBR_CLEARCOAT
    if (u.z < p.x) {
        LocalFrame fc = pbrCoatFrame(m, n);
        vec3 co = toFrame(fc, wo);
        li = toFrame(f, fromFrame(fc, reflect(-co, sampleGgxVisibleNormal(co, vec2(m.clearcoatAlpha), u.xy))));
    } else
#endif
    if (u.z < p.x + p.y)
        li = reflect(-lo, sampleGgxVisibleNormal(lo, ggxAlpha(m), u.xy));
#ifdef VKRT_PBR_TRANSMISSION
    else if (u.z >= p.x + p.y + p.z && p.w > 0.0)
        return samplePbrTransmission(m, f, lo, coatCosO, eta, p.w, u.xy);
#endif
    else
        li = toFrame(f, sampleCosineHemisphere(n, u.xy));
    if (li.z <= 0.0)
        return noScatter();
    return sampleToEvaluate(fromFrame(f, li));
}
#else
vec3 evalPbr(Material m, vec3 n, vec3 wo, vec3 wi)
{
    LocalFrame f = frameAround(n);
    vec3 lo = toFrame(f, wo), li = toFrame(f, wi);
    vec3 h = normalize(lo + li);
    float s = ggxSpecularCorrelated(lo, li, h, ggxAlpha(m));
    float schlick = pow5(1.0 - clamp(dot(lo, h), 0.0, 1.0));
    float fs = 0.04 + 0.96 * schlick;
    vec3 fm = m.diffuse + (vec3(1.0) - m.diffuse) * schlick;
    return (1.0 - m.metallic) * ((1.0 - fs) * m.diffuse * INV_PI + vec3(fs * s)) + m.metallic * fm * s;
}

// The share of the specular lobe: Fresnel at the macro-surface angle against
// the diffuse's mean weight over its lobe (diffuseMeanHalfCosine).
float pbrSpecularProbability(Material m, float cosO)
{
    float fs = 0.04 + 0.96 * pow5(1.0 - clamp(cosO, 0.0, 1.0));
    float fsDiffuse = min(0.04 + 0.96 * pow5(1.0 - diffuseMeanHalfCosine(cosO)), fs);
    float specular = m.metallic + (1.0 - m.metallic) * fs;
    float diffuse = (1.0 - m.metallic) * (1.0 - fsDiffuse) * luminance(m.diffuse);
    return diffuse > 0.0 ? specular / (specular + diffuse) : 1.0;
}

float pdfPbr(Material m, vec3 n, vec3 wo, vec3 wi, float cosI)
{
    LocalFrame f = frameAround(n);
    vec3 lo = toFrame(f, wo), li = toFrame(f, wi);
    float ps = pbrSpecularProbability(m, lo.z);
    return ps * ggxReflectionPdf(lo, normalize(lo + li), ggxAlpha(m)) + (1.0 - ps) * li.z * INV_PI;
}

BsdfSample samplePbr(Material m, vec3 n, vec3 wo, float eta, vec3 u)
{
    LocalFrame f = frameAround(n);
    vec3 lo = toFrame(f, wo);
    if (lo.z <= 0.0)
        return noScatter();
    vec3 li = u.z < pbrSpecularProbability(m, lo.z)
                  ? reflect(-lo, sampleGgxVisibleNormal(lo, ggxAlpha(m), u.xy))
                  : toFrame(f, sampleCosineHemisphere(n, u.xy));
    if (li.z <= 0.0)
        return noScatter();
    return sampleToEvaluate(fromFrame(f, li));
}
#endif // VKRT_PBR_LAYERS
#else
VKRT_ABSENT_MATERIAL(Pbr)
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

// eta: n_incident / n_transmitted, used by dielectrics only. A sample marked
// `evaluate` gets its weight from completedSample.
BsdfSample sampleBsdf(Material m, vec3 n, vec3 wo, float eta, vec3 u)
{
    VKRT_MATERIAL_KINDS(VKRT_SAMPLE_OF_KIND)
    return noScatter();
}

// The BSDF at one pair of directions: f (when wantF) and the density of
// sampling wi (when wantPdf), from one call site of each, so that a kernel
// that evaluates through this function alone holds one copy of every
// material's eval and pdf.
struct BsdfValue {
    vec3 f;
    float pdf;
};

BsdfValue evaluateBsdf(Material m, vec3 n, vec3 wo, vec3 wi, bool wantF, bool wantPdf)
{
    BsdfValue v = BsdfValue(vec3(0.0), 0.0);
    if (wantF)
        v.f = evalBsdf(m, n, wo, wi);
    if (wantPdf)
        v.pdf = pdfBsdf(m, n, wo, wi);
    return v;
}

// What evaluateBsdf must give for a BSDF sample: f where the sampler left its
// weight to the caller, the pdf wherever the sample is not a delta (for MIS).
bool sampleWantsF(BsdfSample s) { return s.evaluate; }
bool sampleWantsPdf(BsdfSample s) { return !s.specular && (s.evaluate || s.weight != vec3(0.0)); }

// The sample with its weight f cos / pdf where the sampler left it to the
// caller (v = evaluateBsdf at s.dir with sampleWantsF and sampleWantsPdf).
BsdfSample completedSample(BsdfSample s, vec3 n, BsdfValue v)
{
    if (!s.evaluate)
        return s;
    if (!(v.pdf > 0.0))
        return noScatter(); // a lobe sample rounded onto the lobe's edge
    s.weight = v.f * (dot(n, s.dir) / v.pdf);
    s.evaluate = false;
    return s;
}

// A BSDF sample with its weight, from its own evaluation site (the Whitted
// integrator and the probes, which share none); pdf: its density where
// `wantPdf` or the weight needs it, 0 for a delta.
BsdfSample sampleBsdfWeighted(Material m, vec3 n, vec3 wo, float eta, vec3 u, bool wantPdf, out float pdf)
{
    BsdfSample s = sampleBsdf(m, n, wo, eta, u);
    BsdfValue v = evaluateBsdf(m, n, wo, s.dir, sampleWantsF(s), s.evaluate || (wantPdf && sampleWantsPdf(s)));
    pdf = v.pdf;
    return completedSample(s, n, v);
}

#endif

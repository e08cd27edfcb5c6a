// Thin-film iridescence Fresnel of KHR_materials_iridescence (the extension's
// "Iridescence Fresnel" implementation notes, after Belcour and Barla 2017, "A
// Practical Extension to Microfacet Theory for the Modeling of Varying
// Iridescence"): the RGB reflectance of outside / thin film / base, where the
// interference of the film's inter-reflections is integrated over the visible
// spectrum analytically, in Fourier space, instead of wavelength by wavelength.
//
// Choices where the specification's text leaves room (docs in the tests,
// tests/gpu/iridescence_probe_test.cpp, measure their effect):
//  - the optical path difference uses the angle inside the film, cos(theta2)
//    (the ratified text; an early draft wrote cos(theta1));
//  - the film fades into the outside medium below IRIDESCENCE_FADE_NM, with
//    the glTF sample viewer's smoothstep(0, 0.03, thickness) and the thickness
//    in nanometres, as the Khronos and three.js implementations have it;
//  - R12 R23 is clamped to [0, 0.9999], not [1e-5, 0.9999]: with the lower
//    bound 1e-5 a vanished film still added 2 sqrt(1e-5) (1 - F) ~ 0.6 % of
//    false interference colour; with 0 a film of thickness 0 at normal
//    incidence returns exactly the base's F0 (the upper bound keeps the
//    geometric sum 1 / (1 - R12 R23) finite).
// Both interfaces use Schlick's Fresnel, as the specification does and as the
// rest of the pbr material (lib/bsdf.glsl) does.
#ifndef VKRT_IRIDESCENCE_GLSL
#define VKRT_IRIDESCENCE_GLSL

#include "shared/SceneTypes.h"
#include "lib/ray.glsl"
#include "lib/fresnel.glsl"

// Below this thickness (nm) the film's IOR is blended into the outside IOR,
// so that the film, and its interference, vanishes smoothly at thickness 0.
const float IRIDESCENCE_FADE_NM = 0.03;

// The base's F0 is at most this, so that its recovered IOR stays finite.
const float IRIDESCENCE_MAX_BASE_F0 = 0.9999;

// CIE XYZ to linear Rec.709 (sRGB primaries, D65), columns as GLSL stores them.
const mat3 IRIDESCENCE_XYZ_TO_REC709 = mat3(3.2404542, -0.9692660, 0.0556434,
                                            -1.5371385, 1.8760108, -0.2040259,
                                            -0.4985314, 0.0415560, 1.0572252);

// A dielectric's IOR from its normal-incidence reflectance against air, the
// inverse of F0 = ((n - 1) / (n + 1))^2 (the specification uses it for metals
// too, whose extinction it cannot recover).
vec3 iridescenceBaseIor(vec3 baseF0)
{
    vec3 s = sqrt(clamp(baseF0, 0.0, IRIDESCENCE_MAX_BASE_F0));
    return (1.0 + s) / (1.0 - s);
}

// The interference term of order m as an RGB colour: the spectrum
// cos(2 pi opd / lambda + shift) integrated against the XYZ colour-matching
// functions. Each function is fitted by a Gaussian in the frequency domain
// (x by two), so the integral is a Gaussian times a cosine of the optical path
// difference (nm); its amplitude falls off as the film gets thick, which is
// why thick films look pastel. Normalised so that opd = 0, shift = 0 gives
// XYZ ~ (1, 1, 1).
vec3 iridescenceSensitivity(float opd, vec3 shift)
{
    float phase = 2.0 * PI * opd * 1.0e-9;
    const vec3 amplitude = vec3(5.4856e-13, 4.4201e-13, 5.2481e-13);
    const vec3 frequency = vec3(1.6810e+06, 1.7953e+06, 2.2084e+06);
    const vec3 variance = vec3(4.3278e+09, 9.3046e+09, 6.6121e+09);
    vec3 xyz = amplitude * sqrt(2.0 * PI * variance) * cos(frequency * phase + shift) * exp(-phase * phase * variance);
    // x's second (blue) lobe.
    xyz.x += 9.7470e-14 * sqrt(2.0 * PI * 4.5282e+09) * cos(2.2399e+06 * phase + shift.x)
           * exp(-4.5282e+09 * phase * phase);
    return IRIDESCENCE_XYZ_TO_REC709 * (xyz / 1.0685e-7);
}

// The phase change on reflection at an interface: pi when the light reflects
// off an optically less dense medium, 0 otherwise (polarization ignored).
float reflectionPhase(float incidentIor, float transmittedIor)
{
    return transmittedIor < incidentIor ? PI : 0.0;
}

// Reflectance of outside (IOR outsideIor) / film (filmIor, thicknessNm) / base
// (normal-incidence reflectance baseF0) at cosTheta1 = V.H, in linear Rec.709.
// Total internal reflection at the film's top (a film less dense than the
// outside medium) reflects everything: 1.
vec3 iridescenceFresnel(float outsideIor, float filmIor, float cosTheta1, float thicknessNm, vec3 baseF0)
{
    cosTheta1 = clamp(cosTheta1, 0.0, 1.0);
    float n2 = mix(outsideIor, filmIor, smoothstep(0.0, IRIDESCENCE_FADE_NM, thicknessNm));

    // Snell: the angle inside the film.
    float ratio = outsideIor / n2;
    float cosTheta2Sq = 1.0 - ratio * ratio * (1.0 - cosTheta1 * cosTheta1);
    if (cosTheta2Sq < 0.0)
        return vec3(1.0);
    float cosTheta2 = sqrt(cosTheta2Sq);

    // Outside -> film: reflected R12 (= R21), transmitted both ways T121.
    float r12 = fresnelSchlick(cosTheta1, schlickR0(n2 / outsideIor));
    float t121 = 1.0 - r12;
    float phi21 = PI - reflectionPhase(outsideIor, n2);

    // Film -> base, per channel.
    vec3 baseIor = iridescenceBaseIor(baseF0);
    vec3 r0Base = (baseIor - n2) / (baseIor + n2);
    vec3 r23 = r0Base * r0Base + (1.0 - r0Base * r0Base) * fresnelSchlick(cosTheta2, 0.0);
    vec3 phi23 = vec3(reflectionPhase(n2, baseIor.r), reflectionPhase(n2, baseIor.g), reflectionPhase(n2, baseIor.b));

    // Airy summation: the light bouncing inside the film forms a geometric
    // series; its mean (m = 0) and the first two interference orders.
    float opd = 2.0 * n2 * thicknessNm * cosTheta2;
    vec3 phi = vec3(phi21) + phi23;
    vec3 r123 = clamp(r12 * r23, 0.0, 0.9999);
    vec3 rs = t121 * t121 * r23 / (1.0 - r123);
    vec3 reflectance = r12 + rs;
    vec3 cm = rs - t121;
    vec3 amplitude = sqrt(r123);
    for (int m = 1; m <= 2; ++m) {
        cm *= amplitude;
        reflectance += cm * 2.0 * iridescenceSensitivity(float(m) * opd, float(m) * phi);
    }
    return max(reflectance, vec3(0.0));
}

#endif

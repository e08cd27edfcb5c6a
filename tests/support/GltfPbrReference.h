#pragma once
// An independent double-precision CPU reference of the glTF 2.0 metallic-roughness material (Appendix B) with
// KHR_materials_specular, KHR_materials_ior, KHR_materials_sheen, KHR_materials_clearcoat (with its own normal) and
// KHR_materials_anisotropy, written from the
// Khronos specification texts alone (not from vkrt's shaders or src/material), to check vkrt's GLSL against.
//
// Local frame: the normal (also the clearcoat normal) is +z; wo = V points to the viewer, wi = L to the light,
// both unit. The BRDF is zero unless wo.z > 0 and wi.z > 0. Layering, from the bottom up:
//   material        = mix(dielectric_brdf, metal_brdf, metallic)                     (Appendix B)
//   dielectric_brdf = F_d * specular_brdf + (1 - max3(F_d)) * baseColor / pi         (KHR_materials_specular)
//                     F_d = f0 + (f90 - f0) (1 - |V.H|)^5, f90 = specular,
//                     f0 = min(((ior - 1) / (ior + 1))^2 specularColor, 1) specular   (+ KHR_materials_ior)
//   metal_brdf      = (baseColor + (1 - baseColor) (1 - |V.H|)^5) * specular_brdf
//   specular_brdf   = D_GGX(alpha) * V_GGX (height-correlated Smith), alpha = roughness^2; with anisotropy the
//                     spec's D_GGX_anisotropic * V_GGX_anisotropic, at = mix(alpha, 1, anisotropy^2) along T,
//                     ab = clamp(alpha, 0.001, 1) along B (metal and dielectric lobes; not the coat)
//   sheen_material  = sheenColor * D_charlie * V_charlie
//                     + material * min(1 - max3(sheenColor) E(N.V), 1 - max3(sheenColor) E(N.L))
//   coated          = (1 - clearcoat Fc) sheen_material + clearcoat Fc specular_brdf(clearcoatRoughness^2),
//                     Fc = 0.04 + 0.96 (1 - |N.V|)^5 (the spec's N.V, not V.H: this layer is not reciprocal)
// Taken literally, these formulas gain energy in places (tests/material/gltf_pbr_reference_test.cpp pins them
// down): a white dielectric at grazing view (fresnel_mix weighs the diffuse with 1 - F(V.H) per direction), and
// the sheen where E > 1 (see sheenDirectionalAlbedo). The reference keeps them as written.
//
// Choices the spec leaves open, made here:
//   - alpha = 0 (roughness or clearcoatRoughness 0) is a Dirac lobe with no finite density: its GGX lobe
//     evaluates to 0 here (the value of the delta off its peak); a renderer handles it separately.
//   - The Charlie alpha_g = sheenRoughness^2 is clamped below at kMinSheenAlphaG = 1e-3, since
//     sheenRoughness 0 divides by zero in the distribution (inv_r = 1 / alpha_g).
//   - E(mu) is not read from the Enterprise PBR table: it is the directional albedo of this very sheen BRDF,
//     by quadrature (memoized per roughness and mu), so that the albedo scaling is exactly consistent with it.
#include <glm/vec3.hpp>

namespace vkrt::test {

/// The material's parameters; the defaults are those of glTF with no extension used (specular 1, specularColor
/// 1, ior 1.5, sheen and clearcoat off), with metallic and roughness at glTF's defaults of 1.
struct GltfPbrParams {
    glm::dvec3 baseColor{1.0};
    double metallic = 1.0;
    double roughness = 1.0; // perceptual; alpha = roughness^2
    double ior = 1.5;
    double specular = 1.0;
    glm::dvec3 specularColor{1.0};
    glm::dvec3 sheenColor{0.0};
    double sheenRoughness = 0.0;
    double clearcoat = 0.0;
    double clearcoatRoughness = 0.0;
    /// KHR_materials_clearcoat's own normal (clearcoatNormalTexture), unit, local frame: the coat's Fresnel and
    /// lobe are taken about it. The lobe enters f weighed by its own cosine: f cos(N, L) holds the coat's
    /// clearcoat_brdf cos(Nc, L), as the Khronos sample viewer lights the coat (the spec's formulas leave the
    /// cosine implicit).
    glm::dvec3 clearcoatNormal{0.0, 0.0, 1.0};
    /// KHR_materials_anisotropy: its strength, and the direction it stretches the base's specular lobes along
    /// (the anisotropicT of the spec's TBN), at angle anisotropyAngle from +x in the tangent plane.
    double anisotropy = 0.0;
    double anisotropyAngle = 0.0;
};

/// The lower bound on the Charlie alpha_g = sheenRoughness^2 (1 / alpha_g is an exponent of the distribution).
inline constexpr double kMinSheenAlphaG = 1e-3;

/// f(wo, wi) (the BRDF, without the cosine), local frame.
glm::dvec3 gltfPbrEval(const GltfPbrParams& p, const glm::dvec3& wo, const glm::dvec3& wi);
/// E(mu): directional albedo of the Charlie sheen BRDF (sheenColor 1) at NdotV = mu, by quadrature.
/// Accurate to about 1e-7 absolute; memoized per (alpha_g, mu), each new pair costs about 0.5 ms. E(mu <= 0)
/// is 0. With the spec's visibility fit E exceeds 1 for smooth sheen at grazing mu (sheenRoughness <= 0.25,
/// mu below 0.01 to 0.05; up to 6 at sheenRoughness 0) and for every roughness at mu below about 5e-6: then
/// the albedo scaling 1 - max3(sheenColor) E is negative and so may be gltfPbrEval. Spec behaviour, kept.
double sheenDirectionalAlbedo(double mu, double sheenRoughness);
/// The same quadrature, not memoized, with refinement >= 1 times the nodes per panel and more panels towards
/// its singular points (refinement 1 is sheenDirectionalAlbedo's): for checks that it has converged.
double sheenDirectionalAlbedoUncached(double mu, double sheenRoughness, int refinement);
/// The Charlie distribution and visibility on their own (for tests of the parts).
double charlieD(double cosH, double sheenRoughness);
double charlieVisibility(double cosV, double cosL, double sheenRoughness);

/// The cosine at which the samplers take the Fresnel that weighs a pbr
/// material's diffuse lobe when they choose a lobe, where F there is below
/// F(N.V) (lib/bsdf.glsl's diffuseMeanHalfCosine, docs/scene-format.md): a fit of the cosine whose
/// (1 - c)^5 is the mean of (1 - V.H)^5 over the cosine lobe's directions,
/// checked against quadrature by PbrLobeChoice.* (tests/gpu/microfacet_probe_test.cpp).
inline double diffuseMeanHalfCosineFit(double cosO)
{
    const double c = cosO < 0.0 ? 0.0 : (cosO > 1.0 ? 1.0 : cosO);
    return 0.5147 + c * (0.2320 + 0.0879 * c);
}

} // namespace vkrt::test

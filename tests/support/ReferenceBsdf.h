#pragma once
// Double-precision reference BSDFs in the local shading frame (normal +z), written independently of the
// GLSL in shaders/lib/bsdf.glsl to check it: eval, pdf and sample for the GGX conductor, rough dielectric,
// rough plastic and glTF metallic-roughness. Conventions (the contract with the GLSL):
//   wo points to the viewer, wi to the light, both unit; wo.z > 0 on the side the ray arrived;
//   eval(wo, wi) is the BSDF f (1/sr) without the cosine; sample() returns wi, f |cos(wi)| / pdf and pdf.
#include "material/Ggx.h"

#include <array>
#include <glm/vec3.hpp>

namespace vkrt::test {

using Rgb = glm::dvec3;

/// One sampled direction; valid is false when the draw produced none (below the surface, zero weight).
struct BsdfSample {
    glm::dvec3 wi{0.0};
    Rgb weight{0.0}; ///< f(wo, wi) |wi.z| / pdf
    double pdf = 0.0;
    bool valid = false;
};

class ReferenceBsdf {
public:
    virtual ~ReferenceBsdf() = default;
    virtual Rgb eval(const glm::dvec3& wo, const glm::dvec3& wi) const = 0;
    virtual double pdf(const glm::dvec3& wo, const glm::dvec3& wi) const = 0;
    /// u0 picks a lobe (or reflection against refraction), (u1, u2) the direction; all in [0, 1).
    virtual BsdfSample sample(const glm::dvec3& wo, double u0, double u1, double u2) const = 0;
};

/// Mitsuba `roughconductor` (ggx, sample_visible): tint F_conductor(wo.h; eta + i k) D G / (4 cosO cosI).
class RoughConductor : public ReferenceBsdf {
public:
    RoughConductor(Ggx ggx, Rgb eta, Rgb k, Rgb tint = Rgb(1.0)) : m_ggx(ggx), m_eta(eta), m_k(k), m_tint(tint) {}
    /// A conductor with F = 1 at every angle (eta = 0, k = 1): the white furnace's lossless metal.
    static RoughConductor perfectMirror(Ggx ggx) { return RoughConductor(ggx, Rgb(0.0), Rgb(1.0)); }
    Rgb eval(const glm::dvec3& wo, const glm::dvec3& wi) const override;
    double pdf(const glm::dvec3& wo, const glm::dvec3& wi) const override;
    BsdfSample sample(const glm::dvec3& wo, double u0, double u1, double u2) const override;

private:
    Rgb fresnel(double cosH) const;
    Ggx m_ggx;
    Rgb m_eta, m_k, m_tint;
};

/// Walter et al. 2007 rough dielectric (Mitsuba `roughdielectric`, ggx, sample_visible) WITHOUT radiance
/// scaling on refraction: eta = n_t / n_i with n_i the index on the wo side (wo.z > 0).
class RoughDielectric : public ReferenceBsdf {
public:
    RoughDielectric(Ggx ggx, double eta) : m_ggx(ggx), m_eta(eta) {}
    Rgb eval(const glm::dvec3& wo, const glm::dvec3& wi) const override;
    double pdf(const glm::dvec3& wo, const glm::dvec3& wi) const override;
    BsdfSample sample(const glm::dvec3& wo, double u0, double u1, double u2) const override;

private:
    /// The generalized half vector of (wo, wi), oriented to +z; false if wi is no refraction of wo.
    bool refractionHalfVector(const glm::dvec3& wo, const glm::dvec3& wi, glm::dvec3& h) const;
    Ggx m_ggx;
    double m_eta;
};

/// Mitsuba `roughplastic` (nonlinear = false, ggx, sample_visible, specular_reflectance 1): GGX dielectric
/// coating of relative index eta over a Lambertian base of albedo rho.
class RoughPlastic : public ReferenceBsdf {
public:
    RoughPlastic(double alpha, double eta, Rgb rho);
    Rgb eval(const glm::dvec3& wo, const glm::dvec3& wi) const override;
    double pdf(const glm::dvec3& wo, const glm::dvec3& wi) const override;
    BsdfSample sample(const glm::dvec3& wo, double u0, double u1, double u2) const override;
    /// Probability of sampling the specular lobe for a viewer at cosine cosO.
    double specularProbability(double cosO) const;

private:
    Ggx m_ggx;
    double m_eta;
    Rgb m_rho;
    std::array<float, 64> m_transmittance;
    double m_internalReflectance;
    double m_specularWeight;
};

/// glTF 2.0 metallic-roughness (Appendix B) with its height-correlated Smith G; ps = probability of the GGX lobe.
class GltfPbr : public ReferenceBsdf {
public:
    GltfPbr(double alpha, Rgb base, double metallic, double specularProbability)
        : m_ggx{alpha, alpha}, m_base(base), m_metallic(metallic), m_ps(specularProbability)
    {
    }
    Rgb eval(const glm::dvec3& wo, const glm::dvec3& wi) const override;
    double pdf(const glm::dvec3& wo, const glm::dvec3& wi) const override;
    BsdfSample sample(const glm::dvec3& wo, double u0, double u1, double u2) const override;

private:
    Ggx m_ggx;
    Rgb m_base;
    double m_metallic, m_ps;
};

/// Cosine-weighted hemisphere direction (Malley's method, concentric disk).
glm::dvec3 sampleCosineHemisphere(double u1, double u2);

} // namespace vkrt::test

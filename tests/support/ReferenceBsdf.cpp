#include "support/ReferenceBsdf.h"

#include "material/Fresnel.h"
#include "material/MicrofacetAlbedo.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <numbers>

namespace vkrt::test {
namespace {

constexpr double kInvPi = 1.0 / std::numbers::pi;

/// The sample record for direction wi with weight f |cos| / pdf, or invalid when pdf or f vanish.
BsdfSample makeSample(const ReferenceBsdf& bsdf, const glm::dvec3& wo, const glm::dvec3& wi)
{
    BsdfSample s;
    s.wi = wi;
    s.pdf = bsdf.pdf(wo, wi);
    if (!(s.pdf > 0.0) || !std::isfinite(s.pdf)) return s;
    s.weight = bsdf.eval(wo, wi) * std::abs(wi.z) / s.pdf;
    s.valid = s.weight.x > 0.0 || s.weight.y > 0.0 || s.weight.z > 0.0;
    return s;
}

/// D G / (4 cosO cosI) for a reflection about h.
double specularFactor(const Ggx& ggx, const glm::dvec3& wo, const glm::dvec3& wi, const glm::dvec3& h)
{
    return ggx.d(h) * ggx.g(wo, wi, h) / (4.0 * wo.z * wi.z);
}

/// Half vector of a reflection, or false for directions not both above the surface.
bool reflectionHalfVector(const glm::dvec3& wo, const glm::dvec3& wi, glm::dvec3& h)
{
    if (wo.z <= 0.0 || wi.z <= 0.0) return false;
    h = glm::normalize(wo + wi);
    return true;
}

} // namespace

glm::dvec3 sampleCosineHemisphere(double u1, double u2)
{
    // Shirley-Chiu concentric map of the square to the disk, then project up.
    double a = 2.0 * u1 - 1.0, b = 2.0 * u2 - 1.0;
    double r = 0.0, phi = 0.0;
    if (a != 0.0 || b != 0.0) {
        if (std::abs(a) > std::abs(b)) {
            r = a;
            phi = 0.25 * std::numbers::pi * (b / a);
        } else {
            r = b;
            phi = 0.5 * std::numbers::pi - 0.25 * std::numbers::pi * (a / b);
        }
    }
    double x = r * std::cos(phi), y = r * std::sin(phi);
    return {x, y, std::sqrt(std::max(0.0, 1.0 - x * x - y * y))};
}

// ---- Conductor ---------------------------------------------------------------------------------------

Rgb RoughConductor::fresnel(double cosH) const
{
    return m_tint * Rgb(fresnelConductor(cosH, m_eta.x, m_k.x), fresnelConductor(cosH, m_eta.y, m_k.y),
                        fresnelConductor(cosH, m_eta.z, m_k.z));
}

Rgb RoughConductor::eval(const glm::dvec3& wo, const glm::dvec3& wi) const
{
    glm::dvec3 h;
    if (!reflectionHalfVector(wo, wi, h)) return Rgb(0.0);
    return fresnel(glm::dot(wo, h)) * specularFactor(m_ggx, wo, wi, h);
}

double RoughConductor::pdf(const glm::dvec3& wo, const glm::dvec3& wi) const
{
    glm::dvec3 h;
    if (!reflectionHalfVector(wo, wi, h)) return 0.0;
    double cosH = glm::dot(wo, h);
    return cosH > 0.0 ? m_ggx.visibleNormalPdf(wo, h) / (4.0 * cosH) : 0.0;
}

BsdfSample RoughConductor::sample(const glm::dvec3& wo, double, double u1, double u2) const
{
    if (wo.z <= 0.0) return {};
    glm::dvec3 m = m_ggx.sampleVisibleNormal(wo, u1, u2);
    glm::dvec3 wi = reflect(wo, m);
    if (wi.z <= 0.0) return {};
    // The weight in closed form (D and G1(wo) cancel against the pdf), not eval / pdf: tests compare them.
    BsdfSample s{wi, fresnel(glm::dot(wo, m)) * m_ggx.g1(wi, m), pdf(wo, wi), true};
    s.valid = s.pdf > 0.0 && (s.weight.x > 0.0 || s.weight.y > 0.0 || s.weight.z > 0.0);
    return s;
}

// ---- Rough dielectric --------------------------------------------------------------------------------

bool RoughDielectric::refractionHalfVector(const glm::dvec3& wo, const glm::dvec3& wi, glm::dvec3& h) const
{
    if (wo.z <= 0.0 || wi.z >= 0.0) return false;
    glm::dvec3 sum = wo + m_eta * wi; // n_i wo + n_t wi with n_i = 1
    double length = glm::length(sum);
    if (!(length > 0.0)) return false;
    h = -sum / length;
    if (h.z < 0.0) h = -h;
    // A refraction about h has wo in front of the microfacet and wi behind it.
    return glm::dot(wo, h) > 0.0 && glm::dot(wi, h) < 0.0;
}

Rgb RoughDielectric::eval(const glm::dvec3& wo, const glm::dvec3& wi) const
{
    glm::dvec3 h;
    if (wi.z > 0.0) {
        if (!reflectionHalfVector(wo, wi, h)) return Rgb(0.0);
        double cosH = glm::dot(wo, h);
        return Rgb(fresnelDielectric(cosH, m_eta).reflectance * specularFactor(m_ggx, wo, wi, h));
    }
    if (!refractionHalfVector(wo, wi, h)) return Rgb(0.0);
    double cosOH = glm::dot(wo, h), cosIH = glm::dot(wi, h);
    double fresnel = fresnelDielectric(cosOH, m_eta).reflectance;
    double denominator = cosOH + m_eta * cosIH;
    // Walter et al. eq. 21 with n_t^2 (not n_i^2) in the numerator: no radiance scaling, so that the
    // sampling weight is exactly G1(wi, h) and roughness 0 gives the smooth dielectric's weight 1.
    double value = std::abs(cosOH * cosIH) / (wo.z * std::abs(wi.z)) * (1.0 - fresnel) * m_ggx.d(h)
                 * m_ggx.g(wo, wi, h) * m_eta * m_eta / (denominator * denominator);
    return Rgb(value);
}

double RoughDielectric::pdf(const glm::dvec3& wo, const glm::dvec3& wi) const
{
    glm::dvec3 h;
    if (wi.z > 0.0) {
        if (!reflectionHalfVector(wo, wi, h)) return 0.0;
        double cosH = glm::dot(wo, h);
        if (cosH <= 0.0) return 0.0;
        return fresnelDielectric(cosH, m_eta).reflectance * m_ggx.visibleNormalPdf(wo, h) / (4.0 * cosH);
    }
    if (!refractionHalfVector(wo, wi, h)) return 0.0;
    double cosOH = glm::dot(wo, h), cosIH = glm::dot(wi, h);
    double fresnel = fresnelDielectric(cosOH, m_eta).reflectance;
    double denominator = cosOH + m_eta * cosIH;
    return (1.0 - fresnel) * m_ggx.visibleNormalPdf(wo, h) * m_eta * m_eta * std::abs(cosIH)
         / (denominator * denominator);
}

BsdfSample RoughDielectric::sample(const glm::dvec3& wo, double u0, double u1, double u2) const
{
    if (wo.z <= 0.0) return {};
    glm::dvec3 m = m_ggx.sampleVisibleNormal(wo, u1, u2);
    double cosM = glm::dot(wo, m);
    DielectricFresnel fresnel = fresnelDielectric(cosM, m_eta);
    glm::dvec3 wi;
    if (u0 < fresnel.reflectance) {
        wi = reflect(wo, m);
        if (wi.z <= 0.0) return {};
    } else {
        // Refraction about m: wi = -wo / eta + (cosM / eta - cosT) m.
        wi = -fresnel.etaTI * wo + (fresnel.etaTI * cosM - fresnel.cosT) * m;
        if (wi.z >= 0.0) return {};
    }
    wi = glm::normalize(wi);
    // Closed-form weight G1(wi, m) for both branches (F or 1 - F cancels against the branch choice).
    BsdfSample s{wi, Rgb(m_ggx.g1(wi, m)), pdf(wo, wi), true};
    s.valid = s.pdf > 0.0 && s.weight.x > 0.0;
    return s;
}

// ---- Rough plastic -----------------------------------------------------------------------------------

RoughPlastic::RoughPlastic(double alpha, double eta, Rgb rho)
    : m_ggx{std::max(alpha, 1e-4), std::max(alpha, 1e-4)},
      m_eta(eta),
      m_rho(rho),
      m_transmittance(roughTransmittanceTable(alpha, eta)),
      m_internalReflectance(internalDiffuseReflectance(alpha, eta)),
      m_specularWeight(1.0 / ((rho.x + rho.y + rho.z) / 3.0 + 1.0))
{
}

double RoughPlastic::specularProbability(double cosO) const
{
    double t = lerpTransmittance(m_transmittance, cosO);
    double specular = (1.0 - t) * m_specularWeight, diffuse = t * (1.0 - m_specularWeight);
    return specular / (specular + diffuse);
}

Rgb RoughPlastic::eval(const glm::dvec3& wo, const glm::dvec3& wi) const
{
    glm::dvec3 h;
    if (!reflectionHalfVector(wo, wi, h)) return Rgb(0.0);
    double specular = fresnelDielectric(glm::dot(wo, h), m_eta).reflectance * specularFactor(m_ggx, wo, wi, h);
    double transmit = lerpTransmittance(m_transmittance, wo.z) * lerpTransmittance(m_transmittance, wi.z);
    Rgb diffuse = m_rho / (1.0 - m_internalReflectance) * (kInvPi / (m_eta * m_eta) * transmit);
    return Rgb(specular) + diffuse;
}

double RoughPlastic::pdf(const glm::dvec3& wo, const glm::dvec3& wi) const
{
    glm::dvec3 h;
    if (!reflectionHalfVector(wo, wi, h)) return 0.0;
    double ps = specularProbability(wo.z);
    double cosH = glm::dot(wo, h);
    double specular = cosH > 0.0 ? m_ggx.visibleNormalPdf(wo, h) / (4.0 * cosH) : 0.0;
    return ps * specular + (1.0 - ps) * wi.z * kInvPi;
}

BsdfSample RoughPlastic::sample(const glm::dvec3& wo, double u0, double u1, double u2) const
{
    if (wo.z <= 0.0) return {};
    glm::dvec3 wi = u0 < specularProbability(wo.z) ? reflect(wo, m_ggx.sampleVisibleNormal(wo, u1, u2))
                                                    : sampleCosineHemisphere(u1, u2);
    if (wi.z <= 0.0) return {};
    return makeSample(*this, wo, wi);
}

// ---- glTF metallic-roughness -------------------------------------------------------------------------

Rgb GltfPbr::eval(const glm::dvec3& wo, const glm::dvec3& wi) const
{
    glm::dvec3 h;
    if (!reflectionHalfVector(wo, wi, h)) return Rgb(0.0);
    double schlick = std::pow(1.0 - std::abs(glm::dot(wo, h)), 5.0);
    double specular = m_ggx.d(h) * m_ggx.gCorrelated(wo, wi, h) / (4.0 * wo.z * wi.z);
    double dielectricF = 0.04 + 0.96 * schlick;
    Rgb metalF = m_base + (Rgb(1.0) - m_base) * schlick;
    Rgb dielectric = (1.0 - dielectricF) * m_base * kInvPi + Rgb(dielectricF * specular);
    return (1.0 - m_metallic) * dielectric + m_metallic * metalF * specular;
}

double GltfPbr::pdf(const glm::dvec3& wo, const glm::dvec3& wi) const
{
    glm::dvec3 h;
    if (!reflectionHalfVector(wo, wi, h)) return 0.0;
    double cosH = glm::dot(wo, h);
    double specular = cosH > 0.0 ? m_ggx.visibleNormalPdf(wo, h) / (4.0 * cosH) : 0.0;
    return m_ps * specular + (1.0 - m_ps) * wi.z * kInvPi;
}

BsdfSample GltfPbr::sample(const glm::dvec3& wo, double u0, double u1, double u2) const
{
    if (wo.z <= 0.0) return {};
    glm::dvec3 wi = u0 < m_ps ? reflect(wo, m_ggx.sampleVisibleNormal(wo, u1, u2)) : sampleCosineHemisphere(u1, u2);
    if (wi.z <= 0.0) return {};
    return makeSample(*this, wo, wi);
}

} // namespace vkrt::test

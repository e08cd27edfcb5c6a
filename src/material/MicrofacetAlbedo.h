#pragma once
// Precomputed albedos of a rough (GGX) dielectric interface, for the energy-consistent rough plastic
// (Mitsuba 3 `roughplastic` with nonlinear = false): the renderer tabulates them per material at scene
// load. All in double precision, accurate to 1e-4 absolute (tests/material/microfacet_albedo_test.cpp).
#include <array>

namespace vkrt {

/// Number of incidence cosines in the rough transmittance table (Mitsuba's MTS_ROUGH_TRANSMITTANCE_RES).
inline constexpr int kRoughTransmittanceResolution = 64;

/// The incidence cosine of entry i of the table: max(1e-6, i / 63), as Mitsuba tabulates it.
double roughTransmittanceCosine(int i);

/// Directional albedo R(mu) = integral over the hemisphere of f_s(wo, wi) cos(wi) dwi of the GGX
/// specular reflection f_s = F D G / (4 cosO cosI) (separable Smith G, exact dielectric Fresnel of
/// relative index eta = n_below / n_above) for a direction at cosine mu (0 < mu <= 1) above an isotropic
/// interface of roughness alpha (clamped to >= 1e-4, as Mitsuba does). quadratureOrder is the number of
/// Gauss-Legendre nodes per smooth segment of each dimension (0: chosen by mu to meet the 1e-4 bound).
double roughSpecularAlbedo(double mu, double alpha, double eta, int quadratureOrder = 0);

/// The energy a rough interface transmits from a direction at cosine mu above it: the expected
/// (1 - F(w.m)) G1(t, m) over visible normals m, t the refracted direction. Less than 1 - R(mu): light
/// masked on the far side is lost (Mitsuba 3's eval_transmittance, which its roughplastic tabulates).
double roughTransmittance(double mu, double alpha, double eta);

/// T(mu_i) = roughTransmittance(mu_i; alpha, eta) at the 64 cosines of roughTransmittanceCosine, for Mitsuba's
/// linear interpolation: x = cos * 63, i = min(floor(x), 62), T = lerp(table[i], table[i + 1], x - i).
std::array<float, kRoughTransmittanceResolution> roughTransmittanceTable(double alpha, double eta);

/// Fdr_int = 2 * mean_i( R(mu_i; alpha, 1 / eta) * mu_i ) over the 64 table cosines: the fraction of
/// diffuse light from below that the rough interface reflects back down (Mitsuba's definition, a
/// 64-point mean rather than the exact cosine-weighted integral, so that images match Mitsuba's).
double internalDiffuseReflectance(double alpha, double eta);

/// Mitsuba's smooth `plastic` Fdr_int: fresnel_diffuse_reflectance(1 / eta), the fits of Egan & Hilgeman
/// (1973) for a relative index < 1 and d'Eon & Irving (2011) for > 1 to the diffuse Fresnel reflectance.
double smoothInternalDiffuseReflectance(double eta);

/// Linear interpolation in a transmittance table exactly as Mitsuba's lerp_gather does it.
double lerpTransmittance(const std::array<float, kRoughTransmittanceResolution>& table, double cosTheta);

} // namespace vkrt

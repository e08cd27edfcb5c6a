#pragma once
// The Charlie sheen of KHR_materials_sheen (Estevez and Kulla 2017, "Production
// Friendly Microfacet Sheen BRDF", in the form the extension gives) in double
// precision, and the table of its directional albedo E(mu, roughness) that the
// pbr material's albedo scaling reads (shared/SceneTypes.h: SHEEN_TABLE_SIDE).
#include <vector>

namespace vkrt {

/// The table's side and the narrowest sheen, as shared/SceneTypes.h has them (SHEEN_TABLE_SIDE,
/// MIN_SHEEN_ALPHA; src/render/GpuScene.cpp asserts that they agree: src/material includes nothing of vkrt).
inline constexpr unsigned kSheenTableSide = 64;
inline constexpr double kMinSheenAlpha = 1e-3;

/// alpha_g = roughness^2, kept at or above kMinSheenAlpha (the distribution divides by it).
double sheenAlpha(double roughness);

/// The Charlie distribution D(h) at cos(theta_h) = cosH.
double charlieDistribution(double cosH, double alpha);

/// The Charlie visibility's Lambda(cos theta) (the extension's fit).
double charlieLambda(double cosTheta, double alpha);

/// The sheen BRDF (colour 1) D V for directions at cosines cosO, cosI > 0 with half vector at cosH.
double sheenBrdf(double cosO, double cosI, double cosH, double alpha);

/// E(mu) = integral over the hemisphere of sheenBrdf cos(theta_i) for a direction at cosine mu,
/// by a product midpoint rule in (sqrt(cos theta_i), phi) (nodes clustered at grazing, where the
/// lobe lives); within 3e-4 of a 16 times finer grid near grazing, 1e-5 elsewhere (0.23-0.25 s of one
/// core for the whole table, once per process).
double sheenDirectionalAlbedo(double mu, double roughness);

/// The kSheenTableSide^2 entries of the sheen table: E at roughness j / (side - 1) and
/// cosine (i / (side - 1))^2 (cosine 0 taken as 1e-4), entry j * side + i. Computed once, then cached.
const std::vector<float>& sheenAlbedoTable();

} // namespace vkrt

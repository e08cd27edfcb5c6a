// The glTF 2.0 PBR reference (see GltfPbrReference.h): every formula below is taken from the Khronos texts
// (glTF 2.0 Appendix B, KHR_materials_specular, _ior, _sheen, _clearcoat), quoted where it matters; nothing
// here is derived from vkrt's shaders or from src/material, so that the two can be checked against each other.
#include "support/GltfPbrReference.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <glm/geometric.hpp>
#include <map>
#include <mutex>
#include <numbers>
#include <utility>
#include <vector>

namespace vkrt::test {
namespace {

constexpr double kPi = std::numbers::pi;

double max3(const glm::dvec3& v) { return std::max(std::max(v.x, v.y), v.z); }

double mix(double x, double y, double a) { return x * (1.0 - a) + y * a; }

/// (1 - |c|)^5: Schlick's Fresnel weight of Appendix B.
double schlickWeight(double c)
{
    double m = 1.0 - std::min(1.0, std::abs(c));
    double m2 = m * m;
    return m2 * m2 * m;
}

// ---- GGX (Appendix B), written out here rather than taken from src/material/Ggx.h --------------------------

/// D_GGX(h) = alpha^2 / (pi (cos^2 (alpha^2 - 1) + 1)^2); alpha 0 (a Dirac lobe) gives its off-peak value 0.
double ggxD(double cosH, double alpha)
{
    if (cosH <= 0.0 || alpha <= 0.0) return 0.0;
    double a2 = alpha * alpha;
    double c2 = cosH * cosH;
    // (cos^2 (alpha^2 - 1) + 1) written as cos^2 alpha^2 + sin^2: no cancellation near cos = 1.
    double t = c2 * a2 + std::max(0.0, 1.0 - c2);
    return a2 / (kPi * t * t);
}

/// Smith's Lambda(w) = (sqrt(1 + alpha^2 tan^2 theta) - 1) / 2, as t / (2 (1 + sqrt(1 + t))) with
/// t = alpha^2 tan^2 theta, which keeps its digits for small t.
double ggxLambda(double cosW, double alpha)
{
    double c2 = std::min(1.0, cosW * cosW);
    if (c2 <= 0.0) return INFINITY;
    double t = alpha * alpha * (1.0 - c2) / c2;
    return 0.5 * t / (1.0 + std::sqrt(1.0 + t));
}

/// specular_brdf(alpha) = D_GGX * V_GGX with V_GGX = G / (4 |N.L| |N.V|), G = 1 / (1 + Lambda(V) + Lambda(L)),
/// zero when V or L sees the back of the microfacet h (which never happens for h = normalize(V + L) with both
/// directions above the surface, but the spec states it, so it is kept).
double specularBrdf(double alpha, const glm::dvec3& v, const glm::dvec3& l, const glm::dvec3& h)
{
    if (glm::dot(v, h) <= 0.0 || glm::dot(l, h) <= 0.0) return 0.0;
    double d = ggxD(h.z, alpha);
    if (d == 0.0) return 0.0;
    double g = 1.0 / (1.0 + ggxLambda(v.z, alpha) + ggxLambda(l.z, alpha));
    return d * g / (4.0 * v.z * l.z);
}

// ---- Anisotropic GGX (KHR_materials_anisotropy, "Implementation") ------------------------------------------

/// "D_GGX_anisotropic(NdotH, TdotH, BdotH, at, ab): a2 = at * ab; f = vec3(ab * TdotH, at * BdotH, a2 * NdotH);
/// w2 = a2 / dot(f, f); return a2 * w2 * w2 / PI".
double ggxDAnisotropic(double nDotH, double tDotH, double bDotH, double at, double ab)
{
    if (nDotH <= 0.0) return 0.0;
    double a2 = at * ab;
    glm::dvec3 f(ab * tDotH, at * bDotH, a2 * nDotH);
    double w2 = a2 / glm::dot(f, f);
    return a2 * w2 * w2 / kPi;
}

/// "V_GGX_anisotropic: GGXV = NdotL * length(vec3(at * TdotV, ab * BdotV, NdotV)); GGXL = NdotV * length(vec3(at
/// * TdotL, ab * BdotL, NdotL)); v = 0.5 / (GGXV + GGXL); return clamp(v, 0.0, 1.0)", without the clamp: V = G / (4
/// N.L N.V) exceeds 1 where both cosines are small (1.08 at N.V 0.95, N.L 0.2, at 0.70, ab 0.16), the isotropic
/// V_GGX of Appendix B has no clamp, and with it the lobe would not be the Smith GGX it stands for.
double ggxVAnisotropic(const glm::dvec3& v, const glm::dvec3& l, const glm::dvec3& t, const glm::dvec3& b, double at,
                       double ab)
{
    double ggxV = l.z * glm::length(glm::dvec3(at * glm::dot(t, v), ab * glm::dot(b, v), v.z));
    double ggxL = v.z * glm::length(glm::dvec3(at * glm::dot(t, l), ab * glm::dot(b, l), l.z));
    return 0.5 / (ggxV + ggxL);
}

/// The base's specular_brdf with KHR_materials_anisotropy: "alphaRoughness = roughness^2; at = mix(alphaRoughness,
/// 1.0, anisotropy^2); ab = clamp(alphaRoughness, 0.001, 1.0)"; T at the given angle in the tangent plane and
/// "anisotropicB = cross(normal, anisotropicT)".
double anisotropicSpecularBrdf(const GltfPbrParams& p, const glm::dvec3& v, const glm::dvec3& l, const glm::dvec3& h)
{
    double alpha = p.roughness * p.roughness;
    double at = mix(alpha, 1.0, p.anisotropy * p.anisotropy);
    double ab = std::clamp(alpha, 0.001, 1.0);
    glm::dvec3 t(std::cos(p.anisotropyAngle), std::sin(p.anisotropyAngle), 0.0);
    glm::dvec3 b = glm::cross(glm::dvec3(0.0, 0.0, 1.0), t);
    return ggxDAnisotropic(h.z, glm::dot(t, h), glm::dot(b, h), at, ab) * ggxVAnisotropic(v, l, t, b, at, ab);
}

// ---- Charlie sheen (KHR_materials_sheen, "Implementation Notes") -------------------------------------------

double sheenAlphaG(double sheenRoughness) { return std::max(sheenRoughness * sheenRoughness, kMinSheenAlphaG); }

/// sheen_distribution = (2 + inv_r) * pow(sin2h, inv_r * 0.5) / (2 * PI), inv_r = 1 / alpha_g, from sin^2 h.
double charlieDFromSin2(double sin2h, double alphaG)
{
    double invR = 1.0 / alphaG;
    return (2.0 + invR) * std::pow(std::max(0.0, sin2h), 0.5 * invR) / (2.0 * kPi);
}

/// The spec's fit l(x, alpha_g), coefficient for coefficient.
double sheenL(double x, double alphaG)
{
    double oneMinusAlphaSq = (1.0 - alphaG) * (1.0 - alphaG);
    double a = mix(21.5473, 25.3245, oneMinusAlphaSq);
    double b = mix(3.82987, 3.32435, oneMinusAlphaSq);
    double c = mix(0.19823, 0.16801, oneMinusAlphaSq);
    double d = mix(-1.97760, -1.27393, oneMinusAlphaSq);
    double e = mix(-4.32054, -4.85967, oneMinusAlphaSq);
    return a / (1.0 + b * std::pow(x, c)) + d * x + e;
}

/// lambda_sheen: exp(l(cos)) below cos 0.5, exp(2 l(0.5) - l(1 - cos)) above (the two meet with equal value
/// and slope at 0.5, but not equal curvature: quadratures break their panels there).
double sheenLambda(double cosTheta, double alphaG)
{
    double c = std::min(1.0, std::abs(cosTheta));
    return c < 0.5 ? std::exp(sheenL(c, alphaG)) : std::exp(2.0 * sheenL(0.5, alphaG) - sheenL(1.0 - c, alphaG));
}

// ---- E(mu) by quadrature -----------------------------------------------------------------------------------

struct GaussRule {
    std::vector<double> x, w; // on [-1, 1]
};

/// Gauss-Legendre nodes and weights by Newton's iteration on P_n (converged to rounding).
GaussRule gaussLegendre(int n)
{
    GaussRule rule;
    rule.x.resize(n);
    rule.w.resize(n);
    for (int i = 0; i < (n + 1) / 2; ++i) {
        double x = std::cos(kPi * (i + 0.75) / (n + 0.5));
        double dp = 0.0;
        for (int iter = 0; iter < 100; ++iter) {
            double p0 = 1.0, p1 = x;
            for (int k = 2; k <= n; ++k) {
                double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
                p0 = p1;
                p1 = p2;
            }
            // p1 = P_n(x), p0 = P_{n-1}(x) (also for n = 1, where the loop does not run).
            dp = n * (x * p1 - p0) / (x * x - 1.0);
            double dx = p1 / dp;
            x -= dx;
            if (std::abs(dx) < 1e-16) break;
        }
        rule.x[i] = x;
        rule.x[n - 1 - i] = -x;
        rule.w[i] = rule.w[n - 1 - i] = 2.0 / ((1.0 - x * x) * dp * dp);
    }
    return rule;
}

const GaussRule& gaussRule(int n)
{
    static std::mutex mutex;
    static std::map<int, GaussRule> rules;
    std::lock_guard lock(mutex);
    auto it = rules.find(n);
    if (it == rules.end()) it = rules.emplace(n, gaussLegendre(n)).first;
    return it->second;
}

/// Composite Gauss-Legendre nodes (absolute) and weights over the panels between consecutive breaks.
void compositeNodes(std::vector<double> breaks, int order, std::vector<double>& x, std::vector<double>& w)
{
    std::sort(breaks.begin(), breaks.end());
    const GaussRule& rule = gaussRule(order);
    x.clear();
    w.clear();
    for (size_t i = 0; i + 1 < breaks.size(); ++i) {
        double a = breaks[i], b = breaks[i + 1];
        if (!(b - a > 1e-14)) continue;
        double half = 0.5 * (b - a), mid = 0.5 * (a + b);
        for (int k = 0; k < order; ++k) {
            x.push_back(mid + half * rule.x[k]);
            w.push_back(half * rule.w[k]);
        }
    }
}

/// E(mu) = integral over the hemisphere of D V_charlie cos(L) dL = (1 / (4 mu)) integral of
/// D(h) / (1 + Lambda(mu) + Lambda(u)) du dphi, u = cos(L), phi the azimuth of L from that of V.
///
/// The integrand is symmetric in phi (twice the integral over [0, pi]) and has three features that a plain
/// product rule would resolve slowly, so the composite Gauss-Legendre panels are placed on them:
///   - u = 0.5, where lambda_sheen switches branch (second derivative jumps): a panel break;
///   - u -> 0 and u -> 1, where Lambda(u) = exp(l(u)) and exp(2 l(0.5) - l(1 - u)) carry the x^c of the fit
///     (c ~ 0.17 to 0.2, infinite slope at x = 0): panels halving towards both ends (without those towards 1
///     the rule stalls near 1e-7);
///   - the mirror direction (u = mu, phi = pi), where sin^2 h vanishes and D ~ |sin h|^(1 / alpha_g) is a
///     cone for alpha_g = 1 (not smooth for alpha_g > 0.5): panels halving towards it in u and in phi.
/// The small-roughness peak of D at sin h -> 1 (both directions grazing) is a few hundredths wide in u at
/// alpha_g = 1e-3 and sits inside the panels halving towards u = 0. refinement multiplies the nodes per panel
/// (6 each at refinement 1) and adds halving levels (for convergence checks). Against refinement 3, refinement
/// 1 is within 4.2e-8 of E (absolute, over sheenRoughness 0 to 1 by 0.05 and mu from 1e-4 to 1), about 0.5 ms.
double sheenAlbedoQuadrature(double mu, double alphaG, int refinement)
{
    if (!(mu > 0.0)) return 0.0;
    mu = std::min(mu, 1.0);
    const int order = 6 * refinement;
    const int levels = 4 + 4 * refinement;

    std::vector<double> uBreaks = {0.0, 0.5, 1.0};
    for (int k = 1; k <= levels + 6; ++k) {
        uBreaks.push_back(0.5 * std::ldexp(1.0, -k));
        uBreaks.push_back(1.0 - 0.5 * std::ldexp(1.0, -k));
    }
    for (int k = 0; k <= levels; ++k) {
        double d = 0.25 * std::ldexp(1.0, -k);
        if (mu - d > 0.0) uBreaks.push_back(mu - d);
        if (mu + d < 1.0) uBreaks.push_back(mu + d);
    }
    uBreaks.push_back(mu);
    std::vector<double> phiBreaks = {0.0, 0.25 * kPi, 0.5 * kPi, 0.75 * kPi, kPi};
    for (int k = 1; k <= levels; ++k) phiBreaks.push_back(kPi - 0.25 * kPi * std::ldexp(1.0, -k));

    std::vector<double> us, uw, phis, phiw;
    compositeNodes(uBreaks, order, us, uw);
    compositeNodes(phiBreaks, order, phis, phiw);
    std::vector<double> cosPhi(phis.size()), sinPhi(phis.size());
    for (size_t j = 0; j < phis.size(); ++j) {
        cosPhi[j] = std::cos(phis[j]);
        sinPhi[j] = std::sin(phis[j]);
    }

    const double sinV = std::sqrt(std::max(0.0, 1.0 - mu * mu));
    const double lambdaV = sheenLambda(mu, alphaG);
    double sum = 0.0;
    for (size_t i = 0; i < us.size(); ++i) {
        double u = us[i];
        double sinU = std::sqrt(std::max(0.0, 1.0 - u * u));
        double z = mu + u;
        double inner = 0.0;
        for (size_t j = 0; j < phis.size(); ++j) {
            // V + L = (sinV + sinU cos phi, sinU sin phi, mu + u): sin^2 h from its horizontal part, exactly.
            double hx = sinV + sinU * cosPhi[j], hy = sinU * sinPhi[j];
            double horizontal = hx * hx + hy * hy;
            inner += phiw[j] * charlieDFromSin2(horizontal / (horizontal + z * z), alphaG);
        }
        sum += uw[i] * inner / (1.0 + lambdaV + sheenLambda(u, alphaG));
    }
    return 2.0 * sum / (4.0 * mu);
}

} // namespace

double charlieD(double cosH, double sheenRoughness)
{
    double c = std::min(1.0, std::abs(cosH));
    return charlieDFromSin2(1.0 - c * c, sheenAlphaG(sheenRoughness));
}

double charlieVisibility(double cosV, double cosL, double sheenRoughness)
{
    if (cosV <= 0.0 || cosL <= 0.0) return 0.0;
    double alphaG = sheenAlphaG(sheenRoughness);
    return 1.0 / ((1.0 + sheenLambda(cosV, alphaG) + sheenLambda(cosL, alphaG)) * (4.0 * cosV * cosL));
}

double sheenDirectionalAlbedoUncached(double mu, double sheenRoughness, int refinement)
{
    return sheenAlbedoQuadrature(mu, sheenAlphaG(sheenRoughness), std::max(1, refinement));
}

double sheenDirectionalAlbedo(double mu, double sheenRoughness)
{
    // Memoized per (alpha_g, mu): the albedo scaling asks for E at N.V and N.L of every evaluation, and a
    // hemisphere integral over a product grid asks for the same few values of N.L again and again.
    static std::mutex mutex;
    static std::map<std::pair<double, double>, double> cache;
    std::pair<double, double> key(sheenAlphaG(sheenRoughness), std::clamp(mu, 0.0, 1.0));
    {
        std::lock_guard lock(mutex);
        auto it = cache.find(key);
        if (it != cache.end()) return it->second;
    }
    double e = sheenAlbedoQuadrature(key.second, key.first, 1);
    std::lock_guard lock(mutex);
    cache.emplace(key, e);
    return e;
}

glm::dvec3 gltfPbrEval(const GltfPbrParams& p, const glm::dvec3& wo, const glm::dvec3& wi)
{
    if (!(wo.z > 0.0) || !(wi.z > 0.0)) return glm::dvec3(0.0);
    const glm::dvec3& v = wo;
    const glm::dvec3& l = wi;
    glm::dvec3 h = glm::normalize(v + l);
    double vDotH = glm::dot(v, h);
    double w = schlickWeight(vDotH);
    double specular = p.anisotropy > 0.0 ? anisotropicSpecularBrdf(p, v, l, h)
                                         : specularBrdf(p.roughness * p.roughness, v, l, h);

    // KHR_materials_specular with KHR_materials_ior: "dielectric_f0 = min(((ior - outside_ior) / (ior +
    // outside_ior))^2 * specularColor, float3(1.0)) * specular; dielectric_f90 = specular", outside_ior 1;
    // "dielectric_brdf = dielectric_fresnel * specular_brdf + (1 - max_value(dielectric_fresnel)) *
    // diffuse_brdf". ior 0 (the specular-glossiness mode) gives ((0 - 1) / (0 + 1))^2 = 1 by the same formula.
    double iorF0 = (p.ior - 1.0) / (p.ior + 1.0);
    iorF0 *= iorF0;
    glm::dvec3 dielectricF0 = glm::min(iorF0 * p.specularColor, glm::dvec3(1.0)) * p.specular;
    glm::dvec3 dielectricF90(p.specular);
    glm::dvec3 dielectricFresnel = dielectricF0 + (dielectricF90 - dielectricF0) * w;
    glm::dvec3 dielectric = dielectricFresnel * specular + (1.0 - max3(dielectricFresnel)) * p.baseColor / kPi;

    // Appendix B: metal_brdf = conductor_fresnel(f0 = baseColor, bsdf = specular_brdf(alpha = roughness^2)).
    glm::dvec3 metal = (p.baseColor + (1.0 - p.baseColor) * w) * specular;
    glm::dvec3 material = dielectric * (1.0 - p.metallic) + metal * p.metallic;

    // KHR_materials_sheen: "If sheenColorFactor is zero, the whole sheen layer is disabled" (the formula would
    // give material * 1 + 0 as well; skipping it also skips the quadratures of E).
    glm::dvec3 sheenMaterial = material;
    if (p.sheenColor != glm::dvec3(0.0)) {
        double sheenBrdf = charlieD(h.z, p.sheenRoughness) * charlieVisibility(v.z, l.z, p.sheenRoughness);
        // "sheen_albedo_scaling = min(1.0 - max3(sheenColor) * E(VdotN), 1.0 - max3(sheenColor) * E(LdotN))"
        double c = max3(p.sheenColor);
        double scaling = std::min(1.0 - c * sheenDirectionalAlbedo(v.z, p.sheenRoughness),
                                  1.0 - c * sheenDirectionalAlbedo(l.z, p.sheenRoughness));
        sheenMaterial = p.sheenColor * sheenBrdf + material * scaling;
    }

    // KHR_materials_clearcoat, on top of sheen ("If clearcoat is active at the same time, clearcoat is layered
    // on top of sheen", KHR_materials_sheen): "clearcoat_fresnel = 0.04 + (1 - 0.04) * (1 - abs(VdotNc))^5",
    // "coated_material = mix(material, clearcoat_brdf, clearcoat * clearcoat_fresnel)", and the Discussion:
    // "we compute the microfacet Fresnel term with NdotV instead of VdotH". Nc is the normal +z here.
    // With clearcoatNormalTexture Nc is the coat's own normal: its lobe is the GGX about Nc (the directions'
    // coordinates in a frame around Nc), lit by cos(Nc, L) where the base is lit by cos(N, L).
    if (p.clearcoat == 0.0) return sheenMaterial; // "If clearcoatFactor is zero, the whole layer is disabled"
    const glm::dvec3 nc = glm::normalize(p.clearcoatNormal);
    const glm::dvec3 tc = glm::normalize(std::abs(nc.x) < 0.9 ? glm::cross(nc, glm::dvec3(1.0, 0.0, 0.0))
                                                              : glm::cross(nc, glm::dvec3(0.0, 1.0, 0.0)));
    const glm::dvec3 bc = glm::cross(nc, tc);
    auto coatLocal = [&](const glm::dvec3& w) { return glm::dvec3(glm::dot(w, tc), glm::dot(w, bc), glm::dot(w, nc)); };
    const glm::dvec3 vc = coatLocal(v), lc = coatLocal(l);
    double coatFresnel = 0.04 + (1.0 - 0.04) * schlickWeight(vc.z);
    double coatBrdf = 0.0;
    if (vc.z > 0.0 && lc.z > 0.0)
        coatBrdf = specularBrdf(p.clearcoatRoughness * p.clearcoatRoughness, vc, lc, glm::normalize(vc + lc)) *
                   lc.z / l.z;
    double t = p.clearcoat * coatFresnel;
    return sheenMaterial * (1.0 - t) + glm::dvec3(coatBrdf * t);
}

} // namespace vkrt::test

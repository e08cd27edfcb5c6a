#include "material/MicrofacetAlbedo.h"

#include "material/Fresnel.h"
#include "material/Ggx.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <map>
#include <mutex>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace vkrt {
namespace {

/// Gauss-Legendre nodes and weights on [-1, 1] (Newton iteration on P_n; Golub-Welsch not needed).
struct GaussLegendre {
    std::vector<double> nodes;
    std::vector<double> weights;
};

GaussLegendre computeGaussLegendre(int n)
{
    GaussLegendre rule{std::vector<double>(n), std::vector<double>(n)};
    for (int i = 0; i < (n + 1) / 2; ++i) {
        double x = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5)); // Tricomi's initial guess
        double derivative = 0.0;
        for (int iteration = 0; iteration < 100; ++iteration) {
            double p0 = 1.0, p1 = x;
            for (int k = 2; k <= n; ++k) {
                double pk = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
                p0 = p1;
                p1 = pk;
            }
            derivative = n * (x * p1 - p0) / (x * x - 1.0);
            double step = p1 / derivative;
            x -= step;
            if (std::abs(step) < 1e-16) break;
        }
        double weight = 2.0 / ((1.0 - x * x) * derivative * derivative);
        rule.nodes[i] = -x;
        rule.nodes[n - 1 - i] = x;
        rule.weights[i] = rule.weights[n - 1 - i] = weight;
    }
    return rule;
}

const GaussLegendre& gaussLegendre(int n)
{
    static std::mutex mutex;
    static std::map<int, GaussLegendre> cache;
    std::lock_guard lock(mutex);
    auto it = cache.find(n);
    if (it == cache.end()) it = cache.emplace(n, computeGaussLegendre(n)).first;
    return it->second;
}

void checkArguments(double alpha, double eta)
{
    if (!(alpha >= 0.0 && alpha <= 1.0) || !(eta > 0.0 && std::isfinite(eta)) || eta == 1.0)
        throw std::invalid_argument("microfacet albedo: alpha must be in [0, 1] and eta positive and not 1 (alpha = "
                                    + std::to_string(alpha) + ", eta = " + std::to_string(eta) + ")");
}

/// n-point Gauss-Legendre on [0, 1] after the substitution x = (1 - cos(pi s)) / 2, which clusters the
/// nodes at both ends: square-root kinks of the integrand at the ends (the critical angle, features
/// entering the domain) become smooth in s. Nodes x_i and weights (Jacobian included) per unit length.
struct ClusteredRule {
    std::vector<double> nodes;
    std::vector<double> weights;
};

const ClusteredRule& clusteredRule(int n)
{
    static std::mutex mutex;
    static std::map<int, ClusteredRule> cache;
    std::lock_guard lock(mutex);
    auto it = cache.find(n);
    if (it != cache.end()) return it->second;
    GaussLegendre gauss = computeGaussLegendre(n);
    ClusteredRule rule;
    for (int i = 0; i < n; ++i) {
        double s = 0.5 * (gauss.nodes[i] + 1.0);
        rule.nodes.push_back(0.5 * (1.0 - std::cos(std::numbers::pi * s)));
        rule.weights.push_back(0.25 * gauss.weights[i] * std::numbers::pi * std::sin(std::numbers::pi * s));
    }
    return cache.emplace(n, std::move(rule)).first->second;
}

template <typename F>
double integrateClustered(const F& f, double a, double b, const ClusteredRule& rule)
{
    double sum = 0.0;
    for (size_t i = 0; i < rule.nodes.size(); ++i) sum += rule.weights[i] * f(a + (b - a) * rule.nodes[i]);
    return (b - a) * sum;
}

/// At most this many breakpoints per integral (3 kinds of kink, each at up to 3 places).
constexpr int kMaxBreaks = 8;

/// Breakpoints of a piecewise integral, without allocation.
struct Breaks {
    std::array<double, kMaxBreaks + 2> values{};
    int count = 0;
    void add(double x)
    {
        if (count < kMaxBreaks) values[count++] = x;
    }
};

/// Integral of f over [a, b] split at the given interior breakpoints (where f has kinks).
template <typename F>
double integratePiecewise(const F& f, double a, double b, Breaks breaks, const ClusteredRule& rule)
{
    breaks.values[breaks.count++] = a;
    breaks.values[breaks.count++] = b;
    std::sort(breaks.values.begin(), breaks.values.begin() + breaks.count);
    double sum = 0.0;
    for (int i = 0; i + 1 < breaks.count; ++i) {
        double lo = std::max(a, breaks.values[i]), hi = std::min(b, breaks.values[i + 1]);
        if (hi > lo) sum += integrateClustered(f, lo, hi, rule);
    }
    return sum;
}

/// The azimuths in (0, pi) where w.h = c for a half vector at polar angle thetaH (w at thetaW, phi = 0).
void addAzimuthBreak(Breaks& breaks, double c, double sinW, double cosW, double sinH, double cosH)
{
    double denominator = sinW * sinH;
    if (denominator <= 0.0) return;
    double cosPhi = (c - cosW * cosH) / denominator;
    if (cosPhi > -1.0 && cosPhi < 1.0) breaks.add(std::acos(cosPhi));
}

/// Nodes per segment that keep the error below 1e-5 typical, 1e-4 worst (measured against order 80 for
/// alpha in [1e-4, 1], eta in [1/3, 3]): grazing incidence needs more, its kinks crowd together.
int defaultOrder(double mu)
{
    if (mu < 0.01) return 32;
    return mu < 0.05 ? 16 : 10;
}

} // namespace

double roughTransmittanceCosine(int i)
{
    return std::max(1e-6, i / double(kRoughTransmittanceResolution - 1));
}

double roughSpecularAlbedo(double mu, double alpha, double eta, int quadratureOrder)
{
    checkArguments(alpha, eta);
    int n = quadratureOrder > 0 ? quadratureOrder : defaultOrder(mu);
    alpha = std::max(alpha, 1e-4);
    Ggx ggx{alpha, alpha};
    mu = std::clamp(mu, 1e-12, 1.0);
    double thetaW = std::acos(mu);
    glm::dvec3 w(std::sqrt(1.0 - mu * mu), 0.0, mu);
    double cosCritical = eta < 1.0 ? std::sqrt(1.0 - eta * eta) : -1.0; // total internal reflection below
    // R = int F(w.h) G1(w, h) G1(r, h) D(h) (w.h) / w.z dh over half vectors h with w.h > 0 and r.z > 0
    // (r = reflect(w, h)). h is parameterized by the GGX slope angle psi (tan(theta_h) = alpha tan(psi),
    // so that D(h) cos(theta_h) dh = 2 sin(psi) cos(psi) dpsi dphi / (2 pi): the peak of D is spread out
    // for any alpha) and its azimuth phi, integrated over [0, pi] by symmetry. Every kink of the integrand
    // (w.h = 0, r.z = 0, the critical angle) lies at a known phi for each theta_h, and enters or leaves
    // the azimuth range at a known theta_h: both integrals are split there and converge spectrally.
    const ClusteredRule& rule = clusteredRule(n);
    double maskingW = ggx.g1(w, glm::dvec3(0.0, 0.0, 1.0)); // G1(w, h) is the same for every h with w.h > 0
    auto azimuthIntegral = [&](double psi) {
        double thetaH = std::atan(alpha * std::tan(psi));
        double sinH = std::sin(thetaH), cosH = std::cos(thetaH);
        Breaks breaks;
        addAzimuthBreak(breaks, 0.0, w.x, mu, sinH, cosH);
        addAzimuthBreak(breaks, mu / (2.0 * cosH), w.x, mu, sinH, cosH);
        if (cosCritical > 0.0) addAzimuthBreak(breaks, cosCritical, w.x, mu, sinH, cosH);
        auto integrand = [&](double phi) {
            glm::dvec3 h(sinH * std::cos(phi), sinH * std::sin(phi), cosH);
            double cosWH = glm::dot(w, h);
            glm::dvec3 r = reflect(w, h);
            if (cosWH <= 0.0 || r.z <= 0.0) return 0.0;
            double fresnel = fresnelDielectric(cosWH, eta).reflectance;
            return fresnel * ggx.g1(r, h) * cosWH;
        };
        return 2.0 * std::sin(psi) * std::cos(psi) * maskingW / (std::numbers::pi * mu * cosH)
             * integratePiecewise(integrand, 0.0, std::numbers::pi, breaks, rule);
    };
    // Polar angles where a kink's azimuth reaches 0 or pi, as slope angles psi.
    double halfPi = 0.5 * std::numbers::pi;
    std::array<double, 6> thetaBreaks = {halfPi - thetaW, 0.5 * (halfPi + thetaW), 0.5 * (halfPi - thetaW), -1, -1, -1};
    if (cosCritical > 0.0) {
        double thetaC = std::acos(cosCritical);
        thetaBreaks[3] = thetaW + thetaC;
        thetaBreaks[4] = thetaW - thetaC;
        thetaBreaks[5] = thetaC - thetaW;
    }
    Breaks psiBreaks;
    for (double theta : thetaBreaks)
        if (theta > 0.0 && theta < halfPi) psiBreaks.add(std::atan(std::tan(theta) / alpha));
    return integratePiecewise(azimuthIntegral, 0.0, halfPi, psiBreaks, rule);
}

double roughTransmittance(double mu, double alpha, double eta)
{
    checkArguments(alpha, eta);
    alpha = std::max(alpha, 1e-4);
    const Ggx ggx{alpha, alpha};
    const glm::dvec3 w(std::sqrt(std::max(0.0, 1.0 - mu * mu)), 0.0, std::clamp(mu, 1e-6, 1.0));
    // The expected (1 - F) G1(t, m) over visible normals m, t the refracted direction: Mitsuba 3's
    // eval_transmittance, with its quadrature (Gauss-Legendre on the square of the visible-normal
    // sampler's inputs, 32 x 32 nodes for eta > 1, 128 x 128 below), so that its tables are matched.
    const int n = eta > 1.0 ? 32 : 128;
    const GaussLegendre& rule = gaussLegendre(n);
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
            const glm::dvec3 m = ggx.sampleVisibleNormal(w, 0.5 * rule.nodes[i] + 0.5, 0.5 * rule.nodes[j] + 0.5);
            const double cosI = glm::dot(w, m);
            const DielectricFresnel fresnel = fresnelDielectric(cosI, eta);
            if (fresnel.reflectance >= 1.0) continue;
            const glm::dvec3 t = -fresnel.etaTI * w + (fresnel.etaTI * cosI - fresnel.cosT) * m;
            if (t.z * w.z >= 0.0) continue;
            sum += ggx.g1(t, m) * (1.0 - fresnel.reflectance) * rule.weights[i] * rule.weights[j] * 0.25;
        }
    }
    return sum;
}

std::array<float, kRoughTransmittanceResolution> roughTransmittanceTable(double alpha, double eta)
{
    std::array<float, kRoughTransmittanceResolution> table{};
    for (int i = 0; i < kRoughTransmittanceResolution; ++i)
        table[i] = float(roughTransmittance(roughTransmittanceCosine(i), alpha, eta));
    return table;
}

double internalDiffuseReflectance(double alpha, double eta)
{
    checkArguments(alpha, eta);
    double sum = 0.0;
    for (int i = 0; i < kRoughTransmittanceResolution; ++i) {
        double mu = roughTransmittanceCosine(i);
        sum += roughSpecularAlbedo(mu, alpha, 1.0 / eta) * mu;
    }
    return 2.0 * sum / kRoughTransmittanceResolution;
}

double smoothInternalDiffuseReflectance(double eta)
{
    if (!(eta > 0.0 && std::isfinite(eta)))
        throw std::invalid_argument("smoothInternalDiffuseReflectance: eta must be positive, got " + std::to_string(eta));
    double e = 1.0 / eta; // Mitsuba evaluates fresnel_diffuse_reflectance(1 / eta)
    if (e < 1.0) return -1.4399 * e * e + 0.7099 * e + 0.6681 + 0.0636 / e; // Egan & Hilgeman 1973
    double ie = 1.0 / e; // d'Eon & Irving 2011, a quintic in 1 / e
    return 0.919317 + ie * (-3.4793 + ie * (6.75335 + ie * (-7.80989 + ie * (4.98554 - 1.36881 * ie))));
}

double lerpTransmittance(const std::array<float, kRoughTransmittanceResolution>& table, double cosTheta)
{
    double x = cosTheta * (kRoughTransmittanceResolution - 1);
    // Mitsuba converts to an unsigned integer and clamps only from above.
    int index = std::min(int(std::max(0.0, x)), kRoughTransmittanceResolution - 2);
    double w1 = x - index;
    return (1.0 - w1) * table[index] + w1 * table[index + 1];
}

} // namespace vkrt

// The pbr material's KHR_materials_transmission lobe (lib/bsdf.glsl under
// VKRT_PBR_LAYERS and VKRT_PBR_TRANSMISSION) on the test GPU through
// tests/gpu/kernels/bsdf_probe.comp. Everything expected is written here from
// the formulas (glTF's, Walter et al. 2007's, GltfPbrReference.h), not read
// from the GLSL:
//  - a thin-walled white dielectric of transmission 1 keeps the white metal's
//    directional albedo: F + (1 - F) = 1 per microfacet, and the mirrored
//    lobe has the reflection's shadowing (Z test, Sidak-corrected);
//  - a volumetric white one keeps its single-scattering albedo (quadrature
//    over visible normals), entering and leaving;
//  - no layer combination gains energy, and no weight is negative or not finite;
//  - thin-walled transmitted directions are mirrored reflections, volumetric
//    ones refractions about a microfacet normal, each with the weight the
//    lobe defines; the transmitted directions follow their density
//    (chi-square with Walter's Jacobian, Sidak-corrected);
//  - partial transmission takes its share of the diffuse only: evalBsdf equals
//    the reference's specular part plus (1 - transmission) x its diffuse part.
// The two tests past the critical angle found faults of lib/bsdf.glsl, since
// fixed (their comments say what they measured before).
#include "material/Ggx.h"
#include "material/Sheen.h"
#include "shared/SceneTypes.h"
#include "support/ChiSquare.h"
#include "support/GltfPbrReference.h"
#include "support/ProbeKernel.h"
#include "support/TestSupport.h"

#include <glm/glm.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

namespace vkrt::test {
namespace {

constexpr size_t kSheenTableAt = 128;  // bsdf_probe.comp's layout with VKRT_PBR_LAYERS
constexpr size_t kTransmissionAt = 38; // ... and with VKRT_PBR_TRANSMISSION: transmission, pbrFlags

const std::vector<Define> kTransmission{{"VKRT_PBR_LAYERS", "1"},
                                        {"VKRT_PBR_TRANSMISSION", "1"},
                                        {"VKRT_PBR_SHEEN", "1"},
                                        {"VKRT_PBR_CLEARCOAT", "1"}};

/// A transmitting pbr material seen from one side of its surface.
struct TransmissionCase {
    std::string name;
    GltfPbrParams p;
    double transmission = 1.0;
    bool volume = false;    ///< bounds a volume (PBR_FLAG_VOLUME): refracts; else thin-walled
    double eta = 1.0 / 1.5; ///< n_i / n_t of the crossing (a volume's; thin-walled: 1 / ior)
};

glm::dvec3 direction(double cosTheta, double phi)
{
    const double s = std::sqrt(std::max(0.0, 1.0 - cosTheta * cosTheta));
    return {s * std::cos(phi), s * std::sin(phi), cosTheta};
}

double luminance(const glm::dvec3& c) { return glm::dot(c, glm::dvec3(0.2126, 0.7152, 0.0722)); }
double max3(const glm::dvec3& v) { return std::max({v.x, v.y, v.z}); }
double pow5(double x) { return x * x * x * x * x; }
double ggxAlpha(double roughness) { return std::max(roughness * roughness, double(gpu::MIN_GGX_ALPHA)); }
glm::dvec3 mirrored(const glm::dvec3& w) { return {w.x, w.y, -w.z}; }

/// The probe's inputs (mode 0: sample, 1: evaluate).
std::vector<float> probeInput(const TransmissionCase& c, const glm::dvec3& wo, float mode, float seed)
{
    const GltfPbrParams& p = c.p;
    std::vector<float> in(kSheenTableAt, 0.0f);
    const float material[] = {float(p.baseColor.x),
                              float(p.baseColor.y),
                              float(p.baseColor.z),
                              float(gpu::MATERIAL_PBR),
                              float(p.specularColor.x),
                              float(p.specularColor.y),
                              float(p.specularColor.z),
                              0.0f,
                              0.0f,
                              0.0f,
                              0.0f,
                              float(p.ior),
                              0.0f,
                              float(ggxAlpha(p.roughness)),
                              float(ggxAlpha(p.roughness)),
                              float(kSheenTableAt),
                              0.0f,
                              0.0f,
                              0.0f,
                              float(p.metallic)};
    std::copy(std::begin(material), std::end(material), in.begin());
    in[25] = float(wo.x);
    in[26] = float(wo.y);
    in[27] = float(wo.z);
    in[28] = float(c.eta);
    in[29] = mode;
    in[30] = seed;
    const float layers[] = {float(p.sheenColor.x),
                            float(p.sheenColor.y),
                            float(p.sheenColor.z),
                            float(p.sheenRoughness),
                            float(p.specular),
                            float(p.clearcoat),
                            float(ggxAlpha(p.clearcoatRoughness)),
                            float(c.transmission),
                            float(c.volume ? gpu::PBR_FLAG_VOLUME : 0u)};
    std::copy(std::begin(layers), std::end(layers), in.begin() + 31);
    static_assert(31 + 7 == kTransmissionAt);
    const std::vector<float>& table = sheenAlbedoTable();
    in.insert(in.end(), table.begin(), table.end());
    return in;
}

struct Sample {
    glm::dvec3 dir;
    glm::dvec3 weight;
    unsigned flags; // 1 specular, 2 transmitted, 4 none
};

std::vector<Sample> sampleOnGpu(const TransmissionCase& c, const glm::dvec3& wo, uint32_t count, float seed)
{
    const std::vector<float> out =
        runProbe("bsdf_probe", probeInput(c, wo, 0.0f, seed), 8 * size_t(count), count, kTransmission);
    std::vector<Sample> samples(count);
    for (size_t i = 0; i < count; ++i) {
        const float* o = &out[8 * i];
        samples[i] = {{o[0], o[1], o[2]}, {o[3], o[4], o[5]}, unsigned(o[7])};
    }
    return samples;
}

/// evalBsdf (xyz) of the GLSL at each direction.
std::vector<glm::dvec3> evaluateOnGpu(const TransmissionCase& c, const glm::dvec3& wo,
                                      const std::vector<glm::dvec3>& wis)
{
    std::vector<float> in = probeInput(c, wo, 1.0f, 0.0f);
    for (const glm::dvec3& d : wis) in.insert(in.end(), {float(d.x), float(d.y), float(d.z)});
    const auto count = uint32_t(wis.size());
    const std::vector<float> out = runProbe("bsdf_probe", in, 8 * size_t(count), count, kTransmission);
    std::vector<glm::dvec3> result(count);
    for (size_t i = 0; i < count; ++i) result[i] = {out[8 * i], out[8 * i + 1], out[8 * i + 2]};
    return result;
}

// ---------------------------------------------------------------------------
// The lobe's definitions in double precision.

/// The dielectric's Fresnel (KHR_materials_specular, _ior) at cosine c on wo's
/// side of the microfacet: Schlick at the cosine on the lower index's side,
/// 1 past the critical angle.
glm::dvec3 dielectricFresnel(const TransmissionCase& tc, double c)
{
    const double eta = tc.volume ? tc.eta : 1.0 / tc.p.ior;
    c = std::clamp(c, 0.0, 1.0);
    if (eta > 1.0) {
        const double sin2t = eta * eta * (1.0 - c * c);
        if (sin2t >= 1.0) return glm::dvec3(1.0);
        c = std::sqrt(1.0 - sin2t);
    }
    const double r = (1.0 - eta) / (1.0 + eta);
    const glm::dvec3 f0 = glm::min(r * r * tc.p.specularColor, glm::dvec3(1.0)) * tc.p.specular;
    return f0 + (glm::dvec3(tc.p.specular) - f0) * pow5(1.0 - c);
}

double coatWeight(const GltfPbrParams& p, double cosO) { return p.clearcoat * (0.04 + 0.96 * pow5(1.0 - cosO)); }

/// The probabilities of the coat, the base's GGX reflection, the cosine lobe
/// and transmission seen from cosO (cases without sheen).
glm::dvec4 lobeProbabilities(const TransmissionCase& tc, double cosO)
{
    const GltfPbrParams& p = tc.p;
    const double coat = coatWeight(p, cosO);
    const double fd = max3(dielectricFresnel(tc, cosO));
    const double specular = p.metallic + (1.0 - p.metallic) * fd;
    const double below = (1.0 - p.metallic) * luminance(p.baseColor);
    // Transmission keeps a tenth of its share where Fd(cosO) reaches 1 (past
    // the critical angle, leaving a volume), where tilted microfacets still transmit.
    const double transmitted = below * tc.transmission * std::max(1.0 - fd, 0.1);
    // The diffuse weighed by its mean 1 - F(V.H) over its lobe (diffuseMeanHalfCosineFit).
    const double fdDiffuse = std::min(max3(dielectricFresnel(tc, diffuseMeanHalfCosineFit(cosO))), fd);
    const double cosine = below * (1.0 - fdDiffuse) * (1.0 - tc.transmission);
    const double total = specular + cosine + transmitted;
    if (!(total > 0.0)) return {coat, 1.0 - coat, 0.0, 0.0};
    return {coat, (1.0 - coat) * specular / total, (1.0 - coat) * cosine / total, (1.0 - coat) * transmitted / total};
}

/// The microfacet normal a transmitted direction came from: the mirrored
/// reflection's half vector (thin-walled) or the generalized half vector
/// -(n_i wo + n_t wi) (Walter et al. 2007, eq. 16), which points to +z when
/// entering the denser side (eta < 1) and to -z when leaving it: turned to +z.
glm::dvec3 transmissionNormal(const TransmissionCase& tc, const glm::dvec3& wo, const glm::dvec3& wi)
{
    if (!tc.volume) return glm::normalize(wo + mirrored(wi));
    const glm::dvec3 h = -glm::normalize(tc.eta * wo + wi);
    return h.z < 0.0 ? -h : h;
}

/// The sampler's solid-angle density over the sphere (cases without sheen):
/// the reflection lobes above, transmission below, the visible-normal density
/// D_wo(h) times |dh/dwi|: 1 / (4 wo.h) for the mirrored reflection, Walter's
/// n_t^2 |wi.h| / (n_i wo.h + n_t wi.h)^2 = |wi.h| / (eta wo.h + wi.h)^2 (eq. 17)
/// for the refraction.
double samplerPdf(const TransmissionCase& tc, const glm::dvec3& wo, const glm::dvec3& wi)
{
    const glm::dvec4 p = lobeProbabilities(tc, wo.z);
    const Ggx base{ggxAlpha(tc.p.roughness), ggxAlpha(tc.p.roughness)};
    auto reflection = [&](const Ggx& ggx, const glm::dvec3& h) {
        return ggx.visibleNormalPdf(wo, h) / (4.0 * glm::dot(wo, h));
    };
    if (wi.z > 0.0) {
        const glm::dvec3 h = glm::normalize(wo + wi);
        const double a = ggxAlpha(tc.p.clearcoatRoughness);
        return (p.x > 0.0 ? p.x * reflection(Ggx{a, a}, h) : 0.0) + p.y * reflection(base, h) +
               p.z * wi.z / std::numbers::pi;
    }
    if (!(p.w > 0.0)) return 0.0;
    const glm::dvec3 h = transmissionNormal(tc, wo, wi);
    const double cosOH = glm::dot(wo, h), cosIH = glm::dot(wi, h);
    if (!tc.volume) return cosOH > 0.0 ? p.w * reflection(base, h) : 0.0;
    if (cosOH <= 0.0 || cosIH >= 0.0) return 0.0;
    const double denominator = tc.eta * cosOH + cosIH;
    return p.w * base.visibleNormalPdf(wo, h) * std::abs(cosIH) / (denominator * denominator);
}

/// A transmitted sample's weight: tint (1 - metallic) transmission
/// (1 - max3 Fd(wo.h)) (1 - coat) G2(wo, wi) / G1(wo) / p.w (cases without sheen);
/// the tint is baseColor through a thin wall and sqrt(baseColor) at each of a
/// volume's two crossings, so that a closed object tints by baseColor once.
glm::dvec3 transmissionWeight(const TransmissionCase& tc, const glm::dvec3& wo, const glm::dvec3& wi,
                              const glm::dvec3& h)
{
    const Ggx ggx{ggxAlpha(tc.p.roughness), ggxAlpha(tc.p.roughness)};
    const double lambdaO = ggx.lambda(wo), lambdaI = ggx.lambda(-wi);
    const double shadowing = (1.0 + lambdaO) / (1.0 + lambdaO + lambdaI);
    const double layers = (1.0 - tc.p.metallic) * tc.transmission *
                          (1.0 - max3(dielectricFresnel(tc, glm::dot(wo, h)))) * (1.0 - coatWeight(tc.p, wo.z));
    const glm::dvec3 tint = tc.volume ? glm::sqrt(tc.p.baseColor) : tc.p.baseColor;
    return tint * (layers * shadowing / lobeProbabilities(tc, wo.z).w);
}

/// The white metal's (baseColor 1, metallic 1: F = 1) directional albedo from
/// the reference: the integral of f cos over the hemisphere, adaptive Simpson
/// in (sqrt(cosI), phi), wo in the xz plane (so symmetric in phi).
double whiteMetalAlbedo(double roughness, const glm::dvec3& wo)
{
    GltfPbrParams metal;
    metal.roughness = roughness;
    auto integrand = [&](double t, double phi) {
        const double cosI = t * t;
        return gltfPbrEval(metal, wo, direction(cosI, phi)).x * cosI * 2.0 * t;
    };
    return 2.0 * integrate2d(integrand, 0.0, 1.0, 0.0, std::numbers::pi, 16, 1e-7);
}

/// E[value(h)] for h ~ D_wo, by the midpoint rule on the visible-normal sampler's square.
template <typename Value>
double overVisibleNormals(const Ggx& ggx, const glm::dvec3& wo, const Value& value)
{
    const int n = 384;
    double sum = 0.0;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) sum += value(ggx.sampleVisibleNormal(wo, (i + 0.5) / n, (j + 0.5) / n));
    return sum / (double(n) * n);
}

/// A figure for the test's XML report (gtest attribute names: no spaces).
void property(std::string key, double value)
{
    std::replace_if(
        key.begin(), key.end(), [](char c) { return !std::isalnum(static_cast<unsigned char>(c)) && c != '.'; }, '_');
    ::testing::Test::RecordProperty(key, std::to_string(value));
}

/// Upper quantile of the standard normal: z with P(Z > z) = tail (bisection).
double normalQuantile(double tail)
{
    double lo = 0.0, hi = 40.0;
    for (int i = 0; i < 200; ++i) {
        const double mid = 0.5 * (lo + hi);
        (0.5 * std::erfc(mid / std::numbers::sqrt2) > tail ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

struct MeanWeight {
    glm::dvec3 mean{0.0};
    glm::dvec3 standardError{0.0};
    long long nonFinite = 0, negative = 0;
};

MeanWeight meanWeight(const std::vector<Sample>& samples)
{
    MeanWeight r;
    glm::dvec3 sum(0.0), sumSquares(0.0);
    for (const Sample& s : samples) {
        for (int k = 0; k < 3; ++k) {
            if (!std::isfinite(s.weight[k])) ++r.nonFinite;
            else if (s.weight[k] < 0.0) ++r.negative;
        }
        sum += s.weight;
        sumSquares += s.weight * s.weight;
    }
    const double n = double(samples.size());
    r.mean = sum / n;
    r.standardError = glm::sqrt(glm::max(sumSquares / n - r.mean * r.mean, glm::dvec3(0.0)) / n);
    return r;
}

std::string describe(const glm::dvec3& v)
{
    std::ostringstream s;
    s << "(" << v.x << ", " << v.y << ", " << v.z << ")";
    return s.str();
}

TransmissionCase whiteDielectric(const std::string& name, double roughness, bool volume, double eta)
{
    TransmissionCase c{name, {}, 1.0, volume, eta};
    c.p.metallic = 0.0;
    c.p.roughness = roughness;
    return c;
}

class PbrTransmissionProbe : public GpuTest {};

TEST_F(PbrTransmissionProbe, ThinWalledWhiteDielectricKeepsTheWhiteMetalsAlbedo)
{
    constexpr uint32_t kSamples = 1u << 16;
    const std::vector<double> roughnesses{0.3, 0.6, 1.0}, cosines{0.9, 0.5, 0.15};
    const double z = normalQuantile(0.5 * sidakCorrectedAlpha(0.01, int(roughnesses.size() * cosines.size())));
    for (const double roughness : roughnesses)
        for (const double cosO : cosines) {
            const std::string name = "roughness " + std::to_string(roughness) + " cosO " + std::to_string(cosO);
            SCOPED_TRACE(name);
            const glm::dvec3 wo = direction(cosO, 0.0);
            const double expected = whiteMetalAlbedo(roughness, wo);
            // The same albedo the other way: E[G2(wo, wi) / G1(wo)] over visible normals. At
            // roughness 0.3 this midpoint rule converges slowly (measured: 384^2 nodes 1.9e-4
            // from the adaptive Simpson's 0.98942360 at cosO 0.9; 2048^2 nodes 1.5e-5), which
            // agreed with itself to 1e-9 at 8x the panels and 1e-3 of the tolerance.
            const Ggx ggx{ggxAlpha(roughness), ggxAlpha(roughness)};
            const double check = overVisibleNormals(ggx, wo, [&](const glm::dvec3& h) {
                const glm::dvec3 wi = reflect(wo, h);
                return wi.z > 0.0 ? ggx.gCorrelated(wo, wi, h) / ggx.g1(wo, h) : 0.0;
            });
            ASSERT_NEAR(expected, check, 3e-4) << "the two quadratures of the white metal's albedo";
            const TransmissionCase c = whiteDielectric("thin", roughness, false, 1.0 / 1.5);
            const MeanWeight w = meanWeight(sampleOnGpu(c, wo, kSamples, 11.0f));
            const double score = (w.mean.x - expected) / w.standardError.x;
            EXPECT_LT(std::abs(score), z) << "mean " << w.mean.x << " +- " << w.standardError.x << ", expected "
                                          << expected << ", Z " << score << " (bound " << z << ")";
            property("z " + name, score);
        }
}

/// A volumetric white dielectric of transmission 1 (roughness 0.5) keeps the
/// single-scattering albedo of its interface: E over visible normals h of
/// Fd G2(wo, r) / G1(wo) for the reflection r plus (1 - Fd) G2(wo, t) / G1(wo)
/// for the refraction t (Z test, Sidak-corrected over the cosines).
void expectVolumetricAlbedo(const std::string& sideName, double eta, const std::vector<double>& cosines)
{
    constexpr uint32_t kSamples = 1u << 16;
    const double roughness = 0.5;
    const double z = normalQuantile(0.5 * sidakCorrectedAlpha(0.01, int(cosines.size())));
    for (const double cosO : cosines) {
        const std::string name = sideName + " cosO " + std::to_string(cosO);
        SCOPED_TRACE(name);
        const TransmissionCase c = whiteDielectric(sideName, roughness, true, eta);
        const glm::dvec3 wo = direction(cosO, 0.0);
        const Ggx ggx{ggxAlpha(roughness), ggxAlpha(roughness)};
        const double lambdaO = ggx.lambda(wo);
        auto shadowing = [&](const glm::dvec3& wi) { return (1.0 + lambdaO) / (1.0 + lambdaO + ggx.lambda(wi)); };
        const double expected = overVisibleNormals(ggx, wo, [&](const glm::dvec3& h) {
            const double cosOH = glm::dot(wo, h), f = dielectricFresnel(c, cosOH).x;
            const glm::dvec3 r = reflect(wo, h);
            double value = r.z > 0.0 ? f * shadowing(r) : 0.0;
            const double cos2t = 1.0 - eta * eta * (1.0 - cosOH * cosOH);
            if (cos2t > 0.0) {
                const glm::dvec3 t = -eta * wo + (eta * cosOH - std::sqrt(cos2t)) * h;
                if (t.z < 0.0) value += (1.0 - f) * shadowing(t);
            }
            return value;
        });
        const MeanWeight w = meanWeight(sampleOnGpu(c, wo, kSamples, 13.0f));
        const double score = (w.mean.x - expected) / w.standardError.x;
        EXPECT_LE(expected, 1.0);
        EXPECT_LT(std::abs(score), z) << "mean " << w.mean.x << " +- " << w.standardError.x << ", expected " << expected
                                      << ", Z " << score << " (bound " << z << ")";
        property("z " + name, score);
    }
}

TEST_F(PbrTransmissionProbe, VolumetricWhiteDielectricKeepsItsSingleScatteringAlbedo)
{
    expectVolumetricAlbedo("entering", 1.0 / 1.5, {0.9, 0.78, 0.3});
    expectVolumetricAlbedo("leaving", 1.5, {0.9, 0.78}); // below the critical angle (cosine 0.745)
}

// Found a bug of lib/bsdf.glsl, fixed (transmission now keeps a tenth of its
// sampling share there): leaving the volume past the critical angle (cosO < 0.745 at eta 1.5), pbrLobeProbabilities
// takes the Fresnel at the macro-surface's cosine, which is 1 there, so the
// transmission lobe gets probability 0; yet microfacets tilted towards wo do not
// reflect totally and should transmit. Measured (2^16 samples): cosO 0.5 mean
// 0.7245 +- 0.0015, expected 0.8271, Z -70; cosO 0.3 mean 0.7473 +- 0.0014,
// expected 0.7972, Z -36 (the means are the reflection's share alone).
TEST_F(PbrTransmissionProbe, VolumetricWhiteDielectricLeavingPastTheCriticalAngleStillTransmits)
{
    expectVolumetricAlbedo("leaving", 1.5, {0.5, 0.3});
}

/// Layer sets on a white base that could gain energy if a share were counted twice.
std::vector<TransmissionCase> energyCases()
{
    std::vector<TransmissionCase> layers;
    layers.push_back(whiteDielectric("smooth", 0.2, false, 0.0));
    layers.push_back(whiteDielectric("transmission 0.5", 0.5, false, 0.0));
    layers.back().transmission = 0.5;
    layers.push_back(whiteDielectric("sheen", 0.5, false, 0.0));
    layers.back().p.sheenColor = glm::dvec3(1.0);
    layers.back().p.sheenRoughness = 0.5;
    layers.push_back(whiteDielectric("clearcoat", 0.5, false, 0.0));
    layers.back().p.clearcoat = 1.0;
    layers.back().p.clearcoatRoughness = 0.3;
    layers.push_back(whiteDielectric("specular colour", 0.5, false, 0.0));
    layers.back().p.specularColor = {1.6, 0.5, 1.0};
    layers.back().p.specular = 1.0;
    layers.push_back(whiteDielectric("every layer", 1.0, false, 0.0));
    TransmissionCase& every = layers.back();
    every.transmission = 0.7;
    every.p.sheenColor = {1.0, 0.6, 0.8};
    every.p.sheenRoughness = 0.6;
    every.p.clearcoat = 0.8;
    every.p.clearcoatRoughness = 0.4;
    every.p.specularColor = {0.5, 1.0, 2.0};
    every.p.ior = 1.4;
    std::vector<TransmissionCase> cases;
    for (const TransmissionCase& l : layers) {
        cases.push_back(l);
        cases.back().name += ", thin";
        cases.back().eta = 1.0 / l.p.ior;
        cases.push_back(l);
        cases.back().name += ", entering";
        cases.back().volume = true;
        cases.back().eta = 1.0 / l.p.ior;
        cases.push_back(l);
        cases.back().name += ", leaving";
        cases.back().volume = true;
        cases.back().eta = l.p.ior;
    }
    return cases;
}

/// The mean weight of each case at each cosine is at most 1 (one-sided Z test,
/// Sidak-corrected over cases, cosines and channels); no weight is negative or
/// not finite.
void expectNoGain(const std::vector<TransmissionCase>& cases, const std::vector<double>& cosines)
{
    constexpr uint32_t kSamples = 1u << 15;
    const double z = normalQuantile(sidakCorrectedAlpha(0.01, int(3 * cases.size() * cosines.size())));
    for (const TransmissionCase& c : cases)
        for (const double cosO : cosines) {
            SCOPED_TRACE(c.name + " cosO " + std::to_string(cosO));
            const MeanWeight w = meanWeight(sampleOnGpu(c, direction(cosO, 0.7), kSamples, 17.0f));
            EXPECT_EQ(w.nonFinite, 0);
            EXPECT_EQ(w.negative, 0);
            for (int k = 0; k < 3; ++k)
                EXPECT_LE(w.mean[k], 1.0 + z * w.standardError[k] + 1e-6)
                    << "gains energy: channel " << k << " mean " << describe(w.mean) << " +- "
                    << describe(w.standardError);
            property("mean " + c.name + " cosO " + std::to_string(cosO), max3(w.mean));
        }
}

std::vector<TransmissionCase> energyCasesOn(bool leaving)
{
    std::vector<TransmissionCase> cases;
    for (const TransmissionCase& c : energyCases())
        if (c.volume && c.eta > 1.0 ? leaving : !leaving) cases.push_back(c);
    return cases;
}

TEST_F(PbrTransmissionProbe, NoLayerCombinationGainsEnergyOrGivesABadWeight)
{
    expectNoGain(energyCasesOn(false), {0.3}); // grazing: the largest Fresnel
    expectNoGain(energyCasesOn(true), {0.8});  // below the critical angle (cosine 0.745)
}

// Found a gain, fixed (inside a volume the diffuse also loses Fd(cosO):
// lib/bsdf.glsl pbrDiffuseFresnel): leaving past the critical angle with
// transmission 0.5, the reflection side's own f integrates to more than 1: the
// specification's fresnel_mix gives the diffuse 1 - Fd(wo.h) per direction (the
// gain GltfPbrReference.h notes for a white dielectric at grazing view), and
// inside the volume Fd's total internal reflection makes the specular keep much
// (0.746) while the diffuse half keeps 0.266 (quadrature, roughness 0.5, cosO
// 0.3: 1.012). Measured: mean 1.016 +- 0.004. The sampler is not at fault
// there; transmission, which that sampler then never picks (see above), would
// add 0.025 more.
TEST_F(PbrTransmissionProbe, NoLayerCombinationGainsEnergyLeavingPastTheCriticalAngle)
{
    expectNoGain(energyCasesOn(true), {0.3});
}

/// Geometry and sampling cases without sheen (its table is the GPU's alone).
std::vector<std::pair<TransmissionCase, double>> directionCases()
{
    TransmissionCase layered{
        "grey, coat, specular colour, metallic 0.2, transmission 0.6, entering", {}, 0.6, true, 1.0 / 1.4};
    layered.p.baseColor = {0.8, 0.5, 0.2};
    layered.p.metallic = 0.2;
    layered.p.roughness = 0.7;
    layered.p.ior = 1.4;
    layered.p.specularColor = {0.5, 1.0, 2.0};
    layered.p.specular = 0.8;
    layered.p.clearcoat = 0.7;
    layered.p.clearcoatRoughness = 0.3;
    return {{whiteDielectric("thin roughness 0.6", 0.6, false, 1.0 / 1.5), 0.5},
            {whiteDielectric("thin roughness 0.3", 0.3, false, 1.0 / 1.5), 0.2},
            {whiteDielectric("entering roughness 0.5", 0.5, true, 1.0 / 1.5), 0.8},
            {whiteDielectric("entering roughness 0.3", 0.3, true, 1.0 / 1.5), 0.3},
            {whiteDielectric("leaving roughness 0.5", 0.5, true, 1.5), 0.9},
            {layered, 0.6}};
}

TEST_F(PbrTransmissionProbe, TransmittedSamplesAreMirrorsOrRefractionsWithTheirWeights)
{
    constexpr uint32_t kSamples = 1u << 14;
    for (const auto& [tc, cosO] : directionCases()) {
        const TransmissionCase& c = tc;
        SCOPED_TRACE(c.name + " cosO " + std::to_string(cosO));
        const glm::dvec3 wo = direction(cosO, 0.4);
        long long transmitted = 0, wrongGeometry = 0, wrongWeight = 0;
        double worstWeight = 0.0;
        std::string firstWrong;
        for (const Sample& s : sampleOnGpu(c, wo, kSamples, 19.0f)) {
            if (!(s.flags & 2u) || (s.flags & 4u)) continue;
            ++transmitted;
            const glm::dvec3 wi = s.dir;
            const glm::dvec3 h = transmissionNormal(c, wo, wi);
            // Thin: wi mirrored is a reflection above the surface about a normal wo sees.
            // Volume: the generalized half vector points to +z entering, -z leaving (before
            // transmissionNormal turns it), and wo, wi lie on either side of it.
            const double orientation = c.volume ? -(c.eta * wo + wi).z * (c.eta < 1.0 ? 1.0 : -1.0) : 1.0;
            const bool geometry = s.flags == 3u && std::abs(glm::length(wi) - 1.0) < 1e-5 && wi.z < 0.0 && h.z > 0.0 &&
                                  glm::dot(wo, h) > 0.0 && orientation > 0.0 &&
                                  (c.volume ? glm::dot(wi, h) < 0.0 : glm::dot(mirrored(wi), h) > 0.0);
            const glm::dvec3 expected = transmissionWeight(c, wo, wi, h);
            const double error = glm::length(s.weight - expected) / glm::length(expected);
            worstWeight = std::max(worstWeight, error);
            if (!geometry) ++wrongGeometry;
            if (!(error < 1e-3)) ++wrongWeight;
            if ((!geometry || !(error < 1e-3)) && firstWrong.empty())
                firstWrong = "wi " + describe(wi) + " h " + describe(h) + " weight " + describe(s.weight) +
                             " expected " + describe(expected) + " flags " + std::to_string(s.flags);
        }
        EXPECT_GT(transmitted, kSamples / 10);
        EXPECT_EQ(wrongGeometry, 0) << firstWrong;
        EXPECT_EQ(wrongWeight, 0) << "worst relative error " << worstWeight << "; first: " << firstWrong;
        property("worst weight error " + c.name, worstWeight);
    }
}

TEST_F(PbrTransmissionProbe, DirectionsFollowTheirDensityChiSquare)
{
    constexpr uint32_t kSamples = 1u << 17;
    const auto cases = directionCases();
    const double alpha = sidakCorrectedAlpha(0.01, int(cases.size()));
    ChiSquareOptions options;
    options.thetaBins = 16;
    options.subCells = 2;
    options.countTolerance = 0.1;
    for (const auto& [tc, cosO] : cases) {
        const TransmissionCase& c = tc;
        SCOPED_TRACE(c.name + " cosO " + std::to_string(cosO));
        const glm::dvec3 wo = direction(cosO, 0.0);
        std::vector<glm::dvec3> directions;
        long long none = 0;
        for (const Sample& s : sampleOnGpu(c, wo, kSamples, 23.0f)) {
            if (s.flags & 4u) ++none;
            else directions.push_back(s.dir);
        }
        const ChiSquareResult result = chiSquareTest(
            directions, none, [&](const glm::dvec3& w) { return samplerPdf(c, wo, w); }, options);
        EXPECT_TRUE(result.passes(alpha)) << "p = " << result.pValue << " (alpha " << alpha << ")\n" << result.table;
        property("p " + c.name, result.pValue);
    }
}

TEST_F(PbrTransmissionProbe, PartialTransmissionTakesItsShareOfTheDiffuseOnly)
{
    TransmissionCase grey{"grey", {}, 0.5, false, 1.0 / 1.5};
    grey.p.baseColor = glm::dvec3(0.5);
    grey.p.metallic = 0.0;
    grey.p.roughness = 0.5;
    TransmissionCase layered = grey;
    layered.p.baseColor = {0.6, 0.4, 0.3};
    layered.p.ior = 1.4;
    layered.p.specular = 0.8;
    layered.p.specularColor = {0.5, 1.0, 2.0};
    layered.p.clearcoat = 0.6;
    layered.p.clearcoatRoughness = 0.3;
    std::vector<TransmissionCase> cases;
    for (const TransmissionCase& c : {grey, layered})
        for (const bool volume : {false, true}) {
            cases.push_back(c);
            cases.back().name += volume ? ", entering a volume" : ", thin";
            cases.back().volume = volume;
            cases.back().eta = 1.0 / c.p.ior;
        }
    for (const TransmissionCase& c : cases) {
        SCOPED_TRACE(c.name);
        GltfPbrParams black = c.p; // the specular part alone: metallic 0, no diffuse
        black.baseColor = glm::dvec3(0.0);
        for (const double cosO : {0.95, 0.6, 0.15}) {
            const glm::dvec3 wo = direction(cosO, 0.3);
            std::vector<glm::dvec3> wis;
            for (const double cosI : {0.9, 0.7, 0.45, 0.2, 0.08})
                for (int k = 0; k < 8; ++k) wis.push_back(direction(cosI, 2.0 * std::numbers::pi * k / 8.0 + 0.1));
            const std::vector<glm::dvec3> gpu = evaluateOnGpu(c, wo, wis);
            for (size_t i = 0; i < wis.size(); ++i) {
                const glm::dvec3 specular = gltfPbrEval(black, wo, wis[i]);
                const glm::dvec3 diffuse = gltfPbrEval(c.p, wo, wis[i]) - specular;
                ASSERT_GT(diffuse.x, 1e-3) << "the diffuse part must matter";
                const glm::dvec3 expected = specular + (1.0 - c.transmission) * diffuse;
                for (int k = 0; k < 3; ++k)
                    EXPECT_NEAR(gpu[i][k], expected[k], 1e-4 * std::abs(expected[k]) + 1e-7)
                        << "cosO " << cosO << " wi " << describe(wis[i]) << " channel " << k;
            }
        }
    }
}

} // namespace
} // namespace vkrt::test

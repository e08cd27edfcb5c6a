// The microfacet BSDFs of shaders/lib/bsdf.glsl (conductor, rough_dielectric,
// plastic, pbr) run on the test GPU through tests/gpu/kernels/bsdf_probe.comp:
//  - chi-square tests of the GLSL samplers against their densities computed
//    here in double precision from src/material (Ggx, Fresnel, the coating
//    tables), at several roughnesses and angles including grazing, with a
//    Sidak correction over all cases at alpha = 0.01 (Mitsuba's and pbrt's
//    practice), and a check that a density with a 10 % wrong alpha is
//    rejected (the test can fail);
//  - the GLSL pdf and the sample weights agree with eval * cos / pdf;
//  - white furnace: a conductor and a glTF (pbr) metal with F = 1 and a lossless rough dielectric
//    keep exactly the single-scattering albedo computed by quadrature here,
//    never more than 1; no NaN anywhere, including alpha = 1e-4 and grazing.
#include "material/Fresnel.h"
#include "material/Ggx.h"
#include "material/MicrofacetAlbedo.h"
#include "shared/SceneTypes.h"
#include "support/ChiSquare.h"
#include "support/GltfPbrReference.h"
#include "support/ProbeKernel.h"
#include "support/TestSupport.h"

#include <glm/glm.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

namespace vkrt::test {
namespace {

constexpr uint32_t kSamples = 1u << 18;
constexpr size_t kTableAt = 64; // where the probe finds a rough plastic's table (bsdf_probe.comp)

struct ProbeCase {
    std::string name;
    gpu::Material m{};
    double cosO = 1.0;
    double eta = 1.0;         ///< n_i / n_t, rough dielectric only
    std::vector<float> table; ///< rough plastic only
};

glm::dvec3 woOf(double cosO) { return {std::sqrt(std::max(0.0, 1.0 - cosO * cosO)), 0.0, cosO}; }

std::vector<float> probeInput(const ProbeCase& c, float mode, float seed)
{
    const gpu::Material& m = c.m;
    std::vector<float> in = {m.diffuse.x,
                             m.diffuse.y,
                             m.diffuse.z,
                             float(m.type),
                             m.specular.x,
                             m.specular.y,
                             m.specular.z,
                             m.exponent,
                             m.absorption.x,
                             m.absorption.y,
                             m.absorption.z,
                             m.ior,
                             float(m.fresnel),
                             m.alphaX,
                             m.alphaY,
                             m.table == gpu::NO_MATERIAL_TABLE ? -1.0f : float(m.table),
                             m.eta.x,
                             m.eta.y,
                             m.eta.z,
                             m.metallic,
                             m.k.x,
                             m.k.y,
                             m.k.z,
                             m.lobeWeight,
                             m.internalReflectance};
    const glm::dvec3 wo = woOf(c.cosO);
    in.insert(in.end(), {float(wo.x), float(wo.y), float(wo.z), float(c.eta), mode, seed});
    in.resize(kTableAt, 0.0f);
    in.insert(in.end(), c.table.begin(), c.table.end());
    in.resize(128, 0.0f);
    return in;
}

struct Sample {
    glm::vec3 dir;
    glm::vec3 weight;
    float pdf;
    unsigned flags; // 1 specular, 2 transmitted, 4 none
};

std::vector<Sample> sampleOnGpu(const ProbeCase& c, uint32_t count, float seed = 1.0f)
{
    const std::vector<float> out = runProbe("bsdf_probe", probeInput(c, 0.0f, seed), 8 * size_t(count), count);
    std::vector<Sample> samples(count);
    for (size_t i = 0; i < count; ++i) {
        const float* o = &out[8 * i];
        samples[i] = {{o[0], o[1], o[2]}, {o[3], o[4], o[5]}, o[6], unsigned(o[7])};
    }
    return samples;
}

/// evalBsdf and pdfBsdf of the GLSL at the given directions.
std::vector<glm::vec4> evaluateOnGpu(const ProbeCase& c, const std::vector<glm::vec3>& directions)
{
    std::vector<float> in = probeInput(c, 1.0f, 0.0f);
    for (const glm::vec3& d : directions) in.insert(in.end(), {d.x, d.y, d.z});
    const auto count = uint32_t(directions.size());
    const std::vector<float> out = runProbe("bsdf_probe", in, 8 * size_t(count), count);
    std::vector<glm::vec4> result(count);
    for (size_t i = 0; i < count; ++i) result[i] = {out[8 * i], out[8 * i + 1], out[8 * i + 2], out[8 * i + 3]};
    return result;
}

// ---------------------------------------------------------------------------
// Materials and their sampling densities in double precision.

gpu::Material conductor(double alphaX, double alphaY)
{
    gpu::Material m{};
    m.type = gpu::MATERIAL_CONDUCTOR;
    m.specular = glm::vec3(1.0f);
    m.alphaX = float(alphaX);
    m.alphaY = float(alphaY);
    m.eta = {0.2f, 0.9f, 1.1f};
    m.k = {3.9f, 2.4f, 2.1f};
    m.table = gpu::NO_MATERIAL_TABLE;
    return m;
}

gpu::Material roughDielectric(double alpha)
{
    gpu::Material m{};
    m.type = gpu::MATERIAL_ROUGH_DIELECTRIC;
    m.ior = 1.5f;
    m.fresnel = gpu::FRESNEL_EXACT;
    m.alphaX = m.alphaY = float(alpha);
    m.table = gpu::NO_MATERIAL_TABLE;
    return m;
}

ProbeCase plastic(const std::string& name, double alpha, double cosO)
{
    ProbeCase c{name, {}, cosO, 1.0, {}};
    gpu::Material& m = c.m;
    m.type = gpu::MATERIAL_PLASTIC;
    m.diffuse = {0.5f, 0.3f, 0.2f};
    m.ior = 1.5f;
    m.alphaX = m.alphaY = float(alpha);
    m.lobeWeight = float(1.0 / (1.0 + (0.5 + 0.3 + 0.2) / 3.0));
    if (alpha > 0.0) {
        const auto table = roughTransmittanceTable(alpha, 1.5);
        c.table.assign(table.begin(), table.end());
        m.table = uint32_t(kTableAt);
        m.internalReflectance = float(internalDiffuseReflectance(alpha, 1.5));
    } else {
        m.table = gpu::NO_MATERIAL_TABLE;
        m.internalReflectance = float(smoothInternalDiffuseReflectance(1.5));
    }
    return c;
}

gpu::Material pbr(double alpha, double metallic)
{
    gpu::Material m{};
    m.type = gpu::MATERIAL_PBR;
    m.diffuse = {0.8f, 0.5f, 0.2f};
    m.metallic = float(metallic);
    m.alphaX = m.alphaY = float(alpha);
    m.table = gpu::NO_MATERIAL_TABLE;
    return m;
}

double luminance(const glm::vec3& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

/// Dielectric reflectance for a ray at cosine c > 0 on the side of n_i; eta = n_i / n_t.
double fresnelFromOutside(double c, double eta) { return fresnelDielectric(c, 1.0 / eta).reflectance; }

/// The coating's transmittance as the GLSL computes it: the table, or 1 - F for a smooth coating.
double coatingTransmittance(const ProbeCase& c, double mu)
{
    if (c.table.empty()) return 1.0 - fresnelFromOutside(mu, 1.0 / c.m.ior);
    std::array<float, kRoughTransmittanceResolution> table{};
    std::copy(c.table.begin(), c.table.end(), table.begin());
    return lerpTransmittance(table, mu);
}

/// Probability of the coating's lobe (Mitsuba's rule).
double coatingProbability(const ProbeCase& c, double cosO)
{
    const double t = coatingTransmittance(c, cosO);
    const double s = (1.0 - t) * c.m.lobeWeight, d = t * (1.0 - c.m.lobeWeight);
    return s + d > 0.0 ? s / (s + d) : 0.0;
}

double schlickDielectric(double c) { return 0.04 + 0.96 * std::pow(1.0 - std::clamp(c, 0.0, 1.0), 5.0); }

double pbrSpecularProbability(const gpu::Material& m, double cosO)
{
    const double specular = m.metallic + (1.0 - m.metallic) * schlickDielectric(cosO);
    const double fsDiffuse = std::min(schlickDielectric(diffuseMeanHalfCosineFit(cosO)), schlickDielectric(cosO));
    const double diffuse = (1.0 - m.metallic) * (1.0 - fsDiffuse) * luminance(m.diffuse);
    return diffuse > 0.0 ? specular / (specular + diffuse) : 1.0;
}

/// The mean of (1 - V.H)^5 over cosine-distributed directions wi, by the
/// midpoint rule on the cosine sampler's square (V.H = sqrt((1 + wo.wi) / 2)).
double meanSchlickWeightOverCosineLobe(double cosO)
{
    const glm::dvec3 wo = woOf(cosO);
    const int n = 400;
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
            const double r = std::sqrt((i + 0.5) / n), phi = 2.0 * std::numbers::pi * (j + 0.5) / n;
            const glm::dvec3 wi(r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0, 1.0 - r * r)));
            const double vh = std::sqrt(std::clamp((1.0 + glm::dot(wo, wi)) / 2.0, 0.0, 1.0));
            sum += std::pow(1.0 - vh, 5.0);
        }
    }
    return sum / (double(n) * n);
}

/// The density of the GLSL sampler's directions (continuous part), written
/// independently from the definitions of docs/scene-format.md; alphaScale
/// perturbs alpha for the power check.
double samplerPdf(const ProbeCase& c, const glm::dvec3& wi, double alphaScale = 1.0)
{
    const glm::dvec3 wo = woOf(c.cosO);
    const Ggx ggx{c.m.alphaX * alphaScale, c.m.alphaY * alphaScale};
    auto reflectionPdf = [&](const glm::dvec3& h) { return ggx.visibleNormalPdf(wo, h) / (4.0 * glm::dot(wo, h)); };
    const double cosine = wi.z > 0.0 ? wi.z / std::numbers::pi : 0.0;
    switch (c.m.type) {
    case gpu::MATERIAL_CONDUCTOR: return wi.z > 0.0 ? reflectionPdf(glm::normalize(wo + wi)) : 0.0;
    case gpu::MATERIAL_ROUGH_DIELECTRIC: {
        if (wi.z > 0.0) {
            const glm::dvec3 h = glm::normalize(wo + wi);
            return fresnelFromOutside(glm::dot(wo, h), c.eta) * reflectionPdf(h);
        }
        glm::dvec3 h = glm::normalize(c.eta * wo + wi);
        if (h.z < 0.0) h = -h;
        const double cosOH = glm::dot(wo, h), cosIH = glm::dot(wi, h);
        if (cosOH <= 0.0 || cosIH >= 0.0) return 0.0;
        const double denominator = c.eta * cosOH + cosIH;
        return (1.0 - fresnelFromOutside(cosOH, c.eta)) * ggx.visibleNormalPdf(wo, h) * std::abs(cosIH) /
               (denominator * denominator);
    }
    case gpu::MATERIAL_PLASTIC: {
        const double ps = coatingProbability(c, c.cosO);
        const double lobe = c.table.empty() || wi.z <= 0.0 ? 0.0 : reflectionPdf(glm::normalize(wo + wi));
        return ps * lobe + (1.0 - ps) * cosine;
    }
    case gpu::MATERIAL_PBR: {
        const double ps = pbrSpecularProbability(c.m, c.cosO);
        const double lobe = wi.z <= 0.0 ? 0.0 : reflectionPdf(glm::normalize(wo + wi));
        return ps * lobe + (1.0 - ps) * cosine;
    }
    default: return 0.0;
    }
}

std::vector<ProbeCase> samplingCases()
{
    std::vector<ProbeCase> cases;
    for (const double roughness : {0.3, 1.0}) {
        const double a = roughness * roughness;
        for (const double cosO : {1.0, 0.3, 0.05}) {
            const std::string at =
                " roughness " + std::to_string(roughness).substr(0, 3) + " cosO " + std::to_string(cosO).substr(0, 3);
            cases.push_back({"conductor" + at, conductor(a, a), cosO, 1.0, {}});
            cases.push_back({"rough_dielectric entering" + at, roughDielectric(a), cosO, 1.0 / 1.5, {}});
            cases.push_back({"rough_dielectric leaving" + at, roughDielectric(a), cosO, 1.5, {}});
            cases.push_back(plastic("plastic" + at, a, cosO));
            cases.push_back({"pbr metallic 0.3" + at, pbr(a, 0.3), cosO, 1.0, {}});
        }
    }
    cases.push_back({"conductor anisotropic", conductor(0.05, 0.4), 0.6, 1.0, {}});
    cases.push_back(plastic("plastic smooth", 0.0, 0.7));
    return cases;
}

class MicrofacetProbe : public GpuTest {};

/// Mitsuba's resolution (10 x 20 cells); each cell's expected count to 0.1 samples,
/// a fraction of a sample at 2^18 samples.
ChiSquareOptions fastOptions()
{
    ChiSquareOptions options;
    options.thetaBins = 10;
    options.subCells = 2;
    options.countTolerance = 0.1;
    return options;
}

/// Directions of the continuous part, and the count of the rest (delta lobes, no sample).
struct Split {
    std::vector<glm::vec3> directions;
    long long other = 0;
};

Split splitSamples(const std::vector<Sample>& samples, bool deltaIsOther)
{
    Split split;
    for (const Sample& s : samples) {
        if ((s.flags & 4u) || (deltaIsOther && (s.flags & 1u) && !(s.flags & 2u))) {
            ++split.other;
        } else {
            split.directions.push_back(s.dir);
        }
    }
    return split;
}

/// Chi-square of every sampling case of one material kind; Sidak over all cases of all kinds.
void expectSamplersMatchTheirDensities(uint32_t type)
{
    const std::vector<ProbeCase> cases = samplingCases();
    const double alpha = sidakCorrectedAlpha(0.01, int(cases.size()));
    int tested = 0;
    for (const ProbeCase& c : cases) {
        if (c.m.type != type) continue;
        ++tested;
        SCOPED_TRACE(c.name);
        const std::vector<Sample> samples = sampleOnGpu(c, kSamples);
        // The smooth coating's mirror reflection is a delta: counted with the draws that gave no direction.
        const Split split = splitSamples(samples, c.m.type == gpu::MATERIAL_PLASTIC && c.table.empty());
        const ChiSquareResult result = chiSquareTest(
            split.directions, split.other, [&](const glm::dvec3& w) { return samplerPdf(c, w); }, fastOptions());
        EXPECT_TRUE(result.passes(alpha)) << "p = " << result.pValue << " (alpha " << alpha << ")\n" << result.table;
    }
    EXPECT_GT(tested, 0);
}

// One test per kind, so that ctest runs them side by side.
TEST_F(MicrofacetProbe, ConductorSamplerMatchesItsDensityChiSquare)
{
    expectSamplersMatchTheirDensities(gpu::MATERIAL_CONDUCTOR);
}
TEST_F(MicrofacetProbe, RoughDielectricSamplerMatchesItsDensityChiSquare)
{
    expectSamplersMatchTheirDensities(gpu::MATERIAL_ROUGH_DIELECTRIC);
}
TEST_F(MicrofacetProbe, PlasticSamplerMatchesItsDensityChiSquare)
{
    expectSamplersMatchTheirDensities(gpu::MATERIAL_PLASTIC);
}
TEST_F(MicrofacetProbe, PbrSamplerMatchesItsDensityChiSquare) { expectSamplersMatchTheirDensities(gpu::MATERIAL_PBR); }

TEST_F(MicrofacetProbe, ChiSquareRejectsADensityWithAlphaTenPercentOff)
{
    // The power check: the same samples against a density of alpha * 1.1.
    for (const ProbeCase& c : {ProbeCase{"conductor", conductor(0.25, 0.25), 0.5, 1.0, {}},
                               ProbeCase{"rough_dielectric", roughDielectric(0.25), 0.5, 1.0 / 1.5, {}}}) {
        SCOPED_TRACE(c.name);
        const Split split = splitSamples(sampleOnGpu(c, kSamples), false);
        const ChiSquareResult wrong = chiSquareTest(
            split.directions, split.other, [&](const glm::dvec3& w) { return samplerPdf(c, w, 1.1); }, fastOptions());
        EXPECT_LT(wrong.pValue, 1e-6);
    }
}

TEST_F(MicrofacetProbe, PdfAndWeightsAgreeWithEvalAndTheReferenceDensity)
{
    for (const ProbeCase& c : samplingCases()) {
        SCOPED_TRACE(c.name);
        const std::vector<Sample> samples = sampleOnGpu(c, 4096, 3.0f);
        std::vector<glm::vec3> reflected;
        std::vector<const Sample*> which;
        for (const Sample& s : samples) {
            for (int ch = 0; ch < 3; ++ch) ASSERT_TRUE(std::isfinite(s.weight[ch])) << "non-finite weight";
            if (s.flags != 0u) continue; // delta, transmitted or none: no pdf to compare
            reflected.push_back(s.dir);
            which.push_back(&s);
        }
        ASSERT_FALSE(reflected.empty());
        const std::vector<glm::vec4> evaluated = evaluateOnGpu(c, reflected);
        double worstPdf = 0.0, worstWeight = 0.0;
        for (size_t i = 0; i < reflected.size(); ++i) {
            const double reference = samplerPdf(c, glm::dvec3(reflected[i]));
            const double pdf = evaluated[i].w;
            if (reference > 1e-3) worstPdf = std::max(worstPdf, std::abs(pdf - reference) / reference);
            // weight == f cos / pdf for every non-delta sample
            for (int ch = 0; ch < 3; ++ch) {
                const double expected = evaluated[i][ch] * reflected[i].z / pdf;
                const double error = std::abs(which[i]->weight[ch] - expected) / std::max(1.0, std::abs(expected));
                worstWeight = std::max(worstWeight, error);
            }
            EXPECT_NEAR(which[i]->pdf, pdf, 1e-5 * std::max(1.0, pdf));
        }
        EXPECT_LT(worstPdf, 2e-3) << "GLSL pdf vs double-precision density";
        EXPECT_LT(worstWeight, 2e-3) << "sample weight vs eval * cos / pdf";
    }
}

TEST(PbrLobeChoice, TheDiffusesMeanHalfCosineFitIsWithinItsStatedError)
{
    for (int k = 0; k <= 20; ++k) {
        const double cosO = k / 20.0;
        const double exact = 1.0 - std::pow(meanSchlickWeightOverCosineLobe(cosO), 0.2);
        EXPECT_NEAR(diffuseMeanHalfCosineFit(cosO), exact, 0.015) << "cosO " << cosO;
    }
}

// A smooth pink dielectric seen at grazing: its sample weights (red) vary
// little, because the diffuse lobe is chosen as often as its mean weight
// says. With the specular probability from F(N.V) alone (before), the
// variance was 0.22 at N.V = 0.15 and 2.2 at 0.05 (NumPy model of the same
// sampler; docs/performance.md).
TEST_F(MicrofacetProbe, ASmoothDielectricSeenAtGrazingHasSteadyWeights)
{
    for (const double cosO : {0.3, 0.15, 0.05}) {
        gpu::Material m = pbr(gpu::MIN_GGX_ALPHA, 0.0);
        m.diffuse = {0.95f, 0.8f, 0.75f};
        const ProbeCase c{"smooth pbr cosO " + std::to_string(cosO), m, cosO, 1.0, {}};
        const std::vector<Sample> samples = sampleOnGpu(c, 1u << 16, 5.0f);
        double sum = 0.0, sumSquares = 0.0;
        for (const Sample& s : samples) {
            sum += s.weight.x;
            sumSquares += double(s.weight.x) * s.weight.x;
        }
        const double mean = sum / samples.size(), variance = sumSquares / samples.size() - mean * mean;
        EXPECT_LT(variance, 0.05) << c.name << ": mean weight " << mean;
    }
}

/// Single-scattering albedo by quadrature over visible normals (64 x 64
/// Gauss-Legendre nodes on the sampler's square): E[value(m)] for m ~ D_wo.
template <typename Value>
double quadratureOverVisibleNormals(const Ggx& ggx, const glm::dvec3& wo, const Value& value)
{
    // Nodes from the midpoint rule refined 4x: smooth integrand, plenty for 1e-4.
    const int n = 256;
    double sum = 0.0;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) sum += value(ggx.sampleVisibleNormal(wo, (i + 0.5) / n, (j + 0.5) / n));
    return sum / (double(n) * n);
}

TEST_F(MicrofacetProbe, WhiteFurnaceLosesOnlyWhatSingleScatteringLoses)
{
    for (const double roughness : {0.1, 0.5, 1.0}) {
        const double a = roughness * roughness;
        for (const double cosO : {1.0, 0.5, 0.05}) {
            const glm::dvec3 wo = woOf(cosO);
            const Ggx ggx{a, a};
            // Conductor with F = 1 (eta 0, k 1): E[G1(wi, m)] over reflections above the surface.
            ProbeCase metal{"conductor F=1", conductor(a, a), cosO, 1.0, {}};
            metal.m.eta = glm::vec3(0.0f);
            metal.m.k = glm::vec3(1.0f);
            const double metalAlbedo = quadratureOverVisibleNormals(ggx, wo, [&](const glm::dvec3& m) {
                const glm::dvec3 wi = reflect(wo, m);
                return wi.z > 0.0 ? ggx.g1(wi, m) : 0.0;
            });
            // Lossless rough glass entering at ior 1.5: reflection and transmission together.
            ProbeCase glass{"rough_dielectric", roughDielectric(a), cosO, 1.0 / 1.5, {}};
            const double glassAlbedo = quadratureOverVisibleNormals(ggx, wo, [&](const glm::dvec3& m) {
                const double c = glm::dot(wo, m);
                const DielectricFresnel f = fresnelDielectric(c, 1.5);
                const glm::dvec3 r = reflect(wo, m);
                const glm::dvec3 t = -f.etaTI * wo + (f.etaTI * c - f.cosT) * m;
                double value = r.z > 0.0 ? f.reflectance * ggx.g1(r, m) : 0.0;
                if (f.reflectance < 1.0 && t.z < 0.0) value += (1.0 - f.reflectance) * ggx.g1(t, m);
                return value;
            });
            // glTF metal with base colour 1 (F = 1) and the height-correlated G:
            // E[G2(wo, wi) / G1(wo)], more than the conductor's E[G1(wi)] away from the normal.
            ProbeCase gltfMetal{"pbr metal F=1", pbr(a, 1.0), cosO, 1.0, {}};
            gltfMetal.m.diffuse = glm::vec3(1.0f);
            const double gltfMetalAlbedo = quadratureOverVisibleNormals(ggx, wo, [&](const glm::dvec3& m) {
                const glm::dvec3 wi = reflect(wo, m);
                return wi.z > 0.0 ? ggx.gCorrelated(wo, wi, m) / ggx.g1(wo, m) : 0.0;
            });
            if (roughness == 1.0 && cosO == 0.05) {
                EXPECT_GT(gltfMetalAlbedo, 1.1 * metalAlbedo);
            }
            for (const auto& [c, expected] : {std::pair{metal, metalAlbedo}, std::pair{glass, glassAlbedo},
                                              std::pair{gltfMetal, gltfMetalAlbedo}}) {
                SCOPED_TRACE(c.name + " roughness " + std::to_string(roughness) + " cosO " + std::to_string(cosO));
                const std::vector<Sample> samples = sampleOnGpu(c, kSamples, 5.0f);
                double sum = 0.0, sumSquares = 0.0;
                for (const Sample& s : samples) {
                    sum += s.weight.x;
                    sumSquares += double(s.weight.x) * s.weight.x;
                }
                const double mean = sum / kSamples;
                const double standardError = std::sqrt(std::max(0.0, sumSquares / kSamples - mean * mean) / kSamples);
                EXPECT_LE(expected, 1.0 + 1e-9);
                EXPECT_LE(mean, 1.0 + 4.0 * standardError + 1e-6) << "gains energy";
                EXPECT_NEAR(mean, expected, 4.5 * standardError + 2e-4) << "GPU mean vs quadrature";
                RecordProperty(c.name + " r" + std::to_string(roughness) + " c" + std::to_string(cosO),
                               std::to_string(expected));
            }
        }
    }
}

TEST_F(MicrofacetProbe, NoNanAtTinyAlphaGrazingOrBelowTheSurface)
{
    const double tiny = gpu::MIN_GGX_ALPHA;
    for (const double cosO : {1.0, 1e-3, 1e-6, -0.3}) {
        for (const ProbeCase& c : {ProbeCase{"conductor", conductor(tiny, tiny), cosO, 1.0, {}},
                                   ProbeCase{"rough_dielectric", roughDielectric(tiny), cosO, 1.0 / 1.5, {}},
                                   ProbeCase{"rough_dielectric leaving", roughDielectric(tiny), cosO, 1.5, {}},
                                   plastic("plastic", tiny, cosO), ProbeCase{"pbr", pbr(tiny, 0.5), cosO, 1.0, {}}}) {
            SCOPED_TRACE(c.name + " cosO " + std::to_string(cosO));
            ProbeCase probe = c;
            probe.cosO = cosO;
            for (const Sample& s : sampleOnGpu(probe, 4096, 9.0f)) {
                for (int ch = 0; ch < 3; ++ch) ASSERT_TRUE(std::isfinite(s.weight[ch]) && s.weight[ch] >= 0.0f);
                ASSERT_TRUE(std::isfinite(s.pdf));
                if (!(s.flags & 4u)) {
                    ASSERT_NEAR(glm::length(s.dir), 1.0f, 1e-4f);
                }
                if (cosO <= 0.0) {
                    ASSERT_EQ(s.flags & 4u, 4u) << "a direction below the surface must not scatter";
                }
            }
        }
    }
}

} // namespace
} // namespace vkrt::test

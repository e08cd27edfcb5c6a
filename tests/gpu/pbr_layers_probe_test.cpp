// The pbr material's glTF extension layers (KHR_materials_specular, _ior,
// _sheen, _clearcoat with its own normal, _anisotropy; lib/bsdf.glsl under
// VKRT_PBR_LAYERS and VKRT_PBR_ANISOTROPY) run on the test GPU
// through tests/gpu/kernels/bsdf_probe.comp, against the independent
// double-precision reference of the Khronos formulas (support/GltfPbrReference.h):
//  - evaluation equals the reference at many direction pairs (the sheen's
//    albedo table is the one difference, within its interpolation error);
//  - without the coat the BRDF is reciprocal; with it, it is not, as the
//    clearcoat specification's N.V Fresnel makes it;
//  - the sampler's directions follow its density (chi-square, Sidak-corrected);
//  - white furnace: the sample weights average to the reference's directional
//    albedo (quadrature), and a white metal under every layer never exceeds 1.
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
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

namespace vkrt::test {
namespace {

constexpr uint32_t kSamples = 1u << 18;
constexpr size_t kSheenTableAt = 128; // bsdf_probe.comp's layout with VKRT_PBR_LAYERS

const std::vector<Define> kLayers{{"VKRT_PBR_LAYERS", "1"},
                                  {"VKRT_PBR_ANISOTROPY", "1"},
                                  {"VKRT_PBR_SHEEN", "1"},
                                  {"VKRT_PBR_CLEARCOAT", "1"}};

struct LayerCase {
    std::string name;
    GltfPbrParams p;
};

glm::dvec3 direction(double cosTheta, double phi)
{
    const double s = std::sqrt(std::max(0.0, 1.0 - cosTheta * cosTheta));
    return {s * std::cos(phi), s * std::sin(phi), cosTheta};
}

/// The probe's inputs for `p` seen from wo (mode 0: sample, 1: evaluate).
std::vector<float> probeInput(const GltfPbrParams& p, const glm::dvec3& wo, float mode, float seed)
{
    const double alpha = std::max(p.roughness * p.roughness, double(gpu::MIN_GGX_ALPHA));
    // KHR_materials_anisotropy as a hit resolves it: alphaX stretched along the direction.
    const double alphaX = alpha + (1.0 - alpha) * p.anisotropy * p.anisotropy;
    const double coatAlpha = std::max(p.clearcoatRoughness * p.clearcoatRoughness, double(gpu::MIN_GGX_ALPHA));
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
                              float(alphaX),
                              float(alpha),
                              float(kSheenTableAt),
                              0.0f,
                              0.0f,
                              0.0f,
                              float(p.metallic)};
    std::copy(std::begin(material), std::end(material), in.begin());
    in[25] = float(wo.x);
    in[26] = float(wo.y);
    in[27] = float(wo.z);
    in[28] = 1.0f;
    in[29] = mode;
    in[30] = seed;
    const float layers[] = {float(p.sheenColor.x),   float(p.sheenColor.y), float(p.sheenColor.z),
                            float(p.sheenRoughness), float(p.specular),     float(p.clearcoat),
                            float(coatAlpha)};
    std::copy(std::begin(layers), std::end(layers), in.begin() + 31);
    if (p.anisotropy > 0.0) {
        in[40] = float(std::cos(p.anisotropyAngle));
        in[41] = float(std::sin(p.anisotropyAngle));
    }
    if (p.clearcoatNormal != glm::dvec3(0.0, 0.0, 1.0)) {
        in[43] = float(p.clearcoatNormal.x);
        in[44] = float(p.clearcoatNormal.y);
        in[45] = float(p.clearcoatNormal.z);
    }
    const std::vector<float>& table = sheenAlbedoTable();
    in.insert(in.end(), table.begin(), table.end());
    return in;
}

struct Sample {
    glm::vec3 dir;
    glm::vec3 weight;
    unsigned flags; // 1 specular, 2 transmitted, 4 none
};

std::vector<Sample> sampleOnGpu(const GltfPbrParams& p, const glm::dvec3& wo, float seed = 1.0f)
{
    const std::vector<float> out =
        runProbe("bsdf_probe", probeInput(p, wo, 0.0f, seed), 8 * size_t(kSamples), kSamples, kLayers);
    std::vector<Sample> samples(kSamples);
    for (size_t i = 0; i < kSamples; ++i) {
        const float* o = &out[8 * i];
        samples[i] = {{o[0], o[1], o[2]}, {o[3], o[4], o[5]}, unsigned(o[7])};
    }
    return samples;
}

/// evalBsdf (xyz) and pdfBsdf (w) of the GLSL at each direction.
std::vector<glm::vec4> evaluateOnGpu(const GltfPbrParams& p, const glm::dvec3& wo, const std::vector<glm::dvec3>& wis)
{
    std::vector<float> in = probeInput(p, wo, 1.0f, 0.0f);
    for (const glm::dvec3& d : wis) in.insert(in.end(), {float(d.x), float(d.y), float(d.z)});
    const auto count = uint32_t(wis.size());
    const std::vector<float> out = runProbe("bsdf_probe", in, 8 * size_t(count), count, kLayers);
    std::vector<glm::vec4> result(count);
    for (size_t i = 0; i < count; ++i) result[i] = {out[8 * i], out[8 * i + 1], out[8 * i + 2], out[8 * i + 3]};
    return result;
}

/// Layer sets inside the region where the specification's sheen albedo stays
/// below 1 (sheen roughness >= 0.3; GltfPbrReference.h).
std::vector<LayerCase> layerCases()
{
    std::vector<LayerCase> cases;
    GltfPbrParams base;
    base.baseColor = {0.8, 0.5, 0.2};
    base.metallic = 0.3;
    base.roughness = 0.5;
    cases.push_back({"specular colour and ior", base});
    cases.back().p.ior = 1.8;
    cases.back().p.specular = 0.7;
    cases.back().p.specularColor = {1.6, 0.5, 1.0};
    cases.push_back({"sheen", base});
    cases.back().p.sheenColor = {0.9, 0.4, 0.2};
    cases.back().p.sheenRoughness = 0.5;
    cases.push_back({"clearcoat", base});
    cases.back().p.clearcoat = 0.8;
    cases.back().p.clearcoatRoughness = 0.2;
    cases.push_back({"every layer, dielectric", base});
    cases.back().p.metallic = 0.0;
    cases.back().p.roughness = 0.8;
    cases.back().p.ior = 1.4;
    cases.back().p.specularColor = {0.5, 1.0, 2.0};
    cases.back().p.sheenColor = {0.3, 0.6, 0.9};
    cases.back().p.sheenRoughness = 0.9;
    cases.back().p.clearcoat = 1.0;
    cases.back().p.clearcoatRoughness = 0.35;
    cases.push_back({"anisotropic metal", base});
    cases.back().p.metallic = 1.0;
    cases.back().p.roughness = 0.4;
    cases.back().p.anisotropy = 0.8;
    cases.back().p.anisotropyAngle = 0.7;
    cases.push_back({"anisotropic dielectric, coat with its own normal", base});
    cases.back().p.metallic = 0.0;
    cases.back().p.anisotropy = 0.5;
    cases.back().p.anisotropyAngle = -1.2;
    cases.back().p.clearcoat = 0.9;
    cases.back().p.clearcoatRoughness = 0.3;
    cases.back().p.clearcoatNormal = glm::normalize(glm::dvec3(0.3, -0.2, 1.0));
    return cases;
}

class PbrLayersProbe : public GpuTest {};

TEST_F(PbrLayersProbe, EvaluationEqualsTheSpecificationsFormulas)
{
    for (const LayerCase& c : layerCases()) {
        SCOPED_TRACE(c.name);
        for (const double cosO : {0.95, 0.6, 0.15}) {
            const glm::dvec3 wo = direction(cosO, 0.3);
            std::vector<glm::dvec3> wis;
            for (const double cosI : {0.9, 0.7, 0.45, 0.2, 0.08})
                for (int k = 0; k < 8; ++k) wis.push_back(direction(cosI, 2.0 * std::numbers::pi * k / 8.0 + 0.1));
            const std::vector<glm::vec4> gpu = evaluateOnGpu(c.p, wo, wis);
            for (size_t i = 0; i < wis.size(); ++i) {
                const glm::dvec3 expected = gltfPbrEval(c.p, wo, wis[i]);
                for (int k = 0; k < 3; ++k)
                    EXPECT_NEAR(gpu[i][k], expected[k], 2e-3 * std::abs(expected[k]) + 1e-5)
                        << "cosO " << cosO << " wi (" << wis[i].x << ", " << wis[i].y << ", " << wis[i].z
                        << ") channel " << k;
            }
        }
    }
}

TEST_F(PbrLayersProbe, ReciprocalExceptForTheCoatsNormalFresnel)
{
    for (const LayerCase& c : layerCases()) {
        SCOPED_TRACE(c.name);
        const glm::dvec3 a = direction(0.8, 0.2), b = direction(0.3, 2.5);
        const glm::vec3 ab(evaluateOnGpu(c.p, a, {b})[0]), ba(evaluateOnGpu(c.p, b, {a})[0]);
        const double difference = glm::length(glm::dvec3(ab - ba)) / glm::length(glm::dvec3(ab));
        if (c.p.clearcoat > 0.0) {
            EXPECT_GT(difference, 1e-3) << "the coat's Fresnel is taken at N.V (KHR_materials_clearcoat)";
        } else {
            EXPECT_LT(difference, 1e-5);
        }
    }
}

/// The sampler's density: the lobes' mixture with the probabilities lib/bsdf.glsl
/// chooses them by, written out here from the reference's parts.
double samplerPdf(const GltfPbrParams& p, const glm::dvec3& wo, const glm::dvec3& wi)
{
    if (wi.z <= 0.0) return 0.0;
    auto pow5 = [](double x) { return x * x * x * x * x; };
    // The coat's lobe about its own normal (any frame around it: the lobe is isotropic).
    const glm::dvec3 nc = p.clearcoatNormal;
    const glm::dvec3 tc = glm::normalize(glm::cross(nc, glm::dvec3(1.0, 0.0, 0.0))), bc = glm::cross(nc, tc);
    auto coatLocal = [&](const glm::dvec3& w) { return glm::dvec3(glm::dot(w, tc), glm::dot(w, bc), glm::dot(w, nc)); };
    const glm::dvec3 woCoat = coatLocal(wo), wiCoat = coatLocal(wi);
    const double coat = woCoat.z > 0.0 ? p.clearcoat * (0.04 + 0.96 * pow5(1.0 - woCoat.z)) : 0.0;
    const double r = (p.ior - 1.0) / (p.ior + 1.0);
    // The specular at wo's cosine; the diffuse weighed by its mean 1 - F(V.H) over its lobe (diffuseMeanHalfCosineFit).
    double fd = 0.0, fdDiffuse = 0.0;
    for (int k = 0; k < 3; ++k) {
        const double f0 = std::min(r * r * p.specularColor[k], 1.0) * p.specular;
        fd = std::max(fd, f0 + (p.specular - f0) * pow5(1.0 - wo.z));
        fdDiffuse = std::max(fdDiffuse, f0 + (p.specular - f0) * pow5(1.0 - diffuseMeanHalfCosineFit(wo.z)));
    }
    fdDiffuse = std::min(fdDiffuse, fd);
    const double specular = p.metallic + (1.0 - p.metallic) * fd;
    const double diffuse =
        (1.0 - p.metallic) * (1.0 - fdDiffuse) * glm::dot(p.baseColor, glm::dvec3(0.2126, 0.7152, 0.0722));
    const double sheenStrength = std::max({p.sheenColor.x, p.sheenColor.y, p.sheenColor.z});
    const double sheen = sheenStrength > 0.0 ? sheenStrength * sheenDirectionalAlbedo(wo.z, p.sheenRoughness) : 0.0;
    const double ps = specular / (specular + diffuse + sheen);
    // The reflection's density about h = normalize(o + i) of the visible normals of Ggx{ax, ay} in the frame
    // where o and i are given.
    auto lobe = [&](double ax, double ay, const glm::dvec3& o, const glm::dvec3& i) {
        const glm::dvec3 h = glm::normalize(o + i);
        const Ggx ggx{ax, ay};
        return ggx.visibleNormalPdf(o, h) / (4.0 * glm::dot(o, h));
    };
    const double coatAlpha = std::max(p.clearcoatRoughness * p.clearcoatRoughness, double(gpu::MIN_GGX_ALPHA));
    // The base's lobe in the frame whose x axis is the anisotropy's direction.
    const double alpha = std::max(p.roughness * p.roughness, double(gpu::MIN_GGX_ALPHA));
    const double c = std::cos(p.anisotropyAngle), s = std::sin(p.anisotropyAngle);
    auto turned = [&](const glm::dvec3& w) { return glm::dvec3(c * w.x + s * w.y, -s * w.x + c * w.y, w.z); };
    const double alphaT = alpha + (1.0 - alpha) * p.anisotropy * p.anisotropy;
    const double base = lobe(alphaT, alpha, turned(wo), turned(wi));
    return coat * lobe(coatAlpha, coatAlpha, woCoat, wiCoat) +
           (1.0 - coat) * (ps * base + (1.0 - ps) * wi.z / std::numbers::pi);
}

TEST_F(PbrLayersProbe, SamplerMatchesItsDensityChiSquare)
{
    const std::vector<LayerCase> cases = layerCases();
    const std::vector<double> cosines{0.9, 0.3};
    const double alpha = sidakCorrectedAlpha(0.01, int(cases.size() * cosines.size()));
    ChiSquareOptions options;
    options.thetaBins = 10;
    options.subCells = 2;
    options.countTolerance = 0.1;
    for (const LayerCase& c : cases)
        for (const double cosO : cosines) {
            SCOPED_TRACE(c.name + " cosO " + std::to_string(cosO));
            const glm::dvec3 wo = direction(cosO, 0.0);
            std::vector<glm::vec3> directions;
            long long none = 0;
            for (const Sample& s : sampleOnGpu(c.p, wo)) {
                if (s.flags & 4u) ++none;
                else directions.push_back(s.dir);
            }
            const ChiSquareResult result = chiSquareTest(
                directions, none, [&](const glm::dvec3& w) { return samplerPdf(c.p, wo, w); }, options);
            EXPECT_TRUE(result.passes(alpha)) << "p = " << result.pValue << "\n" << result.table;
        }
}

/// The directional albedo of the reference at wo: the integral of f cos over
/// the hemisphere by a midpoint rule in (cos^2, phi), nodes clustered at grazing.
double referenceAlbedo(const GltfPbrParams& p, const glm::dvec3& wo, int channel)
{
    constexpr int kT = 256, kPhi = 256;
    double sum = 0.0;
    for (int a = 0; a < kT; ++a) {
        const double t = (a + 0.5) / kT, cosI = t * t;
        for (int b = 0; b < kPhi; ++b) {
            const glm::dvec3 wi = direction(cosI, 2.0 * std::numbers::pi * (b + 0.5) / kPhi);
            sum += gltfPbrEval(p, wo, wi)[channel] * cosI * 2.0 * t;
        }
    }
    return sum / kT * (2.0 * std::numbers::pi / kPhi);
}

TEST_F(PbrLayersProbe, WhiteFurnaceMatchesTheReferenceAlbedoAndNeverGains)
{
    // A white metal under a white sheen and a full coat: each layer takes
    // energy from the one below, so the whole stays at most 1. Then the same
    // metal anisotropic under a coat with its own, tilted normal.
    GltfPbrParams layered;
    layered.baseColor = glm::dvec3(1.0);
    layered.metallic = 1.0;
    layered.roughness = 0.6;
    layered.sheenColor = glm::dvec3(1.0);
    layered.sheenRoughness = 0.6;
    layered.clearcoat = 1.0;
    layered.clearcoatRoughness = 0.3;
    GltfPbrParams anisotropic = layered;
    anisotropic.sheenColor = glm::dvec3(0.0);
    anisotropic.roughness = 0.3;
    anisotropic.anisotropy = 0.9;
    anisotropic.anisotropyAngle = 0.4;
    anisotropic.clearcoatNormal = glm::normalize(glm::dvec3(-0.25, 0.1, 1.0));
    for (const GltfPbrParams& p : {layered, anisotropic})
        for (const double cosO : {1.0, 0.5, 0.15}) {
            SCOPED_TRACE("anisotropy " + std::to_string(p.anisotropy) + " cosO " + std::to_string(cosO));
            const glm::dvec3 wo = direction(cosO, 0.0);
            double sum = 0.0, sumSquares = 0.0;
            for (const Sample& s : sampleOnGpu(p, wo, 3.0f)) {
                sum += s.weight.x;
                sumSquares += double(s.weight.x) * s.weight.x;
            }
            const double mean = sum / kSamples;
            const double standardError = std::sqrt(std::max(0.0, sumSquares / kSamples - mean * mean) / kSamples);
            const double expected = referenceAlbedo(p, wo, 0);
            EXPECT_LE(expected, 1.0);
            EXPECT_LE(mean, 1.0 + 4.0 * standardError) << "gains energy";
            EXPECT_NEAR(mean, expected, 4.5 * standardError + 2e-3) << "GPU mean vs quadrature of the reference";
            RecordProperty("albedo_a" + std::to_string(p.anisotropy) + "_c" + std::to_string(cosO),
                           std::to_string(expected));
        }
}

} // namespace
} // namespace vkrt::test

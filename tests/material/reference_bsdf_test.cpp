// The CPU reference BSDFs: their samplers against their pdfs (chi-square, Sidak-corrected alpha = 0.01),
// a deliberately wrong sampler rejected, closed-form weights against eval cos / pdf, pdf mass, white
// furnaces against an independent quadrature, reciprocity, and finite values at the extremes.
#include "material/Ggx.h"
#include "material/MicrofacetAlbedo.h"
#include "support/ChiSquare.h"
#include "support/ReferenceBsdf.h"

#include <cmath>
#include <cstdio>
#include <functional>
#include <glm/geometric.hpp>
#include <gtest/gtest.h>
#include <memory>
#include <numbers>
#include <random>
#include <string>
#include <vector>

namespace vkrt::test {
namespace {

constexpr double kRoughnesses[] = {0.05, 0.2, 0.5, 1.0}; // perceptual; alpha = roughness^2
constexpr double kViewCosines[] = {1.0, 0.5, 0.1, 0.01};

glm::dvec3 viewDirection(double cosO, double phi = 0.7)
{
    double sinO = std::sqrt(std::max(0.0, 1.0 - cosO * cosO));
    return {sinO * std::cos(phi), sinO * std::sin(phi), cosO};
}

struct NamedBsdf {
    std::string name;
    std::shared_ptr<ReferenceBsdf> bsdf;
};

/// Every BSDF kind at one roughness (the conductor anisotropic, the dielectric seen from both sides).
std::vector<NamedBsdf> bsdfsAt(double roughness)
{
    double alpha = roughness * roughness;
    Ggx iso{alpha, alpha}, aniso{alpha, std::max(1e-4, 0.5 * alpha)};
    return {
        {"conductor(Au, aniso)",
         std::make_shared<RoughConductor>(aniso, Rgb(0.1431, 0.3750, 1.4425), Rgb(3.9832, 2.3857, 1.6032))},
        {"dielectric(1.5)", std::make_shared<RoughDielectric>(iso, 1.5)},
        {"dielectric(1/1.5)", std::make_shared<RoughDielectric>(iso, 1.0 / 1.5)},
        {"plastic(1.5)", std::make_shared<RoughPlastic>(alpha, 1.5, Rgb(0.6, 0.3, 0.1))},
        {"pbr(metallic 0.3)", std::make_shared<GltfPbr>(alpha, Rgb(0.8, 0.5, 0.2), 0.3, 0.5)},
    };
}

struct Draws {
    std::vector<glm::dvec3> directions;
    std::vector<BsdfSample> samples;
    long long rejected = 0;
};

Draws draw(const ReferenceBsdf& bsdf, const glm::dvec3& wo, int count, unsigned seed)
{
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    Draws out;
    for (int i = 0; i < count; ++i) {
        double u0 = uniform(rng), u1 = uniform(rng), u2 = uniform(rng);
        BsdfSample s = bsdf.sample(wo, u0, u1, u2);
        if (!s.valid) {
            ++out.rejected;
            continue;
        }
        out.directions.push_back(s.wi);
        out.samples.push_back(s);
    }
    return out;
}

ChiSquareOptions optionsFor(double roughness)
{
    ChiSquareOptions options;
    options.thetaBins = 16;
    options.subCells = roughness < 0.1 ? 8 : 4; // near-specular lobes are narrower than a cell
    return options;
}

TEST(ReferenceBsdf, SamplersMatchTheirPdfs)
{
    const int tests = 4 * 4 * 5;
    const double alpha = sidakCorrectedAlpha(0.01, tests);
    unsigned seed = 1;
    for (double roughness : kRoughnesses)
        for (double cosO : kViewCosines)
            for (const NamedBsdf& named : bsdfsAt(roughness)) {
                glm::dvec3 wo = viewDirection(cosO);
                Draws d = draw(*named.bsdf, wo, 100000, seed++);
                auto pdf = [&](const glm::dvec3& wi) { return named.bsdf->pdf(wo, wi); };
                ChiSquareResult r = chiSquareTest(std::span<const glm::dvec3>(d.directions), d.rejected, pdf,
                                                  optionsFor(roughness));
                EXPECT_TRUE(r.passes(alpha)) << named.name << " roughness " << roughness << " cosO " << cosO << "\n"
                                             << r.table;
            }
}

TEST(ReferenceBsdf, ChiSquareRejectsASamplerWithAlphaOffByTenPercent)
{
    for (double roughness : {0.2, 0.5}) {
        double alpha = roughness * roughness;
        RoughConductor right(Ggx{alpha, alpha}, Rgb(0.2), Rgb(3.0));
        RoughConductor wrong(Ggx{1.1 * alpha, 1.1 * alpha}, Rgb(0.2), Rgb(3.0));
        glm::dvec3 wo = viewDirection(0.5);
        Draws d = draw(wrong, wo, 100000, 99);
        auto pdf = [&](const glm::dvec3& wi) { return right.pdf(wo, wi); };
        ChiSquareResult r =
            chiSquareTest(std::span<const glm::dvec3>(d.directions), d.rejected, pdf, optionsFor(roughness));
        EXPECT_LT(r.pValue, 1e-4) << "roughness " << roughness << "\n" << r.table;
        // The same draws from the right sampler pass.
        Draws good = draw(right, wo, 100000, 99);
        EXPECT_TRUE(chiSquareTest(std::span<const glm::dvec3>(good.directions), good.rejected, pdf,
                                  optionsFor(roughness))
                        .passes(0.01));
    }
}

TEST(ReferenceBsdf, SampleWeightIsEvalCosOverPdf)
{
    for (double roughness : kRoughnesses)
        for (double cosO : kViewCosines)
            for (const NamedBsdf& named : bsdfsAt(roughness)) {
                glm::dvec3 wo = viewDirection(cosO);
                Draws d = draw(*named.bsdf, wo, 2000, 7);
                for (const BsdfSample& s : d.samples) {
                    ASSERT_NEAR(s.pdf, named.bsdf->pdf(wo, s.wi), 1e-9 * s.pdf);
                    Rgb expected = named.bsdf->eval(wo, s.wi) * std::abs(s.wi.z) / s.pdf;
                    for (int c = 0; c < 3; ++c)
                        ASSERT_NEAR(s.weight[c], expected[c], 1e-7 * std::max(1.0, expected[c]))
                            << named.name << " roughness " << roughness << " cosO " << cosO;
                    // Microfacet weights never exceed 1 (tinted by F <= 1); pbr/plastic mixtures may not.
                    if (named.name.starts_with("conductor") || named.name.starts_with("dielectric")) {
                        ASSERT_LE(s.weight.x, 1.0 + 1e-12);
                    }
                }
            }
}

/// Integral of f over the whole sphere in (cos theta, phi).
double sphereIntegral(const std::function<double(const glm::dvec3&)>& f, int subCells)
{
    auto g = [&](double c, double phi) {
        double s = std::sqrt(std::max(0.0, 1.0 - c * c));
        return f(glm::dvec3(s * std::cos(phi), s * std::sin(phi), c));
    };
    double sum = 0.0;
    for (int i = 0; i < 8; ++i) // 8 bands in cos theta: keeps the lobes' kinks local
        sum += integrate2d(g, -1.0 + 0.25 * i, -0.75 + 0.25 * i, 0.0, 2.0 * std::numbers::pi, subCells, 1e-7);
    return sum;
}

TEST(ReferenceBsdf, PdfMassIsOneMinusTheRejectedDraws)
{
    for (double roughness : {0.2, 0.5, 1.0})
        for (double cosO : {1.0, 0.5, 0.1})
            for (const NamedBsdf& named : bsdfsAt(roughness)) {
                glm::dvec3 wo = viewDirection(cosO);
                double mass = sphereIntegral([&](const glm::dvec3& wi) { return named.bsdf->pdf(wo, wi); }, 4);
                Draws d = draw(*named.bsdf, wo, 100000, 11);
                double rejectedFraction = double(d.rejected) / 100000.0;
                double sigma = std::sqrt(std::max(rejectedFraction, 1e-6) / 100000.0);
                EXPECT_LE(mass, 1.0 + 1e-6) << named.name;
                EXPECT_NEAR(mass, 1.0 - rejectedFraction, 5.0 * sigma + 1e-4)
                    << named.name << " roughness " << roughness << " cosO " << cosO;
                // The dielectric's r + t pdf integrates to 1 only as alpha -> 0: a reflection or refraction
                // about a steep microfacet can leave on the wrong side (at alpha = 1 from inside glass, half of
                // all draws do, as for the conductor), and those draws are rejected.
                if (named.name.starts_with("dielectric") && cosO == 1.0 && roughness <= 0.2) {
                    EXPECT_NEAR(mass, 1.0, 2e-3) << named.name << " roughness " << roughness;
                }
            }
}

double meanWeight(const ReferenceBsdf& bsdf, const glm::dvec3& wo, int count, double* standardError)
{
    Draws d = draw(bsdf, wo, count, 23);
    double sum = 0.0, sum2 = 0.0;
    for (const BsdfSample& s : d.samples) {
        sum += s.weight.x;
        sum2 += s.weight.x * s.weight.x;
    }
    double mean = sum / count;
    *standardError = std::sqrt(std::max(0.0, sum2 / count - mean * mean) / count);
    return mean;
}

TEST(ReferenceBsdf, WhiteFurnaceLosesOnlySingleScatteringEnergy)
{
    std::printf("white furnace, albedo (1 - loss): roughness alpha cosO | F=1 conductor: MC quadrature | "
                "lossless dielectric 1.5: MC quadrature\n");
    for (double roughness : kRoughnesses)
        for (double cosO : kViewCosines) {
            double alpha = roughness * roughness;
            glm::dvec3 wo = viewDirection(cosO, 0.0);
            RoughConductor mirror = RoughConductor::perfectMirror(Ggx{alpha, alpha});
            RoughDielectric glass(Ggx{alpha, alpha}, 1.5);
            double conductorError = 0.0, glassError = 0.0;
            double conductorMc = meanWeight(mirror, wo, 400000, &conductorError);
            double glassMc = meanWeight(glass, wo, 400000, &glassError);
            // Independent quadrature of the same albedo: the half-vector integral of MicrofacetAlbedo with a
            // dielectric of enormous index, whose Fresnel reflectance is 1 to ~1e-7.
            double conductorQuadrature = roughSpecularAlbedo(cosO, alpha, 1e9);
            // The dielectric by brute-force quadrature of eval |cos| over the sphere (broad lobes only).
            double glassQuadrature = NAN;
            if (roughness >= 0.5 && cosO >= 0.1)
                glassQuadrature = sphereIntegral(
                    [&](const glm::dvec3& wi) { return glass.eval(wo, wi).x * std::abs(wi.z); }, 12);
            std::printf("  %.2f %.4f %.2f | %.5f %.5f | %.5f %.5f\n", roughness, alpha, cosO, conductorMc,
                        conductorQuadrature, glassMc, glassQuadrature);
            EXPECT_NEAR(conductorMc, conductorQuadrature, 5.0 * conductorError + 1e-4)
                << "roughness " << roughness << " cosO " << cosO;
            EXPECT_LE(conductorQuadrature, 1.0 + 1e-6);
            EXPECT_LE(glassMc, 1.0);
            if (!std::isnan(glassQuadrature)) {
                EXPECT_NEAR(glassMc, glassQuadrature, 5.0 * glassError + 2e-4) << "roughness " << roughness;
                EXPECT_LE(glassQuadrature, 1.0 + 1e-5);
            }
            // Nearly smooth surfaces lose nearly nothing away from grazing.
            if (roughness <= 0.05 && cosO >= 0.5) {
                EXPECT_GT(conductorMc, 0.999);
                EXPECT_GT(glassMc, 0.999);
            }
        }
    // A closed form: at alpha = 1, D = 1/pi, so at normal incidence visible normals are cosine-distributed,
    // theta_i = 2 theta_h and G1(wi) = 2 cos(theta_i) / (1 + cos(theta_i)); the albedo
    // 2 int_0^{pi/4} cos(2t) tan(t) dt = 1 - ln 2 = 0.3069 (the loss is 69 %, not the albedo).
    EXPECT_NEAR(roughSpecularAlbedo(1.0, 1.0, 1e9), 1.0 - std::log(2.0), 1e-5);
    double error = 0.0;
    double mc = meanWeight(RoughConductor::perfectMirror(Ggx{1.0, 1.0}), glm::dvec3(0, 0, 1), 1000000, &error);
    EXPECT_NEAR(mc, 1.0 - std::log(2.0), 5.0 * error);
}

TEST(ReferenceBsdf, ReflectionIsReciprocal)
{
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    for (double roughness : kRoughnesses)
        for (const NamedBsdf& named : bsdfsAt(roughness)) {
            if (named.name.starts_with("dielectric")) continue;
            for (int i = 0; i < 200; ++i) {
                glm::dvec3 a = sampleCosineHemisphere(uniform(rng), uniform(rng));
                glm::dvec3 b = sampleCosineHemisphere(uniform(rng), uniform(rng));
                Rgb ab = named.bsdf->eval(a, b), ba = named.bsdf->eval(b, a);
                for (int c = 0; c < 3; ++c) ASSERT_NEAR(ab[c], ba[c], 1e-9 * std::max(1.0, ab[c])) << named.name;
            }
        }
}

TEST(ReferenceBsdf, FiniteAtExtremes)
{
    std::vector<NamedBsdf> all;
    for (double roughness : {0.01, 1e-6, 0.0}) // alpha = 1e-4, 1e-12, 0 (clamped by GGX users to 1e-4)
        for (auto& b : bsdfsAt(std::max(roughness, 0.01))) all.push_back(b);
    const glm::dvec3 directions[] = {viewDirection(1e-6), viewDirection(1.0), viewDirection(-0.5), viewDirection(0.0),
                                     glm::dvec3(0, 0, -1), viewDirection(1e-6, 2.0)};
    for (const NamedBsdf& named : all)
        for (const glm::dvec3& wo : directions)
            for (const glm::dvec3& wi : directions) {
                Rgb f = named.bsdf->eval(wo, wi);
                double p = named.bsdf->pdf(wo, wi);
                for (int c = 0; c < 3; ++c) ASSERT_TRUE(std::isfinite(f[c]) && f[c] >= 0.0) << named.name;
                ASSERT_TRUE(std::isfinite(p) && p >= 0.0) << named.name;
                for (double u : {0.0, 0.3, 0.999999}) {
                    BsdfSample s = named.bsdf->sample(wo, u, u, 1.0 - u);
                    if (wo.z <= 0.0) {
                        ASSERT_FALSE(s.valid) << named.name << " samples from below";
                    }
                    if (!s.valid) continue;
                    for (int c = 0; c < 3; ++c) ASSERT_TRUE(std::isfinite(s.weight[c])) << named.name;
                    ASSERT_TRUE(std::isfinite(s.pdf) && s.pdf > 0.0) << named.name;
                }
            }
}

} // namespace
} // namespace vkrt::test

// The chi-square tool itself: the incomplete gamma against closed forms, a right sampler accepted, a
// slightly wrong one rejected, and the mass of rejected draws accounted for.
#include "support/ChiSquare.h"

#include <cmath>
#include <gtest/gtest.h>
#include <numbers>
#include <random>
#include <vector>

namespace vkrt::test {
namespace {

TEST(ChiSquareTool, IncompleteGammaMatchesClosedForms)
{
    for (double x : {0.0, 0.1, 1.0, 3.0, 10.0, 40.0}) {
        EXPECT_NEAR(upperIncompleteGammaQ(1.0, x), std::exp(-x), 1e-14) << x;
        EXPECT_NEAR(upperIncompleteGammaQ(0.5, x), std::erfc(std::sqrt(x)), 1e-13) << x;
        EXPECT_NEAR(upperIncompleteGammaQ(2.0, x), (1.0 + x) * std::exp(-x), 1e-13) << x;
    }
    // chi^2 with 2 degrees of freedom: P(X >= s) = exp(-s / 2); the 1 % point of 10 dof is 23.209.
    EXPECT_NEAR(chiSquarePValue(2.0 * std::log(100.0), 2), 0.01, 1e-12);
    EXPECT_NEAR(chiSquarePValue(23.2093, 10), 0.01, 1e-5);
    EXPECT_NEAR(chiSquarePValue(1000.0, 1000), 0.4940, 1e-3); // ~ median for large dof
    EXPECT_NEAR(sidakCorrectedAlpha(0.01, 1), 0.01, 1e-15);
    EXPECT_NEAR(sidakCorrectedAlpha(0.01, 64), 1.0 - std::pow(0.99, 1.0 / 64.0), 1e-15);
}

TEST(ChiSquareTool, Integrate2dIsAccurate)
{
    auto f = [](double u, double v) { return std::exp(u) * std::cos(v); };
    EXPECT_NEAR(integrate2d(f, 0.0, 1.0, 0.0, 1.0, 2, 1e-10), (std::exp(1.0) - 1.0) * std::sin(1.0), 1e-9);
}

/// Directions with density proportional to cos^exponent over the upper hemisphere.
std::vector<glm::dvec3> powerCosineSamples(double exponent, int count, unsigned seed)
{
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    std::vector<glm::dvec3> out;
    for (int i = 0; i < count; ++i) {
        double cosTheta = std::pow(uniform(rng), 1.0 / (exponent + 1.0));
        double sinTheta = std::sqrt(1.0 - cosTheta * cosTheta), phi = 2.0 * std::numbers::pi * uniform(rng);
        out.emplace_back(sinTheta * std::cos(phi), sinTheta * std::sin(phi), cosTheta);
    }
    return out;
}

double powerCosinePdf(double exponent, const glm::dvec3& w)
{
    return w.z > 0.0 ? (exponent + 1.0) / (2.0 * std::numbers::pi) * std::pow(w.z, exponent) : 0.0;
}

TEST(ChiSquareTool, AcceptsTheRightSamplerAndRejectsAWrongOne)
{
    auto pdf = [](const glm::dvec3& w) { return powerCosinePdf(1.0, w); };
    auto right = powerCosineSamples(1.0, 200000, 1);
    ChiSquareResult good = chiSquareTest(std::span<const glm::dvec3>(right), 0, pdf);
    EXPECT_TRUE(good.passes(0.01)) << good.table;
    EXPECT_NEAR(good.integratedPdf, 1.0, 1e-6);
    // A 20 % error in the exponent is plain to see with this many samples (5 % gives p ~ 0.002 only:
    // an azimuth-independent error is spread over 40 azimuth cells).
    auto wrong = powerCosineSamples(1.2, 200000, 2);
    ChiSquareResult bad = chiSquareTest(std::span<const glm::dvec3>(wrong), 0, pdf);
    EXPECT_LT(bad.pValue, 1e-6) << bad.table;
    EXPECT_NE(bad.table.find("observed"), std::string::npos);
}

TEST(ChiSquareTool, CountsRejectedDrawsAgainstTheMissingMass)
{
    // A sampler that gives up on 30 % of its draws against a pdf that integrates to 0.7.
    auto pdf = [](const glm::dvec3& w) { return 0.7 * powerCosinePdf(2.0, w); };
    auto samples = powerCosineSamples(2.0, 70000, 3);
    ChiSquareResult right = chiSquareTest(std::span<const glm::dvec3>(samples), 30000, pdf);
    EXPECT_TRUE(right.passes(0.01)) << right.table;
    EXPECT_NEAR(right.integratedPdf, 0.7, 1e-6);
    // Rejecting 33 % instead of 30 % is detected, though the accepted directions are right.
    ChiSquareResult wrong = chiSquareTest(std::span<const glm::dvec3>(samples), 34500, pdf);
    EXPECT_LT(wrong.pValue, 1e-4) << wrong.table;
    EXPECT_NE(wrong.table.find("rejected"), std::string::npos);
}

TEST(ChiSquareTool, SamplesWhereThePdfIsZeroFail)
{
    auto pdf = [](const glm::dvec3& w) { return powerCosinePdf(1.0, w); };
    auto samples = powerCosineSamples(1.0, 10000, 4);
    samples.emplace_back(0.0, 0.0, -1.0); // below the surface, where nothing is expected
    ChiSquareResult result = chiSquareTest(std::span<const glm::dvec3>(samples), 0, pdf);
    EXPECT_EQ(result.pValue, 0.0) << result.table;
    // Single-precision input, as from a probe kernel, gives the same verdict for good samples.
    auto good = powerCosineSamples(1.0, 20000, 5);
    std::vector<glm::vec3> floats(good.begin(), good.end());
    EXPECT_TRUE(chiSquareTest(std::span<const glm::vec3>(floats), 0, pdf).passes(0.01));
}

} // namespace
} // namespace vkrt::test

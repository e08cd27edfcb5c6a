// The image error estimate that --target-error stops on (render/ErrorMetrics.h),
// without a device: its formula on known values, and on synthetic images
// whose true value is known, its behaviour where the old estimate failed.
// Each synthetic pixel is a heavy-tailed estimator (most samples 0, a few
// large: the firefly shape of glossy paths), rendered as 8 batch means as the
// Sobol' sampler gives them. The end-to-end coverage on the validation scenes
// against their Mitsuba references is tools/target_error_coverage.py
// (docs/convergence.md).
#include "render/ErrorMetrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace vkrt::test {
namespace {

TEST(ErrorEstimate, KnownValues)
{
    Image mean(2, 1), variance(2, 1);
    mean.rgb = {1, 2, 0, 4, 0.5f, 3};
    variance.rgb = {0.04f, 0.25f, 0.01f, 0, 1, INFINITY}; // the last value is skipped
    EstimatedError e = estimateError(mean, variance, 7.0);
    // Each term: v / (max(|m| - sqrt v, 0)^2 + 0.01).
    const double terms[] = {0.04 / (0.8 * 0.8 + 0.01), 0.25 / (1.5 * 1.5 + 0.01), 0.01 / 0.01, 0.0, 1 / 0.01};
    double sum = 0, squares = 0, variances = 0;
    for (double t : terms) sum += t, squares += t * t;
    for (double v : {0.04, 0.25, 0.01, 0.0, 1.0}) variances += v;
    EXPECT_NEAR(e.relMse, sum / 5, 1e-6 * sum);
    EXPECT_NEAR(e.rmse, std::sqrt(variances / 5), 1e-6);
    EXPECT_NEAR(e.degreesOfFreedom, sum * sum / (squares / 7.0), 1e-6 * e.degreesOfFreedom);
    EXPECT_NEAR(e.relMseUpper, e.relMse * varianceUpperFactor(e.degreesOfFreedom, kRelMseConfidence), 1e-9);
    EXPECT_GT(e.relMseUpper, e.relMse);
}

// nu / chi2_{0.05}(nu) from tables: chi2_{0.05}(7) = 2.16735, chi2_{0.05}(100) = 77.9295.
TEST(ErrorEstimate, UpperFactorMatchesChiSquareTables)
{
    EXPECT_NEAR(varianceUpperFactor(7.0, 0.95), 7.0 / 2.16735, 1e-4);
    EXPECT_NEAR(varianceUpperFactor(100.0, 0.95), 100.0 / 77.9295, 1e-4);
    EXPECT_EQ(varianceUpperFactor(INFINITY, 0.95), 1.0);
    EXPECT_TRUE(std::isinf(varianceUpperFactor(0.0, 0.95)));
}

// Equal terms over N values: N times the pixel's degrees of freedom.
TEST(ErrorEstimate, DegreesOfFreedomGrowWithTheValuesThatCarryTheEstimate)
{
    Image mean(10, 10), variance(10, 10);
    for (float& m : mean.rgb) m = 1.0f;
    for (float& v : variance.rgb) v = 0.01f;
    EXPECT_NEAR(estimateError(mean, variance, 7.0).degreesOfFreedom, 300 * 7.0, 1e-6);
    // One value carrying nearly everything: about the pixel's own 7.
    variance.rgb[17] = 100.0f;
    EXPECT_LT(estimateError(mean, variance, 7.0).degreesOfFreedom, 8.0);
    // No batch estimate yet (0 degrees of freedom): no estimate.
    EXPECT_TRUE(std::isinf(estimateError(mean, variance, 0.0).relMseUpper));
}

TEST(ErrorEstimate, NoNoiseIsAZeroBound)
{
    Image mean(2, 2), variance(2, 2);
    for (float& m : mean.rgb) m = 0.5f;
    EstimatedError e = estimateError(mean, variance, 7.0);
    EXPECT_EQ(e.relMse, 0.0);
    EXPECT_EQ(e.relMseUpper, 0.0);
}

/// One synthetic render. Each value's samples are a base, uniform on [0, 2b]
/// (mean b; its batch means are drawn as normals), plus a firefly: f / p with probability p, else 0 (mean f), so
/// the true value is b + f. They are averaged in 8 batches of spp / 8, as the
/// Sobol' sampler's independently scrambled batches are.
struct SyntheticRender {
    Image mean, varianceOfMean;
    double trueRelMse = 0.0;
};

struct HeavyTailedPixel {
    double base = 0.0, firefly = 0.0;
    double value() const { return base + firefly; }
};

SyntheticRender renderHeavyTailed(const std::vector<HeavyTailedPixel>& pixels, double p, uint32_t spp,
                                  std::mt19937_64& rng)
{
    constexpr uint32_t kBatches = 8;
    const uint32_t perBatch = spp / kBatches;
    const size_t n = pixels.size();
    SyntheticRender r{Image(uint32_t(n / 3), 1), Image(uint32_t(n / 3), 1)};
    std::normal_distribution<double> normal;
    std::binomial_distribution<uint32_t> hits(perBatch, p);
    double sumRelative = 0.0;
    for (size_t i = 0; i < n; ++i) {
        const HeavyTailedPixel& pixel = pixels[i];
        double batchMeans[kBatches], sum = 0.0;
        for (double& b : batchMeans) {
            // The base's batch mean: normal to many samples (variance b^2 / 3 per sample).
            b = pixel.base + normal(rng) * pixel.base / std::sqrt(3.0 * perBatch) +
                hits(rng) * pixel.firefly / p / perBatch;
            sum += b;
        }
        double m = sum / kBatches, squares = 0.0;
        for (double b : batchMeans) squares += (b - m) * (b - m);
        r.mean.rgb[i] = float(m);
        r.varianceOfMean.rgb[i] = float(squares / (kBatches * (kBatches - 1)));
        double truth = pixel.value();
        sumRelative += (m - truth) * (m - truth) / (truth * truth + kRelMseEpsilon);
    }
    r.trueRelMse = sumRelative / double(n);
    return r;
}

/// The estimate before: each value's variance over its own mean squared.
double ownMeanEstimate(const SyntheticRender& r)
{
    double sum = 0.0;
    for (size_t i = 0; i < r.mean.rgb.size(); ++i)
        sum += r.varianceOfMean.rgb[i] / (double(r.mean.rgb[i]) * r.mean.rgb[i] + kRelMseEpsilon);
    return sum / double(r.mean.rgb.size());
}

// Over many renders of an image with fireflies, the upper bound covers the
// true relMSE in at least 95 % of them (the promise of --target-error) and
// the point estimate is not far below it on average; the mean's own square as
// the denominator (the estimate before) is, by a large factor: a firefly
// raises a pixel's mean with its variance, so its term stays near 1
// however wrong the pixel is. Half of each value comes from samples 1024
// times the rest, once in 1024 samples.
TEST(ErrorEstimate, UpperBoundCoversTheTrueErrorOfFireflies)
{
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> value(0.2, 2.0);
    std::vector<HeavyTailedPixel> pixels(3 * 32 * 32);
    for (HeavyTailedPixel& pixel : pixels) pixel.base = value(rng), pixel.firefly = 0.5 * pixel.base;
    for (uint32_t spp : {64u, 512u}) {
        const int trials = 100;
        int covered = 0;
        double sumEstimate = 0.0, sumOwnMean = 0.0, sumTrue = 0.0;
        for (int trial = 0; trial < trials; ++trial) {
            SyntheticRender r = renderHeavyTailed(pixels, 1.0 / 1024, spp, rng);
            EstimatedError e = estimateError(r.mean, r.varianceOfMean, 7.0);
            covered += e.relMseUpper >= r.trueRelMse;
            sumEstimate += e.relMse;
            sumOwnMean += ownMeanEstimate(r);
            sumTrue += r.trueRelMse;
        }
        EXPECT_GE(covered, int(0.95 * trials)) << spp << " spp";
        // Measured 2.2 and 1.7 (a pixel's firefly is half its value: the
        // denominator, the value without it, is that much smaller).
        EXPECT_GE(sumEstimate / sumTrue, 0.9) << spp << " spp: the estimate is biased low";
        EXPECT_LE(sumEstimate / sumTrue, 3.0) << spp << " spp: the estimate costs too many samples";
        EXPECT_LT(sumOwnMean / sumTrue, 0.5) << spp << " spp: measured 0.03 and 0.43";
    }
}

} // namespace
} // namespace vkrt::test

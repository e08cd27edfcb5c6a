// Error reporting: the variance-based estimate must track the true error, and
// the true error must fall as 1/spp (an unbiased, uncorrelated estimator).
#include "render/ErrorMetrics.h"
#include "render/Renderer.h"
#include "support/TestSupport.h"

#include <cmath>

namespace vkrt::test {
namespace {

/// Irradiance at p (normal n) from a polygon of unit radiance (Lambert's formula).
double polygonIrradiance(const glm::dvec3& p, const glm::dvec3& n, const std::vector<glm::dvec3>& v)
{
    double sum = 0.0;
    for (size_t i = 0; i < v.size(); ++i) {
        glm::dvec3 a = glm::normalize(v[i] - p), b = glm::normalize(v[(i + 1) % v.size()] - p);
        glm::dvec3 c = glm::cross(a, b);
        sum += std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0)) * glm::dot(n, c / glm::length(c));
    }
    return 0.5 * std::abs(sum);
}

const std::vector<glm::dvec3> kLight = {{-0.4, 1.5, -0.2}, {0.5, 1.3, 0.4}, {0.3, 1.6, -0.6}};

Scene lightOverFloor()
{
    return sceneFromText(R"(
[render]
integrator = "path"
max_depth = 1
[camera]
eye = [0, 1.0, 3]
target = [0, 0, 0]
fov = 40
width = 48
height = 36
[materials.floor]
type = "lambert"
albedo = 0.7
[[objects]]
shape = "plane"
point = [0, 0, 0]
normal = [0, 1, 0]
material = "floor"
[[lights]]
type = "triangle"
vertices = [[-0.4, 1.5, -0.2], [0.5, 1.3, 0.4], [0.3, 1.6, -0.6]]
radiance = [3, 2, 1]
two_sided = true
)");
}

/// The exact expected pixel values: the closed form averaged over each
/// pixel's area (the renderer's box filter) by a 12 x 12 midpoint rule.
Image exactImage(const Scene& scene)
{
    const Camera& c = scene.camera;
    glm::dvec3 forward = glm::normalize(c.target - c.eye), right = glm::normalize(glm::cross(forward, c.up));
    glm::dvec3 up = glm::cross(right, forward);
    double t = std::tan(c.fovY * M_PI / 360.0);
    Image image(c.width, c.height);
    constexpr int kGrid = 12;
    for (uint32_t y = 0; y < c.height; ++y)
        for (uint32_t x = 0; x < c.width; ++x) {
            double sum = 0.0;
            for (int j = 0; j < kGrid; ++j)
                for (int i = 0; i < kGrid; ++i) {
                    double fx = (x + (i + 0.5) / kGrid) / c.width, fy = (y + (j + 0.5) / kGrid) / c.height;
                    glm::dvec3 d =
                        glm::normalize((2 * fx - 1) * t * c.width / c.height * right + (1 - 2 * fy) * t * up + forward);
                    glm::dvec3 p = c.eye + (-c.eye.y / d.y) * d;
                    sum += 0.7 / M_PI * polygonIrradiance(p, {0, 1, 0}, kLight);
                }
            for (int k = 0; k < 3; ++k) image.at(x, y)[k] = float(sum / (kGrid * kGrid) * glm::dvec3(3, 2, 1)[k]);
        }
    return image;
}

class ConvergenceTest : public GpuTest {
protected:
    struct ErrorAtSpp {
        uint32_t spp;
        double trueMse;
        double estimatedMse;
    };

    /// True and estimated MSE of one progressive render at 1, 2, 4, ... 1024 spp.
    std::vector<ErrorAtSpp> errorsBySpp(bool sobol)
    {
        Scene scene = lightOverFloor();
        Image exact = exactImage(scene);
        RenderOptions options;
        options.variance = true;
        options.sobol = sobol;
        options.seed = 3;
        options.cacheDirectory = testCacheDir();
        Renderer renderer(gpu(), scene, options);
        std::vector<ErrorAtSpp> errors;
        for (uint32_t spp = 1; spp <= 1024; spp *= 2) {
            renderer.renderFrames(spp - renderer.completedFrames());
            Image mean = renderer.mean();
            errors.push_back(
                {spp, std::pow(measureError(mean, exact).rmse, 2),
                 std::pow(
                     estimateError(mean, renderer.varianceOfMean(), double(renderer.varianceDegreesOfFreedom())).rmse,
                     2)});
        }
        return errors;
    }
};

TEST_F(ConvergenceTest, EstimatedErrorTracksTrueErrorAndMseFallsAsOneOverSpp)
{
    std::vector<double> logSpp, logMse;
    for (const ErrorAtSpp& e : errorsBySpp(false)) {
        if (e.spp >= 16) {
            EXPECT_NEAR(e.estimatedMse / e.trueMse, 1.0, 0.25) << "spp " << e.spp;
        }
        if (e.spp >= 4) logSpp.push_back(std::log(double(e.spp))), logMse.push_back(std::log(e.trueMse));
    }
    double n = double(logSpp.size()), sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (size_t i = 0; i < logSpp.size(); ++i)
        sx += logSpp[i], sy += logMse[i], sxx += logSpp[i] * logSpp[i], sxy += logSpp[i] * logMse[i];
    double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
    EXPECT_NEAR(slope, -1.0, 0.1);
}

// Under the Sobol' sampler the frames of a pixel are correlated, so their
// spread overstates the error of the mean (here by orders of magnitude); the
// estimate from independently scrambled batches must track the true error
// instead, while the image keeps a large part of the sampler's gain.
TEST_F(ConvergenceTest, SobolBatchVarianceTracksTrueError)
{
    std::vector<ErrorAtSpp> sobol = errorsBySpp(true), independent = errorsBySpp(false);
    for (const ErrorAtSpp& e : sobol) {
        if (e.spp < gpu::VARIANCE_BATCHES) {
            EXPECT_TRUE(std::isinf(e.estimatedMse)) << "spp " << e.spp << ": a batch without samples";
        } else if (e.spp >= 2 * gpu::VARIANCE_BATCHES) {
            EXPECT_NEAR(e.estimatedMse / e.trueMse, 1.0, 0.25) << "spp " << e.spp;
        }
    }
    double gain = independent.back().trueMse / sobol.back().trueMse;
    reportStat("sobol_batched_mse_gain_at_1024spp", gain);
    EXPECT_GT(gain, 4.0) << "batched Sobol' at 1024 spp should still beat independent samples clearly";
}

TEST(ErrorMetrics, KnownValues)
{
    Image a(2, 1), b(2, 1);
    a.rgb = {1, 2, 3, 4, 5, 6};
    b.rgb = {1, 2, 3, 4, 5, 8};
    MeasuredError e = measureError(a, b);
    EXPECT_DOUBLE_EQ(e.rmse, std::sqrt(4.0 / 6.0));
    EXPECT_DOUBLE_EQ(e.relMse, 4.0 / (64.0 + kRelMseEpsilon) / 6.0);
    EXPECT_DOUBLE_EQ(e.mape, 2.0 / (8.0 + kRelMseEpsilon) / 6.0);
    EXPECT_DOUBLE_EQ(e.maxAbs, 2.0);
    a.rgb[0] = NAN;
    EXPECT_EQ(measureError(a, b).nonFiniteA, 1u);
    EXPECT_EQ(measureError(a, b).compared, 5u);
    EXPECT_NEAR(normalQuantileTwoSided(0.05), 1.959964, 1e-5);
    EXPECT_NEAR(normalQuantileTwoSided(0.01), 2.575829, 1e-5);
}

// Student's t against tabulated quantiles, and the Welch test's degrees of
// freedom: two variances of 7 each, equal, give 14.
TEST(ErrorMetrics, StudentTailAndWelchDegreesOfFreedom)
{
    EXPECT_NEAR(studentTwoSidedTail(2.364624, 7.0), 0.05, 1e-6);
    EXPECT_NEAR(studentTwoSidedTail(-3.499483, 7.0), 0.01, 1e-6);
    EXPECT_NEAR(studentTwoSidedTail(12.706205, 1.0), 0.05, 1e-6);
    EXPECT_NEAR(studentTwoSidedTail(1.959964, INFINITY), 0.05, 1e-6);
    EXPECT_EQ(studentTwoSidedTail(INFINITY, 7.0), 0.0);

    // One value, difference t * sqrt(2) with unit variances: p is the t tail.
    Image a(1, 1), b(1, 1), unit(1, 1);
    unit.rgb = {1, 1, 1};
    b.rgb = {0, 0, 0};
    a.rgb = {float(2.144787 * std::sqrt(2.0)), 0, 0}; // t_{0.975} with 14 degrees of freedom
    PixelTestSummary welch = pixelZTest(a, unit, b, unit, 0.01, 7.0, 7.0);
    EXPECT_NEAR(welch.minPValue, 0.05, 1e-5);
    PixelTestSummary z = pixelZTest(a, unit, b, unit, 0.01);
    EXPECT_NEAR(z.minPValue, std::erfc(2.144787 / std::sqrt(2.0)), 1e-6); // the normal tail, smaller
    EXPECT_EQ(welch.passed, 3u);
}

} // namespace
} // namespace vkrt::test

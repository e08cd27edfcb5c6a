// Progressive accumulation: compensated sums, non-finite rejection, the loop
// budget counter and determinism, checked through the real kernels.
#include "render/Renderer.h"
#include "shared/Bindings.h"
#include "support/TestSupport.h"

#include <cmath>

namespace vkrt::test {
namespace {

RenderOptions testOptions(uint32_t seed = 0)
{
    RenderOptions options;
    options.seed = seed;
    options.cacheDirectory = testCacheDir();
    return options;
}

std::string emptySceneWithBackground(const std::string& colour, int width, int height)
{
    return "[camera]\neye = [0,0,0]\ntarget = [0,0,-1]\nfov = 60\nwidth = " + std::to_string(width) +
           "\nheight = " + std::to_string(height) + "\n[background]\ncolor = " + colour + "\n";
}

class AccumulationTest : public GpuTest {};

// 4096 additions of 0.1f: a plain float32 running sum drifts by about 1e-4
// relative; Kahan summation (kept by `precise`) stays within float rounding.
TEST_F(AccumulationTest, CompensatedSumKeepsTheMeanExact)
{
    Scene scene = sceneFromText(emptySceneWithBackground("[0.1, 0.3, 0.7]", 8, 8));
    Renderer renderer(gpu(), scene, testOptions());
    renderer.renderFrames(4096);
    Image image = renderer.mean();
    const double expected[3] = {double(0.1f), double(0.3f), double(0.7f)};
    for (size_t i = 0; i < image.pixelCount(); ++i)
        for (int c = 0; c < 3; ++c) ASSERT_NEAR(image.rgb[i * 3 + c], expected[c], expected[c] * 1e-6) << "pixel " << i;
}

// The test hook poisons every 7th pixel with NaN: those samples must be
// counted, never accumulated, and the other pixels must be untouched.
TEST_F(AccumulationTest, NonFiniteSamplesAreRejectedAndCounted)
{
    Scene scene = sceneFromText(emptySceneWithBackground("0.5", 16, 16));
    RenderOptions options = testOptions();
    options.extraDefines = {{"VKRT_TEST_INJECT_NONFINITE", "1"}};
    Renderer renderer(gpu(), scene, options);
    renderer.renderFrames(5);
    Image image = renderer.mean();
    uint64_t poisoned = 0;
    for (size_t i = 0; i < image.pixelCount(); ++i) {
        bool hit = i % 7 == 0;
        poisoned += hit;
        for (int c = 0; c < 3; ++c) ASSERT_EQ(image.rgb[i * 3 + c], hit ? 0.0f : 0.5f) << "pixel " << i;
    }
    EXPECT_EQ(renderer.counters().rejectedSamples, poisoned * 5);
}

// Samples alternating between c and c + 1 have sample variance n / (4 (n - 1)).
// With c = 1e4 the textbook E[x^2] - E[x]^2 in float32 loses every digit;
// Welford's update with a compensated m2 keeps the variance within 1 %.
TEST_F(AccumulationTest, VarianceOfTheMeanIsAccurateOnALargeOffset)
{
    for (const char* offset : {"0.0", "10000.0"}) {
        Scene scene = sceneFromText(emptySceneWithBackground("0", 8, 8));
        RenderOptions options = testOptions();
        options.variance = true;
        options.extraDefines = {{"VKRT_TEST_ALTERNATING_SAMPLES", offset}};
        Renderer renderer(gpu(), scene, options);
        const uint32_t n = 1000;
        renderer.renderFrames(n);
        Image mean = renderer.mean(), variance = renderer.varianceOfMean();
        double expectedVarianceOfMean = double(n) / (4.0 * (n - 1)) / n;
        for (size_t i = 0; i < variance.rgb.size(); ++i) {
            ASSERT_NEAR(mean.rgb[i], std::stod(offset) + 0.5, 1e-6 * (std::stod(offset) + 1)) << offset;
            ASSERT_NEAR(variance.rgb[i], expectedVarianceOfMean, 0.01 * expectedVarianceOfMean) << offset;
        }
    }
}

TEST_F(AccumulationTest, VarianceNeedsTwoSamples)
{
    Scene scene = sceneFromText(emptySceneWithBackground("0.5", 4, 4));
    RenderOptions options = testOptions();
    options.variance = true;
    Renderer renderer(gpu(), scene, options);
    renderer.renderFrames(1);
    for (float v : renderer.varianceOfMean().rgb) EXPECT_TRUE(std::isinf(v));
    renderer.renderFrames(1);
    for (float v : renderer.varianceOfMean().rgb) EXPECT_EQ(v, 0.0f);
}

TEST_F(AccumulationTest, CleanRenderRejectsNothing)
{
    Scene scene = sceneFromText(emptySceneWithBackground("0.5", 16, 16));
    Renderer renderer(gpu(), scene, testOptions());
    renderer.renderFrames(3);
    EXPECT_EQ(renderer.counters().rejectedSamples, 0u);
}

// With max_depth = 1 a lit surface pixel runs one depth-loop step, 3
// primitive tests for the camera ray, then one light-loop step and 3
// primitive tests for the shadow ray: 8 iterations.
TEST_F(AccumulationTest, LoopCounterMatchesWorstCase)
{
    Scene scene = sceneFromText(R"(
[render]
max_depth = 1
[camera]
eye = [0, 1, 4]
target = [0, 0, 0]
fov = 60
width = 32
height = 24
[materials.m]
type = "lambert"
[[objects]]
shape = "plane"
point = [0, 0, 0]
normal = [0, 1, 0]
material = "m"
[[objects]]
shape = "sphere"
center = [0, 0.5, 0]
radius = 0.5
material = "m"
[[objects]]
shape = "box"
min = [1, 0, -1]
max = [1.5, 0.5, -0.5]
material = "m"
[[lights]]
type = "point"
position = [0, 3, 0]
intensity = 5
)");
    Renderer renderer(gpu(), scene, testOptions());
    renderer.renderFrames(2);
    RenderCounters counters = renderer.counters();
    EXPECT_EQ(counters.maxLoopIterations, worstCaseLoopIterations(scene));
    EXPECT_EQ(counters.maxLoopIterations, 8u);
    EXPECT_EQ(counters.budgetExceeded, 0u);
}

TEST_F(AccumulationTest, SameSeedSameBitsDifferentSeedDifferentNoise)
{
    Scene scene = sceneFromText(R"(
[camera]
eye = [0, 1, 4]
target = [0, 0.5, 0]
fov = 40
width = 40
height = 30
[materials.m]
type = "lambert"
[[objects]]
shape = "sphere"
center = [0, 0.5, 0]
radius = 0.8
material = "m"
[[lights]]
type = "point"
position = [2, 3, 2]
intensity = 8
)");
    auto render = [&](uint32_t seed) {
        Renderer renderer(gpu(), scene, testOptions(seed));
        renderer.renderFrames(3);
        return renderer.mean();
    };
    Image a = render(11), b = render(11), c = render(12);
    EXPECT_EQ(a.rgb, b.rgb);
    EXPECT_NE(a.rgb, c.rgb);
}

} // namespace
} // namespace vkrt::test

// Several samples per invocation (path regeneration, RenderOptions::
// samplesPerInvocation): every frame of a batch is rendered exactly once and
// in order, so the image is the same for any count, batches of any length and
// any first frame (a shard's start).
#include "gpu/LoopCap.h"
#include "render/Renderer.h"
#include "scene/SceneParser.h"
#include "support/TestSupport.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

namespace vkrt::test {
namespace {

namespace fs = std::filesystem;

class PathRegenerationTest : public GpuTest {};

RenderOptions optionsWith(uint32_t samplesPerInvocation, uint32_t firstFrame = 0)
{
    RenderOptions options;
    options.seed = 5;
    options.samplesPerInvocation = samplesPerInvocation;
    options.firstFrame = firstFrame;
    options.cacheDirectory = testCacheDir();
    return options;
}

std::string alternatingScene(const std::string& integrator)
{
    return "[render]\nintegrator = \"" + integrator +
           "\"\n[camera]\neye = [0,0,0]\ntarget = [0,0,-1]\nfov = 60\nwidth = 20\nheight = 12\n"
           "[background]\ncolor = 0\n";
}

Scene shippedScene(const std::string& relative)
{
    return parseSceneFile((fs::path(VKRT_TEST_SOURCE_DIR) / "scenes" / relative).string());
}

// The hook makes frame f's sample c + (f & 1): after frames [first, first + n)
// every pixel's mean is c plus the share of odd frames, which any skipped or
// repeated frame would change.
TEST_F(PathRegenerationTest, EveryFrameOfEveryBatchIsRenderedOnce)
{
    for (const char* integrator : {"path", "whitted"}) {
        Scene scene = sceneFromText(alternatingScene(integrator));
        for (uint32_t perInvocation : {1u, 3u, 8u}) {
            for (uint32_t first : {0u, 3u}) {
                RenderOptions options = optionsWith(perInvocation, first);
                options.extraDefines = {{"VKRT_TEST_ALTERNATING_SAMPLES", "2.0"}};
                Renderer renderer(gpu(), scene, options);
                renderer.renderFrames(5); // batches shorter and longer than perInvocation
                renderer.renderFrames(1);
                renderer.renderFrames(13);
                uint32_t odd = 0;
                for (uint32_t f = first; f < first + 19; ++f) odd += f & 1u;
                float expected = 2.0f + float(odd) / 19.0f;
                Image mean = renderer.mean();
                for (size_t i = 0; i < mean.rgb.size(); ++i)
                    ASSERT_NEAR(mean.rgb[i], expected, 1e-6f)
                        << integrator << ", " << perInvocation << " per invocation, first frame " << first;
                EXPECT_EQ(renderer.completedFrames(), 19u);
            }
        }
    }
}

// Real paths of different lengths, with both samplers and both variance
// estimates: the sums, and so the images, are bit for bit those of one
// sample per invocation.
TEST_F(PathRegenerationTest, ImageIsTheSameForAnySamplesPerInvocation)
{
    for (const char* relative : {"validation/glass.toml", "validation/mesh-cornell.toml", "seed/glass.toml"}) {
        Scene scene = shippedScene(relative);
        scene.camera.width = 24;
        scene.camera.height = 16;
        for (bool sobol : {false, true}) {
            auto render = [&](uint32_t perInvocation) {
                RenderOptions options = optionsWith(perInvocation);
                options.sobol = sobol;
                options.variance = true;
                Renderer renderer(gpu(), scene, options);
                renderer.renderFrames(7);
                renderer.renderFrames(10);
                return std::pair(renderer.mean(), renderer.varianceOfMean());
            };
            auto [mean1, variance1] = render(1);
            for (uint32_t perInvocation : {4u, 8u}) {
                auto [mean, variance] = render(perInvocation);
                EXPECT_EQ(mean.rgb, mean1.rgb) << relative << ", sobol " << sobol << ", " << perInvocation;
                EXPECT_EQ(variance.rgb, variance1.rgb) << relative << ", sobol " << sobol << ", " << perInvocation;
            }
        }
    }
}

// A cubemap lookup is the exception: lavapipe's cube sampling rounds a
// direction differently depending on which other invocations share its
// 8-lane vector (measured: ulps apart on environment-sky), so the image
// agrees to float rounding, not bit for bit, across samples per invocation.
TEST_F(PathRegenerationTest, CubemapImagesAgreeToRoundingForAnySamplesPerInvocation)
{
    Scene scene = shippedScene("validation/environment-sky.toml");
    scene.camera.width = 24;
    scene.camera.height = 16;
    auto render = [&](uint32_t perInvocation) {
        Renderer renderer(gpu(), scene, optionsWith(perInvocation));
        renderer.renderFrames(9);
        return renderer.mean();
    };
    Image one = render(1), sixteen = render(16);
    double largest = 0.0;
    for (size_t i = 0; i < one.rgb.size(); ++i) {
        ASSERT_TRUE(std::isfinite(one.rgb[i]) && one.rgb[i] >= 0.0f);
        largest = std::max(largest, double(std::abs(one.rgb[i] - sixteen.rgb[i])) / std::max(1.0f, one.rgb[i]));
    }
    std::printf("[ measured ] environment-sky, 1 vs 16 samples per invocation: largest difference %.3g\n", largest);
    EXPECT_LT(largest, 1e-6);
}

// On a device that caps an invocation's loop passes in total, several samples
// would share one budget: one per invocation there.
TEST(SamplesPerInvocation, OneWhereTheDeviceCapsLoops)
{
    LoopCap capped{65535, "probe"};
    EXPECT_EQ(samplesPerInvocationFor(capped), 1u);
    EXPECT_GT(samplesPerInvocationFor(LoopCap{}), 1u);
}

} // namespace
} // namespace vkrt::test

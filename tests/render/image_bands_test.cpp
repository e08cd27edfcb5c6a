// Images rendered in bands (render/ImageBands.h): when the per-pixel buffers
// would exceed maxStorageBufferRange each band has buffers of its own rows,
// and every workgroup sees the same pixels as in one band, so mean, variance,
// tally and counters are bit for bit those of one unbanded render.
#include "render/Renderer.h"
#include "scene/SceneParser.h"
#include "support/TestSupport.h"

#include <filesystem>

namespace vkrt::test {
namespace {

namespace fs = std::filesystem;

class ImageBandsTest : public GpuTest {};

Scene shippedScene(const std::string& relative, uint32_t width, uint32_t height)
{
    Scene scene = parseSceneFile((fs::path(VKRT_TEST_SOURCE_DIR) / "scenes" / relative).string());
    scene.camera.width = width;
    scene.camera.height = height;
    return scene;
}

struct Rendered {
    uint32_t bands = 0;
    Image mean, variance;
    Tally tally;
    uint64_t rejected = 0;
};

enum class Estimate { None, Welford, SobolBatches };

RenderOptions optionsFor(Estimate estimate, uint64_t maxBandBytes)
{
    RenderOptions options;
    options.seed = 11;
    options.cacheDirectory = testCacheDir();
    options.variance = estimate != Estimate::None;
    options.sobol = estimate == Estimate::SobolBatches;
    options.maxBandBytes = maxBandBytes;
    return options;
}

Rendered render(const VulkanContext& context, const Scene& scene, const RenderOptions& options)
{
    Renderer renderer(context, scene, options);
    renderer.renderFrames(5);
    renderer.renderFrames(12);
    Rendered r{renderer.bands().count, renderer.mean(), {}, renderer.tally(), renderer.counters().rejectedSamples};
    if (options.variance) r.variance = renderer.varianceOfMean();
    return r;
}

void expectSameImages(const Rendered& banded, const Rendered& whole, const std::string& what)
{
    EXPECT_EQ(banded.mean.rgb, whole.mean.rgb) << what;
    EXPECT_EQ(banded.variance.rgb, whole.variance.rgb) << what;
    EXPECT_EQ(banded.tally.count.rgb, whole.tally.count.rgb) << what;
    EXPECT_EQ(banded.tally.mean.rgb, whole.tally.mean.rgb) << what;
    ASSERT_EQ(banded.tally.m2.has_value(), whole.tally.m2.has_value()) << what;
    if (whole.tally.m2) {
        EXPECT_EQ(banded.tally.m2->rgb, whole.tally.m2->rgb) << what;
    }
    ASSERT_EQ(banded.tally.batchMean.size(), whole.tally.batchMean.size()) << what;
    for (size_t b = 0; b < whole.tally.batchMean.size(); ++b)
        EXPECT_EQ(banded.tally.batchMean[b].rgb, whole.tally.batchMean[b].rgb) << what << ", batch " << b;
    EXPECT_EQ(banded.rejected, whole.rejected) << what;
}

// 40 x 30 pixels in bands of 8 rows: four bands, the last 6 rows tall (its
// last workgroup row reaches past the image). Path and Whitted integrators,
// meshes (the two-level BVH) and a cubemap, whose lookups round by which
// lanes share a vector: any change of the workgroups would show there first.
TEST_F(ImageBandsTest, BandedImagesAreBitIdenticalToOneBand)
{
    const uint32_t width = 40, height = 30;
    for (const char* relative : {"validation/glass.toml", "seed/glass.toml", "validation/mesh-cornell.toml",
                                 "validation/environment-sky.toml"}) {
        Scene scene = shippedScene(relative, width, height);
        for (Estimate estimate : {Estimate::None, Estimate::Welford, Estimate::SobolBatches}) {
            uint64_t bytesPerPixel = sizeof(gpu::AccumPixel);
            if (estimate != Estimate::None)
                bytesPerPixel =
                    std::max<uint64_t>(bytesPerPixel, varianceBytesPerPixel(estimate == Estimate::SobolBatches));
            // 12 rows' worth rounds down to bands of 8 rows (whole workgroups).
            const uint64_t maxBandBytes = width * 12 * bytesPerPixel;
            std::string what = std::string(relative) + ", estimate " + std::to_string(int(estimate));
            Rendered whole = render(gpu(), scene, optionsFor(estimate, 0));
            Rendered banded = render(gpu(), scene, optionsFor(estimate, maxBandBytes));
            ASSERT_EQ(whole.bands, 1u) << what;
            ASSERT_EQ(banded.bands, 4u) << what;
            expectSameImages(banded, whole, what);
        }
    }
}

// Test hooks that depend on the pixel index (every 7th pixel non-finite) see
// the image's index, not the band's: the same pixels are rejected.
TEST_F(ImageBandsTest, PixelIndexIsTheImagesInEveryBand)
{
    Scene scene = shippedScene("validation/diffuse-box.toml", 24, 20);
    RenderOptions whole = optionsFor(Estimate::Welford, 0), banded = optionsFor(Estimate::Welford, 24 * 8 * 36);
    whole.extraDefines = banded.extraDefines = {{"VKRT_TEST_INJECT_NONFINITE", "1"}};
    Rendered a = render(gpu(), scene, whole), b = render(gpu(), scene, banded);
    ASSERT_EQ(b.bands, 3u);
    EXPECT_GT(a.rejected, 0u);
    expectSameImages(b, a, "non-finite hook");
}

// A camera move re-makes the scene camera-relative; the band layout (and so
// each band's tile count) stays.
TEST_F(ImageBandsTest, MovedCameraStaysBitIdentical)
{
    Scene scene = shippedScene("validation/mesh-cornell.toml", 32, 20);
    Camera moved = scene.camera;
    moved.eye += glm::dvec3(0.05, 0.02, 0.0);
    auto renderMoved = [&](uint64_t maxBandBytes) {
        Renderer renderer(gpu(), scene, optionsFor(Estimate::None, maxBandBytes));
        renderer.renderFrames(3);
        renderer.moveCamera(moved);
        renderer.renderFrames(6);
        EXPECT_EQ(renderer.completedFrames(), 6u);
        return std::pair(renderer.bands().count, renderer.mean());
    };
    auto [oneBand, whole] = renderMoved(0);
    auto [threeBands, banded] = renderMoved(32 * 8 * sizeof(gpu::AccumPixel));
    EXPECT_EQ(oneBand, 1u);
    EXPECT_EQ(threeBands, 3u);
    EXPECT_EQ(banded.rgb, whole.rgb);
}

} // namespace
} // namespace vkrt::test

// The staged kernels (render --staged, lib/stages.glsl): the path integrator
// as a trace and a shade kernel that take turns. They do the megakernel's
// arithmetic in its order, so the sums, and so the images, their variance
// and the AOVs, are the megakernel's bit for bit, for runs of any length.
#include "render/Renderer.h"
#include "scene/SceneParser.h"
#include "support/TestSupport.h"

#include <filesystem>

namespace vkrt::test {
namespace {

namespace fs = std::filesystem;

class StagedKernelsTest : public GpuTest {};

Scene shippedScene(const std::string& relative)
{
    Scene scene = parseSceneFile((fs::path(VKRT_TEST_SOURCE_DIR) / "scenes" / relative).string());
    scene.camera.width = 24;
    scene.camera.height = 16;
    return scene;
}

struct Rendered {
    Image mean, variance;
    std::optional<AovImages> aovs;
    uint32_t frames = 0;
};

Rendered render(const Scene& scene, bool staged, bool sobol, bool aov)
{
    RenderOptions options;
    options.seed = 11;
    options.staged = staged;
    options.sobol = sobol;
    options.variance = true;
    options.aov = aov;
    options.cacheDirectory = testCacheDir();
    Renderer renderer(gpu(), scene, options);
    renderer.warmUp();
    renderer.renderFrames(7); // runs of different lengths, the second starting where the first ended
    renderer.renderFrames(10);
    Rendered r{renderer.mean(), renderer.varianceOfMean(), std::nullopt, renderer.completedFrames()};
    if (aov) r.aovs = renderer.aovs();
    return r;
}

// Glass (media, total internal reflection) on a mesh with vkrt's BVH, a mesh
// with the driver's ray queries, and an environment map, with both samplers
// (independent samples: Welford moments; Sobol': batch sums).
TEST_F(StagedKernelsTest, ImagesAreTheMegakernelsBitForBit)
{
    for (const char* relative :
         {"validation/mesh-bunny-glass.toml", "validation/mesh-cornell.toml", "validation/environment-hdri.toml"}) {
        Scene scene = shippedScene(relative);
        for (bool sobol : {true, false}) {
            Rendered mega = render(scene, false, sobol, false), staged = render(scene, true, sobol, false);
            EXPECT_EQ(staged.frames, 17u);
            EXPECT_EQ(staged.mean.rgb, mega.mean.rgb) << relative << ", sobol " << sobol;
            EXPECT_EQ(staged.variance.rgb, mega.variance.rgb) << relative << ", sobol " << sobol;
            if (relative != std::string("validation/mesh-bunny-glass.toml")) break; // one sampler suffices there
        }
    }
}

TEST_F(StagedKernelsTest, AovsAreTheMegakernelsBitForBit)
{
    Scene scene = shippedScene("validation/textured.toml");
    Rendered mega = render(scene, false, true, true), staged = render(scene, true, true, true);
    EXPECT_EQ(staged.mean.rgb, mega.mean.rgb);
    EXPECT_EQ(staged.aovs->albedo.rgb, mega.aovs->albedo.rgb);
    EXPECT_EQ(staged.aovs->normal.rgb, mega.aovs->normal.rgb);
    EXPECT_EQ(staged.aovs->position.rgb, mega.aovs->position.rgb);
    EXPECT_EQ(staged.aovs->depth, mega.aovs->depth);
}

TEST_F(StagedKernelsTest, WhittedScenesAreRefused)
{
    Scene scene = shippedScene("seed/glass.toml");
    RenderOptions options;
    options.staged = true;
    options.cacheDirectory = testCacheDir();
    std::string message = inputErrorOf([&] { Renderer renderer(gpu(), scene, options); });
    EXPECT_NE(message.find("--staged runs the path integrator only"), std::string::npos) << message;
}

} // namespace
} // namespace vkrt::test

// Kernel variants: a scene's kernel holds only the code its features need,
// and gives the same image as the all-features ("uber") kernel.
#include "render/Renderer.h"
#include "scene/SceneParser.h"
#include "shared/Bindings.h"
#include "support/TestSupport.h"

namespace fs = std::filesystem;

namespace vkrt::test {
namespace {

constexpr uint32_t kOpName = 5, kOpDecorate = 71, kDecorationBinding = 33;

struct SpirvSummary {
    bool refract = false; ///< the kernel defines lib/fresnel.glsl's refractDirection
    std::set<uint32_t> bindings;
};

/// Walks the SPIR-V instruction stream (word count in the high 16 bits).
SpirvSummary summarize(const std::vector<uint32_t>& spirv)
{
    SpirvSummary summary;
    for (size_t i = 5; i < spirv.size();) {
        uint32_t words = spirv[i] >> 16, opcode = spirv[i] & 0xffff;
        if (words == 0) break;
        if (opcode == kOpName && words >= 3) {
            std::string name(reinterpret_cast<const char*>(&spirv[i + 2]), (words - 2) * 4);
            if (name.rfind("refractDirection(", 0) == 0) summary.refract = true;
        }
        if (opcode == kOpDecorate && words >= 4 && spirv[i + 2] == kDecorationBinding)
            summary.bindings.insert(spirv[i + 3]);
        i += words;
    }
    return summary;
}

RenderOptions options(bool uber)
{
    RenderOptions o;
    o.uber = uber;
    o.seed = 5;
    o.cacheDirectory = testCacheDir();
    return o;
}

Scene shippedScene(const std::string& relative)
{
    // A path, not `std::string + "..."`: GCC 14 reports a false -Warray-bounds there at -O2.
    Scene scene = parseSceneFile((fs::path(VKRT_TEST_SOURCE_DIR) / "scenes" / relative).string());
    scene.camera.width = 40, scene.camera.height = 30;
    return scene;
}

class VariantTest : public GpuTest {};

TEST_F(VariantTest, SpecializedAndUberKernelsGiveIdenticalImages)
{
    for (const char* name : {"seed/baseline.toml", "seed/glass.toml", "seed/area-light.toml",
                             "seed/glass-area-light.toml", "default.toml"}) {
        Scene scene = shippedScene(name);
        Renderer specialized(gpu(), scene, options(false)), uber(gpu(), scene, options(true));
        specialized.renderFrames(2);
        uber.renderFrames(2);
        EXPECT_NE(specialized.kernel().cacheKey, uber.kernel().cacheKey) << name;
        Image a = specialized.mean(), b = uber.mean();
        size_t differing = 0;
        double worst = 0.0;
        for (size_t i = 0; i < a.rgb.size(); ++i) {
            if (a.rgb[i] == b.rgb[i]) continue;
            ++differing;
            worst =
                std::max(worst, std::abs(double(a.rgb[i]) - b.rgb[i]) / std::max(1e-30, std::abs(double(b.rgb[i]))));
        }
        EXPECT_EQ(differing, 0u) << name << ": worst relative difference " << worst;
    }
}

// Scene arrays in uniform buffers (the fast path on lavapipe) hold the same
// records as storage buffers: the images must be bit-identical.
TEST_F(VariantTest, UniformAndStorageSceneDataGiveIdenticalImages)
{
    for (const char* name : {"default.toml", "seed/baseline.toml"}) {
        Scene scene = shippedScene(name);
        RenderOptions storage = options(false);
        storage.storageScene = true;
        Renderer a(gpu(), scene, options(false)), b(gpu(), scene, storage);
        EXPECT_TRUE(a.variant().uniformScene) << name;
        EXPECT_FALSE(b.variant().uniformScene) << name;
        a.renderFrames(2);
        b.renderFrames(2);
        EXPECT_EQ(a.mean().rgb, b.mean().rgb) << name;
    }
}

// More spheres than a 16 KiB uniform block holds: the storage variant is
// chosen, and the sphere past the uniform capacity is still rendered.
TEST_F(VariantTest, SceneTooBigForUniformBuffersUsesStorageBuffers)
{
    Scene scene = shippedScene("seed/baseline.toml");
    Sphere last = scene.spheres.front();
    while (scene.spheres.size() <= gpu::UNIFORM_SPHERES) {
        Sphere hidden = last;
        hidden.center = glm::dvec3(0.0, -1e6, 0.0); // far below the floor, out of view
        hidden.radius = 1.0;
        scene.spheres.push_back(hidden);
    }
    scene.spheres.push_back(last); // the visible sphere again, as the very last record
    scene.spheres.front().center.y -= 1e6;
    EXPECT_FALSE(sceneFitsUniformBuffers(scene));
    Scene small = shippedScene("seed/baseline.toml");
    Renderer big(gpu(), scene, options(false)), reference(gpu(), small, options(false));
    EXPECT_FALSE(big.variant().uniformScene);
    big.renderFrames(1);
    reference.renderFrames(1);
    // The hidden spheres never win a closest hit and the same spheres are
    // visible, so the same seed gives the same image bit for bit.
    EXPECT_EQ(big.mean().rgb, reference.mean().rgb) << "the moved sphere must still be drawn from the last record";
}

TEST_F(VariantTest, SceneWithoutGlassHasNoRefractionCode)
{
    Scene scene = shippedScene("seed/baseline.toml");
    Renderer specialized(gpu(), scene, options(false)), uber(gpu(), scene, options(true));
    auto defines = describeDefines(specialized.variant().defines());
    EXPECT_EQ(defines.find("VKRT_MATERIAL_DIELECTRIC"), std::string::npos) << defines;
    EXPECT_FALSE(summarize(specialized.kernel().spirv).refract);
    EXPECT_TRUE(summarize(uber.kernel().spirv).refract);
    EXPECT_LT(specialized.kernel().spirv.size(), uber.kernel().spirv.size());
}

TEST_F(VariantTest, GlassSceneHasRefractionCode)
{
    Renderer renderer(gpu(), shippedScene("seed/glass.toml"), options(false));
    EXPECT_TRUE(summarize(renderer.kernel().spirv).refract);
}

TEST_F(VariantTest, UnusedLightsAndCubemapHaveNoBindings)
{
    Scene scene = shippedScene("seed/baseline.toml"); // point light, cubemap
    scene.background.cubemap.reset();
    Renderer specialized(gpu(), scene, options(false)), uber(gpu(), scene, options(true));
    auto used = summarize(specialized.kernel().spirv).bindings;
    EXPECT_FALSE(used.count(gpu::BINDING_TRIANGLE_LIGHTS));
    EXPECT_FALSE(used.count(gpu::BINDING_ENVIRONMENT));
    EXPECT_TRUE(used.count(gpu::BINDING_POINT_LIGHTS));
    auto all = summarize(uber.kernel().spirv).bindings;
    EXPECT_TRUE(all.count(gpu::BINDING_TRIANGLE_LIGHTS));
    EXPECT_TRUE(all.count(gpu::BINDING_ENVIRONMENT));
    // The descriptor set layout holds exactly what the module declares.
    auto layout = specialized.variant().bindings();
    EXPECT_EQ(std::set<uint32_t>(layout.begin(), layout.end()), used);

    Renderer area(gpu(), shippedScene("seed/area-light.toml"), options(false));
    auto areaBindings = summarize(area.kernel().spirv).bindings;
    EXPECT_TRUE(areaBindings.count(gpu::BINDING_TRIANGLE_LIGHTS));
    EXPECT_FALSE(areaBindings.count(gpu::BINDING_POINT_LIGHTS));
    EXPECT_TRUE(areaBindings.count(gpu::BINDING_ENVIRONMENT));
}

TEST(FeatureSetTest, ReflectsExactlyWhatTheSceneUses)
{
    Scene scene = sceneFromText(R"(
[camera]
eye = [0, 0, 5]
target = [0, 0, 0]
fov = 40
[materials.used]
type = "glossy"
[materials.unused]
type = "dielectric"
[[objects]]
shape = "triangle"
vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
material = "used"
[[lights]]
type = "triangle"
vertices = [[0, 2, 0], [1, 2, 0], [0, 2, 1]]
radiance = 1
)");
    FeatureSet f = featuresOf(scene);
    EXPECT_TRUE(f.has(ShapeKind::Triangle) && f.has(LightKind::TriangleLight));
    EXPECT_FALSE(f.has(ShapeKind::Sphere) || f.has(ShapeKind::Box) || f.has(ShapeKind::Plane) ||
                 f.has(LightKind::PointLight) || f.cubemap);
    EXPECT_TRUE(f.has(MaterialType::Glossy));
    EXPECT_FALSE(f.has(MaterialType::Dielectric)) << "an unused material must not pull in its code";
    KernelVariant v{f};
    v.uniformScene = sceneFitsUniformBuffers(scene);
    EXPECT_EQ(v.describe(), "whitted; triangles triangle-lights emitters; glossy; uniform-scene");
    EXPECT_TRUE(v.uniformScene) << "a small scene's arrays fit uniform buffers";
    EXPECT_TRUE(v.isUniformBinding(gpu::BINDING_TRIANGLES));
    EXPECT_TRUE(v.isUniformBinding(gpu::BINDING_MATERIALS));
    EXPECT_FALSE(v.isUniformBinding(gpu::BINDING_ACCUMULATION));
    v.uniformScene = false;
    EXPECT_FALSE(v.isUniformBinding(gpu::BINDING_TRIANGLES));
}

TEST(InfoCli, PrintsVariantAndCacheState)
{
    fs::path dir = freshTempDir("info-cli");
    setenv("VKRT_CACHE_DIR", (dir / "cache").c_str(), 1);
    std::string scene = (fs::path(VKRT_TEST_SOURCE_DIR) / "scenes/seed/baseline.toml").string();
    ProcessResult cold = runVkrt({"info", scene});
    ProcessResult warm = runVkrt({"info", scene});
    unsetenv("VKRT_CACHE_DIR");
    ASSERT_EQ(cold.exitCode, 0) << cold.output;
    ASSERT_EQ(warm.exitCode, 0) << warm.output;
    EXPECT_NE(cold.output.find("features:       whitted; spheres boxes triangles planes point-lights cubemap;"),
              std::string::npos)
        << cold.output;
    EXPECT_NE(cold.output.find("spirv bytes:"), std::string::npos);
    EXPECT_NE(cold.output.find("loop cap:       " + gpu().loopCap().describe()), std::string::npos) << cold.output;
    EXPECT_EQ(cold.output.find("cache hit"), std::string::npos) << cold.output;
    EXPECT_NE(warm.output.find("cache hit"), std::string::npos) << warm.output;
}

} // namespace
} // namespace vkrt::test

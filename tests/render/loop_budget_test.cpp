// The loop-budget guard follows the device: where the driver silently cuts
// long loops short (Mesa < 25 lavapipe) a scene that could reach the cap is
// refused before anything renders; where it does not, the same scene renders,
// and renders right. ctest runs these tests on the default driver and again on
// Debian 12's stock Mesa 22 lavapipe (tests/CMakeLists.txt, old-lavapipe).
// The rule itself, without a device, is tested in loop_cap_rule_test.cpp.
#include "gpu/LoopCap.h"
#include "mesh/MeshData.h"
#include "mesh/Procedural.h"
#include "render/Renderer.h"
#include "shared/Bindings.h"
#include "support/ManyLightsScene.h"
#include "support/TestSupport.h"

#include <cstdio>
#include <cstdlib>

namespace vkrt::test {
namespace {

class LoopBudget : public GpuTest {};

// ctest's old-driver run sets VKRT_EXPECT_DRIVER, so that a driver manifest
// the loader ignored cannot pass for a run on Mesa 22.
TEST_F(LoopBudget, RunsOnTheExpectedDriver)
{
    const char* expected = std::getenv("VKRT_EXPECT_DRIVER");
    if (!expected) GTEST_SKIP() << "VKRT_EXPECT_DRIVER not set";
    EXPECT_NE(gpu().deviceInfo().driver.find(expected), std::string::npos) << gpu().deviceInfo().driver;
}

// The version rule (no probe on Mesa >= 25) must agree with what a probe
// dispatch measures on the same driver.
TEST_F(LoopBudget, DriverRuleAgreesWithTheProbe)
{
    LoopCap rule = detectLoopCap(gpu());
    LoopCap probed = detectLoopCap(gpu(), true);
    EXPECT_EQ(rule.capped(), probed.capped()) << rule.describe() << " vs " << probed.describe();
    reportStat("loop cap capped", probed.capped() ? 1 : 0);
    std::printf("loop cap on %s: %s\n", gpu().deviceInfo().driver.c_str(), probed.describe().c_str());
    if (probed.capped()) {
        EXPECT_EQ(*probed.budget, gpu::LOOP_BUDGET) << probed.describe();
    }
}

// A capped device counts an invocation's loop passes in total, so several
// samples per invocation would share one budget: refused there, by name.
TEST_F(LoopBudget, SeveralSamplesPerInvocationAreRefusedWhereLoopsAreCapped)
{
    if (!gpu().loopCap().capped()) GTEST_SKIP() << "this device runs every loop to completion";
    Scene scene = sceneFromText(manyLightsScene(8, 1, 1.0), "few-lights.toml");
    RenderOptions options = pixelCentreOptions();
    options.samplesPerInvocation = 4;
    try {
        Renderer renderer(gpu(), scene, options);
        FAIL() << "4 samples per invocation were accepted on a capped device";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("--samples-per-invocation 4"), std::string::npos) << e.what();
    }
    options.samplesPerInvocation = 1;
    Renderer renderer(gpu(), scene, options);
    renderer.renderFrames(2);
    EXPECT_EQ(renderer.counters().budgetExceeded, 0u);
}

// 8 lights of intensity 1 at one point (as many as the kernel tests one by
// one: more go into the light table) over 8000 spheres must light the plane
// exactly as one light of intensity 8 does: a driver that cut the light loop
// short would give a darker image, and a capped one must refuse the scene instead.
TEST_F(LoopBudget, ScenePastTheOldCapRendersRightOrIsRefused)
{
    Scene many = sceneFromText(manyLightsScene(8000, 8, 1.0), "many-lights.toml");
    ASSERT_GT(worstCaseLoopIterations(many), uint64_t(gpu::LOOP_BUDGET));
    if (gpu().loopCap().capped()) {
        EXPECT_THROW(Renderer(gpu(), many, pixelCentreOptions()), InputError);
        return;
    }
    Renderer renderer(gpu(), many, pixelCentreOptions());
    renderer.renderFrames(1);
    EXPECT_GT(renderer.counters().maxLoopIterations, gpu::LOOP_BUDGET);
    Image image = renderer.mean();

    Renderer single(gpu(), sceneFromText(manyLightsScene(8000, 1, 8.0)), pixelCentreOptions());
    single.renderFrames(1);
    Image expected = single.mean();
    ASSERT_GT(channelMean(expected, 0), 0.01);
    for (size_t i = 0; i < image.rgb.size(); ++i)
        ASSERT_NEAR(image.rgb[i], expected.rgb[i], 1e-4 * expected.rgb[i] + 1e-7) << "value " << i;
}

/// A mesh that defeats any BVH: `count` thin slivers along the image's
/// diagonal, stacked in depth, whose boxes all cover the whole view while
/// almost every ray misses them all, so each ray tests every sliver.
MeshData sliverHedgehog(uint32_t count)
{
    MeshData mesh;
    for (uint32_t i = 0; i < count; ++i) {
        const float z = -0.5f * float(i) / float(count);
        const uint32_t first = uint32_t(mesh.positions.size());
        mesh.positions.push_back({-1.0f, -1.0f, z});
        mesh.positions.push_back({1.0f, 1.0f, z});
        mesh.positions.push_back({1.0f, 1.0f + 1e-4f, z});
        mesh.triangles.push_back({first, first + 1, first + 2});
    }
    return mesh;
}

// Mesh traversal has no useful static bound, so on a device that caps loops
// the kernel counts every subgroup's passes: a worst-case mesh either renders
// right (no cap: every pixel off the diagonal sees the grey wall behind) or
// fails loudly (a cap), never a silently truncated image.
TEST_F(LoopBudget, WorstCaseMeshIsNeverCutShortSilently)
{
    const auto dir = freshTempDir("loop-budget-mesh");
    writeObj(sliverHedgehog(20000), dir / "hedgehog.obj");
    const Scene scene = sceneFromText(R"(
[render]
max_depth = 1
[camera]
eye = [0, 0, 3]
target = [0, 0, 0]
fov = 30
width = 16
height = 16
[materials.m]
type = "lambert"
albedo = [0.5, 0.5, 0.5]
[[objects]]
shape = "mesh"
file = "hedgehog.obj"
material = "m"
[[objects]]
shape = "box"
min = [-5, -5, -2]
max = [5, 5, -1]
material = "m"
[[lights]]
type = "point"
position = [0, 0, 3]
intensity = 10
)",
                                      (dir / "hedgehog.toml").string());
    EXPECT_NO_THROW(checkLoopBudget(scene, LoopCap{gpu::LOOP_BUDGET, "probe"})) << "checked at run time instead";
    Renderer renderer(gpu(), scene, pixelCentreOptions());
    if (gpu().loopCap().capped()) {
        try {
            renderer.renderFrames(1);
            FAIL() << "a capped device must not return the truncated image";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find("loop cap"), std::string::npos) << e.what();
        }
        return;
    }
    renderer.renderFrames(1);
    EXPECT_GT(renderer.counters().maxLoopIterations, 20000u) << "the rays did test every sliver";
    // The wall at z = -1 lit head-on from 4 away: at most 0.5 / pi * 10 / 16, at the centre.
    const Image image = renderer.mean();
    const double centre = 0.5 / M_PI * 10.0 / 16.0;
    for (uint32_t y = 0; y < image.height; ++y)
        for (uint32_t x = 0; x < image.width; ++x) {
            // The slivers lie along the diagonal from bottom left to top right.
            if (std::abs(int(x + y) - int(image.width - 1)) <= 1) continue;
            // Off-centre the wall is farther and tilted: 0.82 of the centre at the corners.
            EXPECT_GT(image.at(x, y)[0], 0.75 * centre) << x << "," << y;
            EXPECT_LT(image.at(x, y)[0], 1.0001 * centre) << x << "," << y;
        }
}

} // namespace
} // namespace vkrt::test

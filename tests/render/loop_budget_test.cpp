// The loop-budget guard follows the device: where the driver silently cuts
// long loops short (Mesa < 25 lavapipe) a scene that could reach the cap is
// refused before anything renders; where it does not, the same scene renders,
// and renders right. ctest runs these tests on the default driver and again on
// Debian 12's stock Mesa 22 lavapipe (tests/CMakeLists.txt, old-lavapipe).
#include "gpu/LoopCap.h"
#include "mesh/MeshData.h"
#include "mesh/Procedural.h"
#include "render/Renderer.h"
#include "shared/Bindings.h"
#include "support/TestSupport.h"

#include <cstdio>
#include <cstdlib>

namespace vkrt::test {
namespace {

/// A lit plane seen by the camera, `spheres` small spheres beside it and
/// `lights` point lights of intensity `intensity` at one position: each pixel
/// of the plane runs one shadow query over every primitive per light.
std::string manyLightsScene(int spheres, int lights, double intensity)
{
    std::string text = "[render]\nmax_depth = 1\n[camera]\neye = [0, 2, 4]\ntarget = [0, 0, 0]\nfov = 40\n"
                       "width = 8\nheight = 8\n[materials.m]\ntype = \"lambert\"\n"
                       "[[objects]]\nshape = \"plane\"\npoint = [0, 0, 0]\nnormal = [0, 1, 0]\nmaterial = \"m\"\n";
    // Appended piece by piece: GCC 14 reports a false -Warray-bounds at -O2 in
    // the inlined `std::string&& + "..."`.
    for (int i = 0; i < spheres; ++i) {
        text += "[[objects]]\nshape = \"sphere\"\ncenter = [";
        text += std::to_string(100 + i);
        text += ", 0, -50]\nradius = 0.1\nmaterial = \"m\"\n";
    }
    for (int i = 0; i < lights; ++i)
        text +=
            "[[lights]]\ntype = \"point\"\nposition = [0.5, 3, 0.5]\nintensity = " + std::to_string(intensity) + "\n";
    return text;
}

TEST(LoopCapRule, MesaVersionIsReadFromTheDriverDescription)
{
    EXPECT_EQ(mesaMajorVersion("llvmpipe: Mesa 22.3.6 (LLVM 15.0.6)"), 22);
    EXPECT_EQ(mesaMajorVersion("llvmpipe: Mesa 25.0.7-2~bpo12+1 (LLVM 15.0.6)"), 25);
    EXPECT_EQ(mesaMajorVersion("NVIDIA: 550.54.14"), std::nullopt);
}

TEST(LoopCapRule, CappedDeviceRefusesAScenePastItsBudgetNamingIt)
{
    Scene scene = sceneFromText(manyLightsScene(300, 250, 1.0), "big.toml");
    ASSERT_GE(worstCaseLoopIterations(scene), uint64_t(gpu::LOOP_BUDGET));
    LoopCap capped{gpu::LOOP_BUDGET, "probe: 65535 of 100000 loop passes ran"};
    try {
        checkLoopBudget(scene, capped);
        FAIL() << "expected InputError";
    } catch (const InputError& e) {
        std::string message = e.what();
        EXPECT_NE(message.find("big.toml"), std::string::npos) << message;
        EXPECT_NE(message.find("65535"), std::string::npos) << message;
        EXPECT_NE(message.find("probe"), std::string::npos) << message;
    }
    EXPECT_NO_THROW(checkLoopBudget(scene, LoopCap{std::nullopt, "no cap"}));
}

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

// 250 lights of intensity 1 at one point must light the plane exactly as one
// light of intensity 250 does: a driver that cut the light loop short would
// give a darker image, and a capped one must refuse the scene instead.
TEST_F(LoopBudget, ScenePastTheOldCapRendersRightOrIsRefused)
{
    Scene many = sceneFromText(manyLightsScene(300, 250, 1.0), "many-lights.toml");
    ASSERT_GT(worstCaseLoopIterations(many), uint64_t(gpu::LOOP_BUDGET));
    if (gpu().loopCap().capped()) {
        EXPECT_THROW(Renderer(gpu(), many, pixelCentreOptions()), InputError);
        return;
    }
    Renderer renderer(gpu(), many, pixelCentreOptions());
    renderer.renderFrames(1);
    EXPECT_GT(renderer.counters().maxLoopIterations, gpu::LOOP_BUDGET);
    Image image = renderer.mean();

    Renderer single(gpu(), sceneFromText(manyLightsScene(300, 1, 250.0)), pixelCentreOptions());
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

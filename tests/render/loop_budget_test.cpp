// The loop-budget guard follows the device: where the driver silently cuts
// long loops short (Mesa < 25 lavapipe) a scene that could reach the cap is
// refused before anything renders; where it does not, the same scene renders,
// and renders right. ctest runs these tests on the default driver and again on
// Debian 12's stock Mesa 22 lavapipe (tests/CMakeLists.txt, old-lavapipe).
#include "gpu/LoopCap.h"
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

} // namespace
} // namespace vkrt::test

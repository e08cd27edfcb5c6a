// The loop-budget rule without a device (ctest label "cpu", built into
// vkrt_cpu_tests): the Mesa version read from a driver description, and a
// capped device refusing a scene past its budget. What the rule decides on a
// real driver is tested in loop_budget_test.cpp.
#include "gpu/LoopCap.h"
#include "render/Renderer.h"
#include "shared/Bindings.h"
#include "support/ManyLightsScene.h"
#include "support/TestSupport.h"

namespace vkrt::test {
namespace {

TEST(LoopCapRule, MesaVersionIsReadFromTheDriverDescription)
{
    EXPECT_EQ(mesaMajorVersion("llvmpipe: Mesa 22.3.6 (LLVM 15.0.6)"), 22);
    EXPECT_EQ(mesaMajorVersion("llvmpipe: Mesa 25.0.7-2~bpo12+1 (LLVM 15.0.6)"), 25);
    EXPECT_EQ(mesaMajorVersion("NVIDIA: 550.54.14"), std::nullopt);
}

TEST(LoopCapRule, CappedDeviceRefusesAScenePastItsBudgetNamingIt)
{
    Scene scene = sceneFromText(manyLightsScene(8000, 8, 1.0), "big.toml");
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

} // namespace
} // namespace vkrt::test

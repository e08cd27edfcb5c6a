// The render session's rules that need no Vulkan device (ctest label "cpu",
// built into vkrt_cpu_tests): its one sampler policy, the frame pacing, the
// Ctrl-C guard and the validation of overrides (resolution from options or a
// suite, viewer camera moves) with the scene parser's rules. The session's
// stop rules and metadata on a device are in render_session_test.cpp.
#include "render/RenderSession.h"
#include "scene/SceneOverrides.h"
#include "support/TestSupport.h"
#include "util/Error.h"
#include "view/CameraControl.h"

#include <atomic>
#include <cmath>
#include <csignal>
#include <functional>

namespace vkrt::test {
namespace {

// ---------------------------------------------------------------- backend policy

DeviceInfo deviceWithRayQueries(vk::PhysicalDeviceType type, bool rayQueries)
{
    DeviceInfo d;
    d.name = "test device";
    d.driver = "test driver";
    d.type = type;
    d.rayQueryMissing = rayQueries ? "" : "the extension VK_KHR_ray_query";
    return d;
}

TEST(AccelPolicy, KeepsAGivenChoiceAndRefusesTheDriverWithoutRayQueries)
{
    const uint64_t analytic = 0, fewTriangles = kDriverAccelMaxCpuTriangles, manyTriangles = 69453;
    const DeviceInfo cpu = deviceWithRayQueries(vk::PhysicalDeviceType::eCpu, true);
    const DeviceInfo gpu = deviceWithRayQueries(vk::PhysicalDeviceType::eDiscreteGpu, true);
    const DeviceInfo old = deviceWithRayQueries(vk::PhysicalDeviceType::eCpu, false);
    EXPECT_EQ(resolveAccel(AccelChoice::Own, gpu, fewTriangles), Accel::Own);
    EXPECT_EQ(resolveAccel(AccelChoice::Driver, cpu, analytic), Accel::Driver);
    try {
        resolveAccel(AccelChoice::Driver, old, analytic);
        ADD_FAILURE() << "--accel driver without ray queries was accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("--accel driver: test device (test driver) lacks the extension "
                                             "VK_KHR_ray_query"),
                  std::string::npos)
            << e.what();
    }
    // auto: the measured rule (docs/performance.md, "Two traversal backends").
    EXPECT_EQ(resolveAccel(AccelChoice::Auto, old, fewTriangles), Accel::Own);
    EXPECT_EQ(resolveAccel(AccelChoice::Auto, gpu, analytic), Accel::Driver);
    EXPECT_EQ(resolveAccel(AccelChoice::Auto, gpu, manyTriangles), Accel::Driver);
    EXPECT_EQ(resolveAccel(AccelChoice::Auto, cpu, fewTriangles), Accel::Driver);
    EXPECT_EQ(resolveAccel(AccelChoice::Auto, cpu, fewTriangles + 1), Accel::Own);
    EXPECT_EQ(resolveAccel(AccelChoice::Auto, cpu, manyTriangles), Accel::Own);
    EXPECT_EQ(resolveAccel(AccelChoice::Auto, cpu, analytic), Accel::Own);
}

// ---------------------------------------------------------------- sampler policy

constexpr uint64_t kRange = uint64_t(1) << 27; // lavapipe's maxStorageBufferRange

TEST(SamplerPolicy, VarianceLayerGetsIndependentSamples)
{
    EXPECT_EQ(resolveSampler(SamplerChoice::Auto, {true, false}, 64, kRange), Sampler::Independent);
    EXPECT_EQ(resolveSampler(SamplerChoice::Auto, {true, true}, 64, kRange), Sampler::Independent);
}

TEST(SamplerPolicy, ErrorEstimateFallsBackToIndependentWhenBatchesPassTheStorageRange)
{
    uint64_t fitting = kRange / varianceBytesPerPixel(true);
    EXPECT_EQ(resolveSampler(SamplerChoice::Auto, {false, true}, fitting, kRange), Sampler::Sobol);
    EXPECT_EQ(resolveSampler(SamplerChoice::Auto, {false, true}, fitting + 1, kRange), Sampler::Independent);
}

TEST(SamplerPolicy, OtherwiseSobolAndAnExplicitChoiceIsKept)
{
    EXPECT_EQ(resolveSampler(SamplerChoice::Auto, {}, 1u << 26, kRange), Sampler::Sobol) << "no batches, no limit";
    EXPECT_EQ(resolveSampler(SamplerChoice::Sobol, {true, false}, 64, kRange), Sampler::Sobol);
    EXPECT_EQ(resolveSampler(SamplerChoice::Independent, {}, 64, kRange), Sampler::Independent);
    EXPECT_EQ(samplerChoiceNamed("auto"), SamplerChoice::Auto);
    EXPECT_EQ(samplerChoiceNamed("halton"), std::nullopt);
}

// ---------------------------------------------------------------- overrides

std::string errorOf(const std::function<void()>& action)
{
    try {
        action();
    } catch (const InputError& e) {
        return e.what();
    }
    return "(no error)";
}

TEST(SceneOverrides, ResolutionErrorsNameTheOptionWithTheParsersWording)
{
    Camera camera;
    EXPECT_EQ(errorOf([&] {
                  applyResolution(camera, {0u, std::nullopt});
              }),
              "--width: must be between 1 and 16384, got 0");
    EXPECT_EQ(errorOf([&] {
                  applyResolution(camera, {std::nullopt, 16385u});
              }),
              "--height: must be between 1 and 16384, got 16385");
    EXPECT_EQ(errorOf([&] {
                  applyResolution(camera, {16384u, 16384u});
              }),
              "--height: width * height = 268435456 pixels exceeds the limit of 67108864");
    // One side alone keeps the aspect ratio: the other side follows, and is checked.
    camera.height = 16384;
    EXPECT_EQ(errorOf([&] {
                  applyResolution(camera, {8192u, std::nullopt});
              }),
              "--width: the height that keeps the scene's aspect ratio (640x16384) must be between 1 and 16384, got "
              "209715; give --height too");
    EXPECT_EQ(camera.width, 640u) << "a refused override changes nothing";
    camera.width = camera.height = 4096;
    EXPECT_EQ(errorOf([&] {
                  applyResolution(camera, {16384u, std::nullopt});
              }),
              "--width: width * height = 268435456 pixels exceeds the limit of 67108864")
        << "only the width was given: it is to blame";
    applyResolution(camera, {std::nullopt, 100u});
    EXPECT_EQ(camera.width, 100u);
    EXPECT_EQ(camera.height, 100u);
    camera.width = 640;
    camera.height = 480;
    applyResolution(camera, {161u, std::nullopt});
    EXPECT_EQ(camera.height, 121u) << "161 x 480 / 640 = 120.75, rounded";
}

TEST(SceneOverrides, SuiteCaseErrorsNameTheSuiteAndCase)
{
    Camera camera;
    ResolutionOverride fromSuite{99999u, std::nullopt, "suite.toml: case a/b: width", "suite.toml: case a/b: height"};
    EXPECT_EQ(errorOf([&] { applyResolution(camera, fromSuite); }),
              "suite.toml: case a/b: width: must be between 1 and 16384, got 99999");
    applyResolution(camera, {320u, 200u});
    EXPECT_EQ(camera.width, 320u);
    EXPECT_EQ(camera.height, 200u);
}

Camera lookingDownMinusZ()
{
    Camera c;
    c.eye = {0, 1, 5};
    c.target = {0, 1, 0};
    return c;
}

TEST(SceneOverrides, CameraMovesThatCollapseTheViewAreRefused)
{
    Camera c = lookingDownMinusZ();
    EXPECT_EQ(cameraProblem(c), std::nullopt);
    EXPECT_EQ(cameraProblem(zoom(c, 0.5)), std::nullopt);
    EXPECT_EQ(cameraProblem(zoom(c, 0.0)), "fov: must be strictly between 0 and 180 degrees, got 0");
    EXPECT_NE(cameraProblem(zoom(c, std::nan(""))), std::nullopt);
    EXPECT_EQ(cameraProblem(fly(c, 0, 0, 1e308)), "eye: must be finite") << "an overflowing fly";
    Camera atTarget = c;
    atTarget.eye = c.target;
    EXPECT_EQ(cameraProblem(atTarget), "target: must differ from camera.eye (the view direction would be undefined)");
    Camera upAlongView = c;
    upAlongView.up = {0, 0, -3};
    EXPECT_EQ(cameraProblem(upAlongView), "up: must not be parallel to the view direction (target - eye)");
    upAlongView.up = {0, 0, 0};
    EXPECT_EQ(cameraProblem(upAlongView), "up: must not be zero-length");
    EXPECT_EQ(errorOf([&] { checkCamera(zoom(c, 0.0), "zoom"); }),
              "zoom: fov: must be strictly between 0 and 180 degrees, got 0");
}

// ---------------------------------------------------------------- frames

TEST(BatchPacer, GrowsAtMostTwofoldTowardsTheTargetAndShrinksAtOnce)
{
    BatchPacer pacer(0.25);
    EXPECT_EQ(pacer.nextFrames(), 1u);
    pacer.record(1, 0.001); // far below the target: double, no more
    EXPECT_EQ(pacer.nextFrames(), 2u);
    pacer.record(40, 0.0); // unmeasurably fast: double up to the cap
    EXPECT_EQ(pacer.nextFrames(), 64u);
    pacer.record(64, 1.0); // four times too long: a quarter
    EXPECT_EQ(pacer.nextFrames(), 16u);
    pacer.record(1, 10.0); // one slow frame: still at least one
    EXPECT_EQ(pacer.nextFrames(), 1u);
}

// The target-error rule looks again where the bound should meet the target
// (relMSE ~ 1 / spp), 5 % past it, on a whole number of batches.
TEST(TargetErrorSchedule, NextCheckpointIsWhereTheBoundShouldMeetTheTarget)
{
    EXPECT_EQ(sppExpectedToMeet(64, 0.02, 0.01, 8), 136u);  // 128 * 1.05 = 134.4, up to a multiple of 8
    EXPECT_EQ(sppExpectedToMeet(64, 0.0101, 0.01, 8), 72u); // at least one batch round ahead
    EXPECT_EQ(sppExpectedToMeet(3, 0.5, 0.1, 1), 16u);      // 15.75 samples
    EXPECT_EQ(sppExpectedToMeet(64, 0.01, 0.01, 8), std::nullopt) << "already met";
    EXPECT_EQ(sppExpectedToMeet(64, INFINITY, 0.01, 8), std::nullopt) << "no estimate yet";
    EXPECT_EQ(sppExpectedToMeet(1u << 30, 1e6, 1e-6, 8), 1u << 31) << "clamped";
}

// ---------------------------------------------------------------- Ctrl-C

std::atomic<int> g_previousHandlerCalls{0};
extern "C" void countingHandler(int) { ++g_previousHandlerCalls; }

TEST(InterruptGuard, CatchesSigintAndRestoresThePreviousHandler)
{
    auto before = std::signal(SIGINT, countingHandler);
    {
        InterruptGuard guard;
        EXPECT_FALSE(interruptFlag().load()) << "a new guard starts clear";
        std::raise(SIGINT);
        EXPECT_TRUE(interruptFlag().load());
        EXPECT_EQ(g_previousHandlerCalls.load(), 0);
    }
    std::raise(SIGINT);
    EXPECT_EQ(g_previousHandlerCalls.load(), 1) << "the handler from before the guard is back";
    std::signal(SIGINT, before);
}

} // namespace
} // namespace vkrt::test

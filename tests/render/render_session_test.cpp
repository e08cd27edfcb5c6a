// The render session: its one sampler policy, its stop rules, the metadata it
// writes for every command, and the validation of overrides (resolution from
// options or a suite, viewer camera moves) with the scene parser's rules.
#include "render/RenderSession.h"
#include "scene/SceneOverrides.h"
#include "shared/Bindings.h"
#include "support/TestSupport.h"
#include "view/CameraControl.h"

#include <atomic>
#include <csignal>
#include <set>

namespace vkrt::test {
namespace {

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
    camera.height = 16384;
    EXPECT_EQ(errorOf([&] {
                  applyResolution(camera, {8192u, std::nullopt});
              }),
              "--width: width * height = 134217728 pixels exceeds the limit of 67108864")
        << "only the width was given: it is to blame";
    EXPECT_EQ(camera.width, 640u) << "a refused override changes nothing";
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

// ---------------------------------------------------------------- session (GPU)

class RenderSessionTest : public GpuTest {
protected:
    static Scene smallScene()
    {
        return sceneFromText("[camera]\neye = [0,0,0]\ntarget = [0,0,-1]\nfov = 60\nwidth = 16\nheight = 12\n"
                             "[background]\ncolor = 0.25\n");
    }
    static SessionConfig config()
    {
        SessionConfig c;
        c.seed = 3;
        c.cacheDirectory = testCacheDir();
        return c;
    }
};

TEST_F(RenderSessionTest, StopsWhenTheSppAreReached)
{
    SessionConfig c = config();
    c.stop.maxSpp = 5;
    RenderSession session(gpu(), smallScene(), c);
    LoopResult loop = session.run();
    EXPECT_EQ(loop.reason, StopReason::SppReached);
    EXPECT_EQ(session.spp(), 5u);
    EXPECT_EQ(session.outcome().kind, OutcomeKind::Passed);
    EXPECT_EQ(session.sampler(), Sampler::Sobol) << "auto without a variance: Sobol'";
}

TEST_F(RenderSessionTest, AnInterruptBeforeTheFirstFrameRendersNothing)
{
    std::atomic<bool> interrupt{true};
    SessionConfig c = config();
    c.stop.interrupt = &interrupt;
    RenderSession session(gpu(), smallScene(), c);
    LoopResult loop = session.run();
    EXPECT_EQ(loop.reason, StopReason::Interrupted);
    EXPECT_EQ(session.spp(), 0u);
    EXPECT_EQ(loop.renderSeconds, 0.0);
    EXPECT_EQ(session.outcome().kind, OutcomeKind::Interrupted);
}

TEST_F(RenderSessionTest, StopsAtTheTimeBudget)
{
    SessionConfig c = config();
    c.stop.maxSpp = 1u << 30;
    c.stop.timeBudgetSeconds = 0.3;
    RenderSession session(gpu(), smallScene(), c);
    LoopResult loop = session.run();
    EXPECT_EQ(loop.reason, StopReason::TimeBudget);
    EXPECT_GE(loop.renderSeconds, 0.3);
    EXPECT_LT(loop.renderSeconds, 3.0) << "one slow frame at most past the budget";
    EXPECT_GT(session.spp(), 0u);
}

TEST_F(RenderSessionTest, StopsAtTheTargetErrorAtACheckpoint)
{
    SessionConfig c = config();
    c.stop.maxSpp = 1u << 30;
    c.stop.targetRelMse = 1e9; // any finite estimate is below it
    c.variance.errorEstimate = true;
    std::vector<uint32_t> checkpoints;
    RunHooks hooks;
    hooks.onCheckpoint = [&](uint32_t spp, double, const Film& film) {
        checkpoints.push_back(spp);
        EXPECT_TRUE(film.variance.has_value());
    };
    RenderSession session(gpu(), smallScene(), c);
    LoopResult loop = session.run(hooks);
    EXPECT_EQ(loop.reason, StopReason::TargetError);
    // Sobol' batches give a finite estimate once each of the 8 has a sample.
    EXPECT_EQ(session.spp(), uint32_t(gpu::VARIANCE_BATCHES));
    EXPECT_EQ(checkpoints, (std::vector<uint32_t>{1, 2, 4, 8}));
}

std::set<std::string> keysOf(const Metadata& metadata)
{
    std::set<std::string> keys;
    for (const auto& [key, value] : metadata) keys.insert(key);
    return keys;
}

TEST_F(RenderSessionTest, RenderMetadataHasEveryField)
{
    SessionConfig c = config();
    c.stop.maxSpp = 8;
    c.stop.timeBudgetSeconds = 100.0;
    c.variance.layer = true;
    RenderSession session(gpu(), smallScene(), c);
    session.run();
    Film film = session.film();
    Metadata m = session.metadata(film);
    for (const char* key :
         {"vkrtVersion", "spp", "seed", "renderSeconds", "stoppedBy", "device", "driver", "scene", "sceneHash",
          "integrator", "kernelVariant", "sampler", "rejectedSamples", "loopCap", "varianceDegreesOfFreedom",
          "varianceEstimator", "estimatedRmse", "estimatedRelMse", "timeBudgetSeconds"})
        EXPECT_EQ(m.count(key), 1u) << key;
    EXPECT_EQ(m.count("savedBy"), 0u);
    EXPECT_EQ(std::get<int64_t>(m.at("spp")), 8);
    EXPECT_EQ(std::get<int64_t>(m.at("seed")), 3);
    EXPECT_EQ(std::get<std::string>(m.at("stoppedBy")), "spp");
    EXPECT_EQ(std::get<std::string>(m.at("sampler")), "independent") << "a variance layer";
    EXPECT_EQ(std::get<int64_t>(m.at("varianceDegreesOfFreedom")), 7);
    EXPECT_EQ(std::get<std::string>(m.at("sceneHash")).rfind("fnv1a64:", 0), 0u);
    EXPECT_EQ(std::get<std::string>(m.at("loopCap")), gpu().loopCap().describe());
    std::string expectedStart = gpu().loopCap().capped() ? std::to_string(gpu::LOOP_BUDGET) : "none";
    EXPECT_EQ(std::get<std::string>(m.at("loopCap")).rfind(expectedStart, 0), 0u)
        << std::get<std::string>(m.at("loopCap"));
}

TEST_F(RenderSessionTest, ViewerSaveMetadataAddsSavedByAndFollowsMovesAndResets)
{
    RenderSession session(gpu(), smallScene(), config());
    session.renderFrames(3);
    Metadata saved = session.metadata(session.film(), "vkrt view");
    EXPECT_EQ(std::get<std::string>(saved.at("savedBy")), "vkrt view");
    EXPECT_EQ(std::get<int64_t>(saved.at("spp")), 3);
    EXPECT_EQ(saved.count("stoppedBy"), 0u) << "no stop rule ran";
    EXPECT_EQ(saved.count("estimatedRmse"), 0u) << "no variance estimated";
    std::set<std::string> expected = {"vkrtVersion", "spp",           "seed",    "renderSeconds",
                                      "device",      "driver",        "scene",   "sceneHash",
                                      "integrator",  "kernelVariant", "sampler", "rejectedSamples",
                                      "loopCap",     "savedBy"};
    EXPECT_EQ(keysOf(saved), expected);

    Camera before = session.scene().camera;
    std::optional<std::string> refused = session.moveCamera(zoom(before, 0.0));
    ASSERT_TRUE(refused.has_value());
    EXPECT_EQ(*refused, "fov: must be strictly between 0 and 180 degrees, got 0");
    EXPECT_EQ(session.scene().camera.fovY, before.fovY);
    EXPECT_EQ(session.spp(), 3u) << "a refused move keeps the accumulation";
    EXPECT_EQ(session.moveCamera(orbit(before, 10, 0)), std::nullopt);
    EXPECT_EQ(session.spp(), 0u) << "a move starts afresh";
    session.setIntegrator(Integrator::Path);
    session.renderFrames(1);
    EXPECT_EQ(std::get<std::string>(session.metadata(session.film()).at("integrator")), "path");
}

} // namespace
} // namespace vkrt::test

// The render session on a device: its stop rules and the metadata it writes
// for every command. Its rules that need no device (sampler policy, pacing,
// Ctrl-C, overrides) are in session_policy_test.cpp (vkrt_cpu_tests).
#include "gpu/VectorWidth.h"
#include "render/RenderSession.h"
#include "shared/Bindings.h"
#include "support/TestSupport.h"
#include "view/CameraControl.h"

#include <atomic>
#include <set>

namespace vkrt::test {
namespace {

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
    c.accel = AccelChoice::Own;
    c.stop.maxSpp = 8;
    c.stop.timeBudgetSeconds = 100.0;
    c.variance.layer = true;
    RenderSession session(gpu(), smallScene(), c);
    session.run();
    Film film = session.film();
    Metadata m = session.metadata(film);
    for (const char* key : {"vkrtVersion",
                            "spp",
                            "seed",
                            "renderSeconds",
                            "stoppedBy",
                            "device",
                            "driver",
                            "scene",
                            "sceneHash",
                            "integrator",
                            "kernelVariant",
                            "sampler",
                            "rejectedSamples",
                            "loopCap",
                            "varianceDegreesOfFreedom",
                            "varianceEstimator",
                            "estimatedRmse",
                            "estimatedRelMse",
                            "timeBudgetSeconds",
                            "accel"})
        EXPECT_EQ(m.count(key), 1u) << key;
    EXPECT_EQ(std::get<std::string>(m.at("accel")), "own") << "the backend asked for";
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
                                      "loopCap",     "savedBy",       "accel"};
    if (lavapipeVectorBits(gpu().deviceInfo())) expected.insert("vectorWidth"); // lavapipe's SIMD width
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

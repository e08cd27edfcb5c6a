// End-to-end tests of `vkrt render` and `vkrt devices` as a user runs them.
#include "gpu/VectorWidth.h"
#include "io/ExrFile.h"
#include "shared/Bindings.h"
#include "support/TestSupport.h"

#include <chrono>
#include <cmath>
#include <csignal>
#include <fstream>
#include <thread>

#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace vkrt::test {
namespace {

class RenderCli : public ::testing::Test {
protected:
    void SetUp() override
    {
        m_dir = freshTempDir(::testing::UnitTest::GetInstance()->current_test_info()->name());
        setenv("VKRT_CACHE_DIR", testCacheDir().c_str(), 1);
    }
    fs::path m_dir;

    ProcessResult render(const std::string& output, std::vector<std::string> extra = {})
    {
        std::vector<std::string> args = {"render",      kDefaultScene, "-o",       (m_dir / output).string(),
                                         "--width",     "64",          "--height", "48",
                                         "--validation"};
        args.insert(args.end(), extra.begin(), extra.end());
        const char* device = std::getenv("VKRT_TEST_DEVICE");
        if (device && std::find(extra.begin(), extra.end(), "--device") == extra.end())
            args.insert(args.end(), {"--device", device});
        return runVkrt(args);
    }

    /// No leftovers such as temporary files in the output directory.
    std::vector<std::string> filesInDir() const
    {
        std::vector<std::string> names;
        for (const auto& e : fs::directory_iterator(m_dir)) names.push_back(e.path().filename().string());
        std::sort(names.begin(), names.end());
        return names;
    }
};

int64_t intAttribute(const Metadata& metadata, const std::string& name)
{
    auto it = metadata.find(name);
    if (it == metadata.end() || !std::holds_alternative<int64_t>(it->second)) return -1;
    return std::get<int64_t>(it->second);
}

std::string textAttribute(const Metadata& metadata, const std::string& name)
{
    auto it = metadata.find(name);
    if (it == metadata.end() || !std::holds_alternative<std::string>(it->second)) return "";
    return std::get<std::string>(it->second);
}

TEST_F(RenderCli, WritesExrWithMetadataAndPng)
{
    ProcessResult r = render("a.exr", {"--spp", "3", "--seed", "5", "--png", (m_dir / "a.png").string()});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    ExrContents exr = readExr(m_dir / "a.exr");
    EXPECT_EQ(exr.image.width, 64u);
    EXPECT_EQ(exr.image.height, 48u);
    EXPECT_EQ(intAttribute(exr.metadata, "spp"), 3);
    EXPECT_EQ(intAttribute(exr.metadata, "seed"), 5);
    EXPECT_EQ(intAttribute(exr.metadata, "rejectedSamples"), 0);
    EXPECT_EQ(textAttribute(exr.metadata, "stoppedBy"), "spp");
    EXPECT_EQ(textAttribute(exr.metadata, "loopCap"), gpu().loopCap().describe());
    EXPECT_EQ(textAttribute(exr.metadata, "vkrtVersion"), VKRT_VERSION);
    EXPECT_EQ(textAttribute(exr.metadata, "sceneHash").rfind("fnv1a64:", 0), 0u);
    EXPECT_FALSE(textAttribute(exr.metadata, "device").empty());
    EXPECT_FALSE(textAttribute(exr.metadata, "driver").empty());
    EXPECT_TRUE(exr.metadata.count("renderSeconds"));
    EXPECT_EQ(filesInDir(), (std::vector<std::string>{"a.exr", "a.png"}));
    // Non-interactive runs print exactly one summary line.
    EXPECT_NE(r.output.find("3 spp"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("samples/s"), std::string::npos) << r.output;
}

// --vector-width: vkrt starts itself again with lavapipe at the width asked
// for, and the EXR and the JSON say which width ran.
TEST_F(RenderCli, VectorWidthRunsLavapipeAtTheWidthAskedFor)
{
    const std::optional<int> running = lavapipeVectorBits(gpu().deviceInfo());
    if (!running) GTEST_SKIP() << gpu().deviceInfo().name << " is not lavapipe";
    if (!cpuHasAvx512()) GTEST_SKIP() << "this CPU lacks AVX-512";
    for (const char* bits : {"512", "256"}) {
        const std::string exr = std::string("w") + bits + ".exr", json = (m_dir / (std::string(bits) + ".json"));
        ProcessResult r = render(exr, {"--spp", "1", "--vector-width", bits, "--json", json});
        ASSERT_EQ(r.exitCode, 0) << r.output;
        EXPECT_EQ(intAttribute(readExr(m_dir / exr).metadata, "vectorWidth"), std::stoi(bits));
        std::ifstream in(json);
        const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        EXPECT_NE(text.find(std::string("\"vectorWidth\": ") + bits), std::string::npos) << text;
    }
    ProcessResult wrong = render("x.exr", {"--vector-width", "300"});
    EXPECT_EQ(wrong.exitCode, 2);
    EXPECT_NE(wrong.output.find("--vector-width 300: expected auto, 256 or 512"), std::string::npos) << wrong.output;
}

// --sampler auto: Sobol' unless a per-pixel variance layer is asked for; an
// error estimate under Sobol' (--report, --target-error, or --variance with an
// explicit sobol) comes from independently scrambled batches, and the EXR
// says how many degrees of freedom the variance layer has.
TEST_F(RenderCli, SamplerAutoPicksSobolUnlessAVarianceLayerIsAsked)
{
    ASSERT_EQ(render("plain.exr", {"--spp", "2"}).exitCode, 0);
    ExrContents plain = readExr(m_dir / "plain.exr");
    EXPECT_EQ(std::get<std::string>(plain.metadata.at("sampler")), "sobol");
    EXPECT_EQ(plain.metadata.count("varianceDegreesOfFreedom"), 0u);
    ASSERT_EQ(render("var.exr", {"--spp", "3", "--variance"}).exitCode, 0);
    ExrContents withVariance = readExr(m_dir / "var.exr");
    EXPECT_EQ(std::get<std::string>(withVariance.metadata.at("sampler")), "independent");
    EXPECT_EQ(std::get<int64_t>(withVariance.metadata.at("varianceDegreesOfFreedom")), 2);
    ASSERT_EQ(render("report.exr", {"--spp", "8", "--report", (m_dir / "r.csv").string()}).exitCode, 0);
    EXPECT_EQ(std::get<std::string>(readExr(m_dir / "report.exr").metadata.at("sampler")), "sobol");
    // Where 8 batch sums per pixel would pass the storage-buffer range the
    // device guarantees (lavapipe: 128 MiB, 0.6 M pixels), auto estimates with
    // independent samples instead: the run stays valid Vulkan (--validation
    // would fail it with exit 3 otherwise).
    ProcessResult wide =
        runVkrt({"render", kDefaultScene, "-o", (m_dir / "wide.exr").string(), "--width", "1024", "--height", "768",
                 "--spp", "2", "--report", (m_dir / "w.csv").string(), "--validation"});
    ASSERT_EQ(wide.exitCode, 0) << wide.output;
    EXPECT_EQ(wide.output.find("maxStorageBufferRange"), std::string::npos) << wide.output;
    ASSERT_EQ(render("batched.exr", {"--spp", "16", "--sampler", "sobol", "--variance"}).exitCode, 0);
    ExrContents batched = readExr(m_dir / "batched.exr");
    EXPECT_EQ(std::get<std::string>(batched.metadata.at("sampler")), "sobol");
    EXPECT_EQ(std::get<int64_t>(batched.metadata.at("varianceDegreesOfFreedom")), int64_t(gpu::VARIANCE_BATCHES) - 1);
    ASSERT_TRUE(batched.layers.count("variance"));
    for (float v : batched.layers.at("variance").rgb) ASSERT_TRUE(std::isfinite(v) && v >= 0.0f);
    ProcessResult unknown = render("no.exr", {"--sampler", "halton"});
    EXPECT_EQ(unknown.exitCode, 2);
    EXPECT_NE(unknown.output.find("--sampler"), std::string::npos) << unknown.output;
}

TEST_F(RenderCli, VarianceOptionWritesAVarianceLayer)
{
    ASSERT_EQ(render("v.exr", {"--spp", "4", "--variance"}).exitCode, 0);
    ExrContents exr = readExr(m_dir / "v.exr");
    ASSERT_TRUE(exr.layers.count("variance"));
    const Image& variance = exr.layers.at("variance");
    EXPECT_EQ(variance.width, exr.image.width);
    size_t positive = 0;
    for (float v : variance.rgb) {
        ASSERT_TRUE(v >= 0.0f && std::isfinite(v));
        positive += v > 0.0f;
    }
    EXPECT_GT(positive, variance.rgb.size() / 4) << "a noisy render must show variance";
    ASSERT_EQ(render("plain.exr", {"--spp", "4"}).exitCode, 0);
    EXPECT_TRUE(readExr(m_dir / "plain.exr").layers.empty());
}

TEST_F(RenderCli, SameSeedGivesIdenticalPixels)
{
    ASSERT_EQ(render("a.exr", {"--spp", "4", "--seed", "9"}).exitCode, 0);
    ASSERT_EQ(render("b.exr", {"--spp", "4", "--seed", "9"}).exitCode, 0);
    EXPECT_EQ(readExr(m_dir / "a.exr").image.rgb, readExr(m_dir / "b.exr").image.rgb);
}

// Different seeds give different noise but the same expected image: the mean
// of the per-pixel differences is zero within its standard error (|z| < 4).
TEST_F(RenderCli, DifferentSeedDifferentNoiseSameMean)
{
    ASSERT_EQ(render("a.exr", {"--spp", "4", "--seed", "1"}).exitCode, 0);
    ASSERT_EQ(render("b.exr", {"--spp", "4", "--seed", "2"}).exitCode, 0);
    Image a = readExr(m_dir / "a.exr").image, b = readExr(m_dir / "b.exr").image;
    ASSERT_NE(a.rgb, b.rgb);
    for (int c = 0; c < 3; ++c) {
        double sum = 0, sumSq = 0;
        size_t n = a.pixelCount();
        for (size_t i = 0; i < n; ++i) {
            double d = double(a.rgb[i * 3 + c]) - b.rgb[i * 3 + c];
            sum += d;
            sumSq += d * d;
        }
        double mean = sum / n, variance = (sumSq - n * mean * mean) / (n - 1);
        ASSERT_GT(variance, 0.0);
        EXPECT_LT(std::abs(mean / std::sqrt(variance / n)), 4.0) << "channel " << c;
    }
}

TEST_F(RenderCli, InterruptWritesPartialImageWithTrueSpp)
{
    fs::path output = m_dir / "partial.exr";
    pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        execl(VKRT_BINARY, "vkrt", "render", kDefaultScene.c_str(), "-o", output.c_str(), "--width", "64", "--height",
              "48", "--spp", "1000000", (char*)nullptr);
        _exit(127);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2500));
    kill(child, SIGINT);
    int status = 0;
    waitpid(child, &status, 0);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 130);
    ExrContents exr = readExr(output);
    int64_t spp = intAttribute(exr.metadata, "spp");
    EXPECT_GT(spp, 0);
    EXPECT_LT(spp, 1000000);
    EXPECT_EQ(textAttribute(exr.metadata, "stoppedBy"), "interrupted");
    EXPECT_EQ(filesInDir(), std::vector<std::string>{"partial.exr"});
}

// Issue 26 item 14: CLI::PositiveNumber printed its bound, the largest double, in 310 digits.
TEST_F(RenderCli, ZeroTimeBudgetOrTargetErrorGetsAShortMessage)
{
    ProcessResult budget = render("x.exr", {"--time-budget", "0"});
    EXPECT_EQ(budget.exitCode, 2);
    EXPECT_NE(budget.output.find("--time-budget: must be > 0 seconds and finite, not 0"), std::string::npos)
        << budget.output;
    EXPECT_LT(budget.output.size(), 200u) << budget.output;
    ProcessResult target = render("x.exr", {"--target-error", "-1"});
    EXPECT_EQ(target.exitCode, 2);
    EXPECT_NE(target.output.find("--target-error: must be > 0 relMSE and finite, not -1"), std::string::npos)
        << target.output;
    ProcessResult word = render("x.exr", {"--time-budget", "soon"});
    EXPECT_EQ(word.exitCode, 2);
    EXPECT_NE(word.output.find("--time-budget"), std::string::npos) << word.output;
    EXPECT_TRUE(filesInDir().empty());
}

// The warning once said "2 spp are too few ... (it needs 2, ...)": it now names what the sampler needs.
TEST_F(RenderCli, TooFewSamplesForAnEstimateSaysHowManyItNeeds)
{
    ProcessResult sobol = render("s.exr", {"--spp", "2", "--sampler", "sobol", "--variance"});
    ASSERT_EQ(sobol.exitCode, 0) << sobol.output;
    EXPECT_NE(sobol.output.find("2 spp are too few for an error estimate with the Sobol' sampler: it needs " +
                                std::to_string(gpu::VARIANCE_BATCHES)),
              std::string::npos)
        << sobol.output;
    ProcessResult independent = render("i.exr", {"--spp", "1", "--variance"});
    ASSERT_EQ(independent.exitCode, 0) << independent.output;
    EXPECT_NE(independent.output.find("1 spp is too few for an error estimate: it needs at least 2"), std::string::npos)
        << independent.output;
    ProcessResult enough = render("e.exr", {"--spp", "2", "--variance"});
    EXPECT_EQ(enough.output.find("too few"), std::string::npos) << enough.output;
}

TEST_F(RenderCli, BadOptionsNameTheOption)
{
    struct Case {
        std::vector<std::string> args;
        std::string expected;
    } cases[] = {
        {{"--spp", "0"}, "--spp"},
        {{"--spp", "many"}, "--spp"},
        {{"--width", "99999"}, "--width"},
        {{"--height", "-3"}, "--height"},
        {{"--exposure", "nan"}, "--exposure"},
        {{"--device", "no-such-device"}, "--device no-such-device"},
        {{"--bogus"}, "--bogus"},
    };
    for (const auto& c : cases) {
        ProcessResult r = render("x.exr", c.args);
        EXPECT_EQ(r.exitCode, 2) << c.args[0] << ": " << r.output;
        EXPECT_NE(r.output.find(c.expected), std::string::npos) << r.output;
    }
    EXPECT_TRUE(filesInDir().empty());
}

// --width/--height go through the scene parser's checks (SceneOverrides.h):
// same limits and wording as width/height in a scene file, naming the option.
TEST_F(RenderCli, ResolutionOverridesAreValidatedLikeTheSceneFile)
{
    struct Case {
        std::vector<std::string> args;
        std::string expected;
    } cases[] = {
        {{"--width", "0"}, "--width: must be between 1 and 16384, got 0"},
        {{"--width", "16384", "--height", "16384"},
         "--height: width * height = 268435456 pixels exceeds the limit of 67108864"},
    };
    for (const auto& c : cases) {
        std::vector<std::string> args = {"render", kDefaultScene, "-o", (m_dir / "x.exr").string()};
        args.insert(args.end(), c.args.begin(), c.args.end());
        ProcessResult r = runVkrt(args); // not render(): it gives --width and --height already
        EXPECT_EQ(r.exitCode, 2) << r.output;
        EXPECT_NE(r.output.find(c.expected), std::string::npos) << r.output;
    }
    EXPECT_TRUE(filesInDir().empty());
}

TEST_F(RenderCli, SceneErrorsNameFileLineAndColumn)
{
    fs::path scene = m_dir / "bad.toml";
    writeText(scene, "[camera]\neye = [0, 0, 0]\ntarget = [0, 0, -1]\nfov = 200\n");
    ProcessResult r = runVkrt({"render", scene.string(), "-o", (m_dir / "x.exr").string()});
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.output.find(scene.string() + ":4:7"), std::string::npos) << r.output;
    ProcessResult missing = runVkrt({"render", (m_dir / "nope.toml").string()});
    EXPECT_EQ(missing.exitCode, 2);
    EXPECT_NE(missing.output.find("nope.toml"), std::string::npos) << missing.output;
}

// A sky of 3e38 is a finite radiance, and so is each sample; two samples'
// sum is not. Such pixels are never written without a word: a warning, the
// JSON summary and the EXR's metadata count them.
TEST_F(RenderCli, PixelsWhoseSumOverflowsFloat32AreCounted)
{
    const fs::path scene = m_dir / "bright.toml";
    writeText(scene, "[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\nfov = 40\nwidth = 8\nheight = 6\n"
                     "[background]\ncolor = 3e38\n");
    std::vector<std::string> args = {"render", scene.string(),
                                     "-o",     (m_dir / "bright.exr").string(),
                                     "--spp",  "2",
                                     "--json", (m_dir / "bright.json").string()};
    if (const char* device = std::getenv("VKRT_TEST_DEVICE")) args.insert(args.end(), {"--device", device});
    const ProcessResult r = runVkrt(args);
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("warning: 48 pixels overflowed float32"), std::string::npos) << r.output;
    std::ifstream json(m_dir / "bright.json");
    const std::string summary((std::istreambuf_iterator<char>(json)), std::istreambuf_iterator<char>());
    EXPECT_NE(summary.find("\"overflowedPixels\": 48"), std::string::npos) << summary;
    EXPECT_EQ(intAttribute(readExr(m_dir / "bright.exr").metadata, "overflowedPixels"), 48);
    // One sample's sum is the sample: nothing overflows, nothing is said.
    args[5] = "1";
    const ProcessResult one = runVkrt(args);
    EXPECT_EQ(one.output.find("overflowed"), std::string::npos) << one.output;
    EXPECT_EQ(intAttribute(readExr(m_dir / "bright.exr").metadata, "overflowedPixels"), -1);
}

TEST_F(RenderCli, FailedRunLeavesExistingOutputUntouched)
{
    writeText(m_dir / "keep.exr", "previous contents");
    fs::path scene = m_dir / "bad.toml";
    writeText(scene, "[camera]\nfov = 45\n");
    ProcessResult r = runVkrt({"render", scene.string(), "-o", (m_dir / "keep.exr").string()});
    EXPECT_EQ(r.exitCode, 2);
    std::ifstream in(m_dir / "keep.exr");
    std::string contents((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(contents, "previous contents");
    ProcessResult noDir = render("missing-dir/x.exr", {"--spp", "1"});
    EXPECT_EQ(noDir.exitCode, 2);
    EXPECT_NE(noDir.output.find("missing-dir"), std::string::npos) << noDir.output;
    EXPECT_EQ(filesInDir(), (std::vector<std::string>{"bad.toml", "keep.exr"}));
}

// 3840 x 2160 needs 0.22 GiB of accumulation, more than the 128 MiB that
// lavapipe guarantees one storage buffer: it is rendered in two bands
// (render/ImageBands.h), which is valid Vulkan (--validation exits 3 on any
// message), and no pixel is left out.
TEST_F(RenderCli, UltraHdRendersInBandsWithoutValidationMessages)
{
    fs::path out = m_dir / "uhd.exr";
    std::vector<std::string> args = {"render",   kDefaultScene, "-o",    out.string(), "--width",     "3840",
                                     "--height", "2160",        "--spp", "1",          "--validation"};
    if (const char* device = std::getenv("VKRT_TEST_DEVICE")) args.insert(args.end(), {"--device", device});
    ProcessResult r = runVkrt(args);
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_EQ(r.output.find("warning"), std::string::npos) << r.output;
    ExrContents image = readExr(out);
    ASSERT_EQ(image.image.width, 3840u);
    ASSERT_EQ(image.image.height, 2160u);
    EXPECT_EQ(intAttribute(image.metadata, "spp"), 1);
    // Every row of both bands was rendered: the default scene has no black
    // pixel (sky above, lit ground below), so a row left at zero would show.
    const uint32_t width = image.image.width;
    const std::vector<float>& rgb = image.image.rgb;
    for (uint32_t y = 0; y < image.image.height; ++y) {
        double row = 0.0;
        for (uint32_t x = 0; x < width; ++x)
            for (int c = 0; c < 3; ++c) {
                float v = rgb[(size_t(y) * width + x) * 3 + c];
                ASSERT_TRUE(std::isfinite(v)) << "row " << y;
                row += v;
            }
        ASSERT_GT(row, 0.0) << "row " << y << " is black";
    }
}

TEST(DevicesCli, ListsLavapipeAsUsable)
{
    ProcessResult r = runVkrt({"devices"});
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("llvmpipe"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("* "), std::string::npos) << r.output;
}

} // namespace
} // namespace vkrt::test

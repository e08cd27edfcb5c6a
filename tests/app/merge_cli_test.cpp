// `vkrt render --shard i/n` and `vkrt merge` as a farm uses them: the merged
// shards equal one run of the same spp and seed to float rounding, and every
// mixture or malformed input is refused, naming the file or option, with
// nothing written.
#include "io/ExrFile.h"
#include "support/TestSupport.h"
#include "texture/TextureTestFiles.h"

#include <cmath>
#include <fstream>

namespace fs = std::filesystem;

namespace vkrt::test {
namespace {

const std::string kScene = std::string(VKRT_TEST_SOURCE_DIR) + "/scenes/validation/diffuse-box.toml";

class MergeCli : public ::testing::Test {
public:
    void SetUp() override
    {
        m_dir = freshTempDir(::testing::UnitTest::GetInstance()->current_test_info()->name());
        setenv("VKRT_CACHE_DIR", testCacheDir().c_str(), 1);
    }

    ProcessResult render(const std::string& output, std::vector<std::string> extra)
    {
        std::vector<std::string> args = {"render", kScene, "-o", path(output), "--width", "32", "--height", "24"};
        args.insert(args.end(), extra.begin(), extra.end());
        return runVkrt(args);
    }
    ProcessResult merge(std::vector<std::string> args)
    {
        args.insert(args.begin(), "merge");
        return runVkrt(args);
    }
    std::string path(const std::string& name) const { return (m_dir / name).string(); }

    fs::path m_dir;
};

double worstRelativeDifference(const Image& a, const Image& b)
{
    double worst = 0.0;
    for (size_t i = 0; i < a.rgb.size(); ++i) {
        if (a.rgb[i] == b.rgb[i]) continue; // +inf == +inf included
        worst = std::max(worst, std::abs(double(a.rgb[i]) - b.rgb[i]) / std::max(1e-6, std::abs(double(b.rgb[i]))));
    }
    return worst;
}

void expectShardsMergeToOneRun(MergeCli& t, const std::vector<std::string>& options, const std::string& what)
{
    std::vector<std::string> shards;
    for (int i = 0; i < 4; ++i) {
        std::vector<std::string> args = options;
        args.insert(args.end(), {"--spp", "64", "--seed", "9", "--shard", std::to_string(i) + "/4"});
        const std::string name = "shard" + std::to_string(i) + ".exr";
        ASSERT_EQ(t.render(name, args).exitCode, 0) << what;
        shards.push_back(t.path(name));
    }
    std::vector<std::string> single = options;
    single.insert(single.end(), {"--spp", "64", "--seed", "9"});
    ASSERT_EQ(t.render("single.exr", single).exitCode, 0) << what;
    std::vector<std::string> mergeArgs = shards;
    mergeArgs.insert(mergeArgs.end(), {"-o", t.path("merged.exr")});
    const ProcessResult merged = t.merge(mergeArgs);
    ASSERT_EQ(merged.exitCode, 0) << what << ": " << merged.output;
    const ExrContents a = readExr(t.path("merged.exr")), b = readExr(t.path("single.exr"));
    // Float rounding: the shards sum their samples in another order than one run.
    EXPECT_LT(worstRelativeDifference(a.image, b.image), 1e-5) << what;
    ASSERT_TRUE(a.layers.count("variance") && b.layers.count("variance")) << what;
    EXPECT_LT(worstRelativeDifference(a.layers.at("variance"), b.layers.at("variance")), 1e-4) << what;
    EXPECT_EQ(std::get<int64_t>(a.metadata.at("spp")), 64) << what;
    EXPECT_EQ(std::get<std::string>(a.metadata.at("sampler")), std::get<std::string>(b.metadata.at("sampler")));
    // The compare command's statistical test agrees: the two are one estimate.
    const ProcessResult compare = runVkrt({"compare", t.path("merged.exr"), t.path("single.exr")});
    EXPECT_EQ(compare.exitCode, 0) << what << ": " << compare.output;
}

TEST_F(MergeCli, FourShardsEqualOneRunWithIndependentSamplesAndWithSobolBatches)
{
    expectShardsMergeToOneRun(*this, {"--variance"}, "independent");
    expectShardsMergeToOneRun(*this, {"--variance", "--sampler", "sobol"}, "sobol batches");
}

TEST_F(MergeCli, MixturesOverlapsGapsAndBadFilesAreRefusedWithNothingWritten)
{
    ASSERT_EQ(render("a0.exr", {"--spp", "8", "--seed", "1", "--shard", "0/2"}).exitCode, 0);
    ASSERT_EQ(render("a1.exr", {"--spp", "8", "--seed", "1", "--shard", "1/2"}).exitCode, 0);
    ASSERT_EQ(render("b1.exr", {"--spp", "8", "--seed", "2", "--shard", "1/2"}).exitCode, 0);
    ASSERT_EQ(render("whole.exr", {"--spp", "8", "--seed", "1"}).exitCode, 0);
    {
        std::ofstream(m_dir / "broken.exr") << "v/1\x01 not really an EXR";
    }
    struct Case {
        std::vector<std::string> inputs;
        std::string message;
    };
    const std::vector<Case> cases = {
        {{"a0.exr", "b1.exr"}, "b1.exr: seed is '2', but"},
        {{"a0.exr", "a0.exr"}, "overlap those of"},
        {{"a0.exr"}, "samples [4, 8) of 8 are in no shard given"},
        {{"a0.exr", "whole.exr"}, "whole.exr: no 'shard' attribute"},
        {{"a0.exr", "broken.exr"}, "broken.exr"},
        {{"a0.exr", "absent.exr"}, "absent.exr"},
    };
    for (const Case& c : cases) {
        std::vector<std::string> args;
        for (const std::string& input : c.inputs) args.push_back(path(input));
        args.insert(args.end(), {"-o", path("out.exr")});
        const ProcessResult result = merge(args);
        EXPECT_EQ(result.exitCode, 2) << result.output;
        EXPECT_NE(result.output.find(c.message), std::string::npos) << result.output;
        EXPECT_FALSE(fs::exists(m_dir / "out.exr")) << c.message;
    }
    // With --allow-missing: the true spp and the missing range are recorded.
    ASSERT_EQ(merge({path("a1.exr"), "--allow-missing", "-o", path("part.exr")}).exitCode, 0);
    const ExrContents part = readExr(path("part.exr"));
    EXPECT_EQ(std::get<int64_t>(part.metadata.at("spp")), 4);
    EXPECT_EQ(std::get<std::string>(part.metadata.at("missingSamples")), "[0, 4)");
}

/// Rewrites a shard with one value of one tally layer replaced.
void poison(const fs::path& shard, const fs::path& out, const std::string& layer, float value)
{
    ExrContents exr = readExr(shard);
    exr.layers.at(layer).rgb[3 * (2 * exr.image.width + 5)] = value; // pixel (5, 2), red
    writeExr(out, exr.image, exr.metadata, exr.layers);
}

TEST_F(MergeCli, PoisonedTalliesAreRefusedNamingLayerAndPixel)
{
    ASSERT_EQ(render("a0.exr", {"--spp", "4", "--shard", "0/2"}).exitCode, 0);
    ASSERT_EQ(render("a1.exr", {"--spp", "4", "--shard", "1/2"}).exitCode, 0);
    struct Case {
        std::string layer;
        float value;
        std::string message;
    };
    const std::vector<Case> cases = {
        {"tally.mean", NAN, "tally.mean at pixel (5, 2) is nan, but a mean must be finite"},
        {"tally.count", 1e30f,
         "tally.count at pixel (5, 2) is 1e+30, but a count is a whole number from 0 to the 2 "
         "samples the shard covers"},
        {"tally.count", -1.0f, "tally.count at pixel (5, 2) is -1, but"},
        {"tally.count", 3.0f, "tally.count at pixel (5, 2) is 3, but"},
    };
    for (const Case& c : cases) {
        poison(path("a1.exr"), path("bad.exr"), c.layer, c.value);
        const ProcessResult result = merge({path("a0.exr"), path("bad.exr"), "-o", path("out.exr")});
        EXPECT_EQ(result.exitCode, 2) << result.output;
        EXPECT_NE(result.output.find(path("bad.exr") + ": " + c.message), std::string::npos) << result.output;
        EXPECT_FALSE(fs::exists(m_dir / "out.exr")) << c.message;
    }
}

TEST_F(MergeCli, ShardWithALyingHeaderIsRefusedInLittleMemory)
{
    ASSERT_EQ(render("a0.exr", {"--spp", "4", "--shard", "0/2"}).exitCode, 0);
    for (const auto& [side, name] : {std::pair{8192u, "big.exr"}, std::pair{16384u, "huge.exr"}}) {
        writeExrDeclaring(m_dir / name, side, side);
        const ProcessResult result = merge({path("a0.exr"), path(name), "-o", path("out.exr")});
        EXPECT_EQ(result.exitCode, 2) << result.output;
        EXPECT_NE(result.output.find(path(name) + ": the header declares"), std::string::npos) << result.output;
        EXPECT_LT(result.peakResidentBytes, kBadInputMemoryLimit);
        EXPECT_FALSE(fs::exists(m_dir / "out.exr"));
    }
}

/// The bytes of pixels reading `file` allocates: its image and every layer, float RGB.
int64_t pixelBytesOf(const fs::path& file)
{
    const ExrHeader header = readExrHeader(file);
    return int64_t(header.width) * header.height * 3 * int64_t(sizeof(float)) * int64_t(1 + header.layers.size());
}

// Headers first: a lying shard given last is refused before the good shards'
// pixels are read, so the refusal costs what reading headers costs, not the
// pixels of every shard before it (two 1024x1024 shards: ~60 MB each).
TEST_F(MergeCli, ALyingShardGivenLastIsRefusedBeforeAnyPixelsAreRead)
{
    for (const char* shard : {"0/3", "1/3"}) {
        const std::string name = std::string("good") + shard[0] + ".exr";
        const ProcessResult good = runVkrt({"render", kScene, "-o", path(name), "--width", "1024", "--height", "1024",
                                            "--spp", "3", "--shard", shard, "--sampler", "independent", "--variance"});
        ASSERT_EQ(good.exitCode, 0) << good.output;
    }
    writeExrDeclaring(m_dir / "lying.exr", 1024, 1024); // the good shards' size: only its length gives it away
    const int64_t shardPixelBytes = pixelBytesOf(m_dir / "good0.exr");
    const ProcessResult alone = merge({path("lying.exr"), "-o", path("out.exr")});
    ASSERT_EQ(alone.exitCode, 2) << alone.output;

    const ProcessResult last = merge({path("good0.exr"), path("good1.exr"), path("lying.exr"), "-o", path("out.exr")});
    EXPECT_EQ(last.exitCode, 2) << last.output;
    EXPECT_NE(last.output.find(path("lying.exr") + ": the header declares"), std::string::npos) << last.output;
    EXPECT_FALSE(fs::exists(m_dir / "out.exr"));
    EXPECT_LT(last.peakResidentBytes, kBadInputMemoryLimit);
    EXPECT_LT(last.peakResidentBytes, alone.peakResidentBytes + shardPixelBytes / 2)
        << "the good shards' pixels were read before the lying one was refused";

    // The measure can tell: merging the good shards alone reads their pixels.
    const ProcessResult goodOnly =
        merge({path("good0.exr"), path("good1.exr"), "--allow-missing", "-o", path("out.exr")});
    ASSERT_EQ(goodOnly.exitCode, 0) << goodOnly.output;
    EXPECT_GT(goodOnly.peakResidentBytes, alone.peakResidentBytes + shardPixelBytes / 2);
    for (const char* name : {"good0.exr", "good1.exr", "out.exr"}) fs::remove(m_dir / name); // ~60 MB
}

TEST_F(MergeCli, BadShardOptionsNameTheOption)
{
    for (const auto& [shard, message] :
         std::vector<std::pair<std::string, std::string>>{{"5/4", "--shard 5/4: i must be below n"},
                                                          {"0/0", "--shard 0/0: n must be at least 1"},
                                                          {"one/4", "--shard one/4: expected i/n"},
                                                          {"3", "--shard 3: expected i/n"},
                                                          {"1/80", "80 shards of 64 spp"}}) {
        const ProcessResult result = render("x.exr", {"--spp", "64", "--shard", shard});
        EXPECT_EQ(result.exitCode, 2) << result.output;
        EXPECT_NE(result.output.find(message), std::string::npos) << result.output;
        EXPECT_FALSE(fs::exists(m_dir / "x.exr"));
    }
    const ProcessResult budget = render("x.exr", {"--shard", "0/2", "--time-budget", "1"});
    EXPECT_NE(budget.output.find("--time-budget"), std::string::npos) << budget.output;
}

} // namespace
} // namespace vkrt::test

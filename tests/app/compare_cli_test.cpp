// `vkrt compare` and the render stopping rules, as scripts use them.
#include "io/ExrFile.h"
#include "support/TestSupport.h"
#include "texture/TextureTestFiles.h"

#include <fstream>
#include <sstream>

namespace fs = std::filesystem;

namespace vkrt::test {
namespace {

const std::string kScene = std::string(VKRT_TEST_SOURCE_DIR) + "/scenes/seed/area-light.toml";

class StatsCli : public ::testing::Test {
protected:
    void SetUp() override
    {
        m_dir = freshTempDir(::testing::UnitTest::GetInstance()->current_test_info()->name());
        setenv("VKRT_CACHE_DIR", testCacheDir().c_str(), 1);
    }
    fs::path m_dir;

    ProcessResult render(const std::string& output, std::vector<std::string> extra)
    {
        std::vector<std::string> args = {"render",  kScene, "-o",       (m_dir / output).string(),
                                         "--width", "48",   "--height", "36"};
        args.insert(args.end(), extra.begin(), extra.end());
        return runVkrt(args);
    }
};

struct CsvRow {
    uint32_t spp;
    double seconds, estRmse, estRelMse, estRelMseUpper, estDegreesOfFreedom;
};

std::vector<CsvRow> readReport(const fs::path& path)
{
    std::ifstream in(path);
    std::string line;
    std::vector<CsvRow> rows;
    while (std::getline(in, line)) {
        if (line.empty() || line[0] == '#' || line.rfind("spp", 0) == 0) continue;
        CsvRow r{};
        std::sscanf(line.c_str(), "%u,%lf,%lf,%lf,%lf,%lf", &r.spp, &r.seconds, &r.estRmse, &r.estRelMse,
                    &r.estRelMseUpper, &r.estDegreesOfFreedom);
        rows.push_back(r);
    }
    return rows;
}

TEST_F(StatsCli, CompareIdenticalIsZeroAndPerturbedFails)
{
    ASSERT_EQ(render("a.exr", {"--spp", "8", "--variance"}).exitCode, 0);
    ProcessResult same =
        runVkrt({"compare", (m_dir / "a.exr").string(), (m_dir / "a.exr").string(), "--max-rmse", "0"});
    EXPECT_EQ(same.exitCode, 0) << same.output;
    EXPECT_NE(same.output.find("RMSE        0\n"), std::string::npos) << same.output;

    ExrContents a = readExr(m_dir / "a.exr");
    for (float& v : a.image.rgb) v *= 1.1f;
    writeExr(m_dir / "b.exr", a.image, {}, a.layers);
    ProcessResult perturbed =
        runVkrt({"compare", (m_dir / "b.exr").string(), (m_dir / "a.exr").string(), "--max-relmse", "0.001"});
    EXPECT_EQ(perturbed.exitCode, 4) << perturbed.output;
    EXPECT_NE(perturbed.output.find("FAIL: relMSE exceeds"), std::string::npos) << perturbed.output;
}

TEST_F(StatsCli, IndependentRendersPassThePixelTestAndABiasFailsIt)
{
    ASSERT_EQ(render("a.exr", {"--spp", "64", "--variance", "--seed", "1"}).exitCode, 0);
    ASSERT_EQ(render("b.exr", {"--spp", "64", "--variance", "--seed", "2"}).exitCode, 0);
    ProcessResult r = runVkrt({"compare", (m_dir / "a.exr").string(), (m_dir / "b.exr").string()});
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("pixel test"), std::string::npos) << r.output;

    ExrContents b = readExr(m_dir / "b.exr");
    for (float& v : b.image.rgb) v *= 1.25f;
    writeExr(m_dir / "biased.exr", b.image, {}, b.layers);
    ProcessResult biased = runVkrt({"compare", (m_dir / "a.exr").string(), (m_dir / "biased.exr").string()});
    EXPECT_EQ(biased.exitCode, 4) << biased.output;
}

// Variances from the Sobol' sampler's 8 batches have 7 degrees of freedom;
// compare reads that from the EXR and uses Welch's t: two seeds agree (at
// most 0.1 % of values may fail), a 25 % bias still fails, and an attribute
// that says no estimate was made is an error, not a test that always passes.
TEST_F(StatsCli, SobolBatchVariancesPassTheWelchTestAndABiasFailsIt)
{
    ASSERT_EQ(render("a.exr", {"--spp", "64", "--sampler", "sobol", "--variance", "--seed", "1"}).exitCode, 0);
    ASSERT_EQ(render("b.exr", {"--spp", "64", "--sampler", "sobol", "--variance", "--seed", "2"}).exitCode, 0);
    ProcessResult r =
        runVkrt({"compare", (m_dir / "a.exr").string(), (m_dir / "b.exr").string(), "--min-pass", "0.999"});
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("Welch's t"), std::string::npos) << r.output;

    ExrContents b = readExr(m_dir / "b.exr");
    for (float& v : b.image.rgb) v *= 1.25f;
    writeExr(m_dir / "biased.exr", b.image, b.metadata, b.layers);
    ProcessResult biased = runVkrt({"compare", (m_dir / "a.exr").string(), (m_dir / "biased.exr").string()});
    EXPECT_EQ(biased.exitCode, 4) << biased.output;

    b.metadata["varianceDegreesOfFreedom"] = int64_t(0);
    writeExr(m_dir / "none.exr", b.image, b.metadata, b.layers);
    ProcessResult none = runVkrt({"compare", (m_dir / "a.exr").string(), (m_dir / "none.exr").string()});
    EXPECT_EQ(none.exitCode, 2) << none.output;
    EXPECT_NE(none.output.find("none.exr: attribute varianceDegreesOfFreedom"), std::string::npos) << none.output;
}

TEST_F(StatsCli, CompareRejectsMismatchedSizes)
{
    writeExr(m_dir / "small.exr", Image(4, 4), {});
    writeExr(m_dir / "big.exr", Image(5, 4), {});
    ProcessResult r = runVkrt({"compare", (m_dir / "small.exr").string(), (m_dir / "big.exr").string()});
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("big.exr: 5x4 pixels, but " + (m_dir / "small.exr").string() + " is 4x4"),
              std::string::npos)
        << r.output;
    ProcessResult missing = runVkrt({"compare", (m_dir / "nope.exr").string(), (m_dir / "big.exr").string()});
    EXPECT_EQ(missing.exitCode, 2) << missing.output;
    EXPECT_NE(missing.output.find("nope.exr"), std::string::npos) << missing.output;
}

TEST_F(StatsCli, CompareRefusesLyingHeadersQuicklyAndInLittleMemory)
{
    writeExr(m_dir / "small.exr", Image(8, 8), {});
    const fs::path big = writeExrDeclaring(m_dir / "big.exr", 8192, 8192);
    const fs::path huge = writeExrDeclaring(m_dir / "huge.exr", 16384, 16384);
    // DWAB's bound is loose (2^18): this one passes the length check and fails reading its first strip.
    const fs::path dwab = writeExrDeclaring(m_dir / "dwab.exr", 8192, 8192, 9);
    fs::resize_file(dwab, 6000);
    for (const fs::path& bad : {big, huge, dwab}) {
        for (const auto& [a, b] : {std::pair{m_dir / "small.exr", bad}, std::pair{bad, m_dir / "small.exr"}}) {
            ProcessResult r = runVkrt({"compare", a.string(), b.string()});
            EXPECT_EQ(r.exitCode, 2) << r.output;
            EXPECT_NE(r.output.find(bad.filename().string()), std::string::npos) << r.output;
            EXPECT_LT(r.peakResidentBytes, kBadInputMemoryLimit);
            EXPECT_LT(r.peakResidentBytes, int64_t(256) << 20) << bad << ": refused before its pixels were allocated";
        }
    }
}

// It stops on the estimate's upper confidence bound, not on the estimate.
TEST_F(StatsCli, TargetErrorStopsAtTheFirstCheckpointWhoseUpperBoundIsBelowIt)
{
    ProcessResult r = render("t.exr", {"--target-error", "0.02", "--report", (m_dir / "t.csv").string()});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    auto rows = readReport(m_dir / "t.csv");
    ASSERT_GE(rows.size(), 2u);
    for (size_t i = 0; i + 1 < rows.size(); ++i) EXPECT_GE(rows[i].estRelMseUpper, 0.02) << "spp " << rows[i].spp;
    EXPECT_LT(rows.back().estRelMseUpper, 0.02);
    EXPECT_LT(rows.back().estRelMse, rows.back().estRelMseUpper);
    EXPECT_GT(rows.back().estDegreesOfFreedom, 0.0);
    ExrContents exr = readExr(m_dir / "t.exr");
    EXPECT_EQ(std::get<std::string>(exr.metadata.at("stoppedBy")), "target-error");
    EXPECT_EQ(std::get<int64_t>(exr.metadata.at("spp")), int64_t(rows.back().spp));
    EXPECT_LT(std::get<double>(exr.metadata.at("estimatedRelMseUpper")), 0.02);
    const double upper = std::get<double>(exr.metadata.at("estimatedRelMseUpper"));
    EXPECT_NEAR(upper, rows.back().estRelMseUpper, 1e-8 * upper) << "the CSV's 9 digits";
}

TEST_F(StatsCli, TimeBudgetStopsWithinOneFrame)
{
    ProcessResult r = render("b.exr", {"--time-budget", "1.0"});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    ExrContents exr = readExr(m_dir / "b.exr");
    EXPECT_EQ(std::get<std::string>(exr.metadata.at("stoppedBy")), "time-budget");
    double seconds = std::get<double>(exr.metadata.at("renderSeconds"));
    double spp = double(std::get<int64_t>(exr.metadata.at("spp")));
    double frame = seconds / spp;
    EXPECT_GE(seconds, 1.0);
    // One frame past the budget, plus the frame that was running when the
    // check fired, plus 50 ms for the scheduler of a loaded 2-core machine.
    EXPECT_LE(seconds, 1.0 + 2.0 * frame + 0.05) << spp << " frames";
}

TEST_F(StatsCli, ReportHasGeometricRowsAndTheLast)
{
    ASSERT_EQ(render("a.exr", {"--spp", "8"}).exitCode, 0);
    ProcessResult r = render("r.exr", {"--spp", "12", "--report", (m_dir / "r.csv").string(), "--reference",
                                       (m_dir / "a.exr").string()});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    std::ifstream in(m_dir / "r.csv");
    std::stringstream text;
    text << in.rdbuf();
    EXPECT_NE(text.str().find("startup_seconds="), std::string::npos);
    EXPECT_NE(text.str().find("spp,seconds,est_rmse,est_relmse,est_relmse_upper,est_dof,rmse,relmse,mape"),
              std::string::npos)
        << text.str();
    auto rows = readReport(m_dir / "r.csv");
    std::vector<uint32_t> spps;
    for (const auto& row : rows) spps.push_back(row.spp);
    EXPECT_EQ(spps, (std::vector<uint32_t>{1, 2, 4, 8, 12}));
    for (size_t i = 1; i < rows.size(); ++i) EXPECT_GT(rows[i].seconds, rows[i - 1].seconds);
    ProcessResult wrongSize = runVkrt({"render", kScene, "-o", (m_dir / "x.exr").string(), "--report",
                                       (m_dir / "x.csv").string(), "--reference", (m_dir / "a.exr").string()});
    EXPECT_EQ(wrongSize.exitCode, 2);
    EXPECT_NE(wrongSize.output.find("--reference"), std::string::npos) << wrongSize.output;
}

} // namespace
} // namespace vkrt::test

// Tests of the baseline files of `vkrt regress` (regress/Expectations.h):
// deqp-runner's `case-name,Status` baseline and regular-expression lists, the
// errors that name file:line, and the rules that turn a case's attempts into
// its status (ExpectedFail, UnexpectedPass, Flake, KnownFlake, Skip).
#include "regress/Expectations.h"

#include "util/Error.h"

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>

#include <sys/stat.h>

namespace vkrt {
namespace {

namespace fs = std::filesystem;

class RegressExpectations : public ::testing::Test {
protected:
    RegressExpectations()
    {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        m_dir = fs::temp_directory_path() / ("vkrt_expectations_" + std::string(info->name()));
        fs::remove_all(m_dir);
        fs::create_directories(m_dir);
    }
    ~RegressExpectations() override
    {
        std::error_code ignored;
        fs::remove_all(m_dir, ignored);
    }

    fs::path write(const std::string& name, const std::string& text) const
    {
        const fs::path path = m_dir / name;
        std::ofstream(path, std::ios::binary) << text;
        return path;
    }

    /// The message of the InputError that reading `text` as a baseline gives.
    std::string baselineError(const std::string& text) const
    {
        const fs::path path = write("fails.txt", text);
        try {
            readBaseline(path);
        } catch (const InputError& e) {
            return e.what();
        }
        ADD_FAILURE() << "expected an error for:\n" << text;
        return "";
    }

    fs::path m_dir;
};

TEST_F(RegressExpectations, BaselineReadsStatusesCommentsAndResultsCsvLines)
{
    const auto baseline = readBaseline(write("fails.txt", "# known driver bugs\n\n"
                                                          "extreme/tir,Fail\n"
                                                          "  seed/glass , Crash \n"
                                                          "extreme/ior-one,Timeout,183.250\n"));
    ASSERT_EQ(baseline.size(), 3u);
    EXPECT_EQ(baseline.at("extreme/tir").status, CaseStatus::Fail);
    EXPECT_EQ(baseline.at("seed/glass").status, CaseStatus::Crash);
    EXPECT_EQ(baseline.at("extreme/ior-one").status, CaseStatus::Timeout); // a failures.csv line: duration ignored
    EXPECT_EQ(baseline.at("extreme/tir").where, (m_dir / "fails.txt").string() + ":3");
}

TEST_F(RegressExpectations, BadBaselineLinesNameFileAndLine)
{
    const std::string file = (m_dir / "fails.txt").string();
    EXPECT_NE(baselineError("# header\nextreme/tir\n").find(file + ":2: expected 'case-name,Status'"),
              std::string::npos);
    EXPECT_NE(baselineError("a,Fail\nb,Broken\n").find(file + ":2: status 'Broken' cannot be expected"),
              std::string::npos);
    EXPECT_NE(baselineError("a,UnexpectedPass\n").find("the case passes now; remove the line"), std::string::npos);
    EXPECT_NE(baselineError("a,Flake\n").find("--flakes"), std::string::npos);
    EXPECT_NE(baselineError("a,Fail\n\na,Crash\n").find(file + ":3: case a is already listed (" + file + ":1)"),
              std::string::npos);
    EXPECT_NE(baselineError(",Fail\n").find(file + ":1:"), std::string::npos);
    EXPECT_NE(baselineError("a,Fail,1,2\n").find(file + ":1:"), std::string::npos);
}

TEST_F(RegressExpectations, MissingFileIsNamedWithItsOption)
{
    try {
        readExpectations({}, m_dir / "nope.txt", {});
        ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("--flakes " + (m_dir / "nope.txt").string() + ": no such file"),
                  std::string::npos)
            << e.what();
    }
}

TEST_F(RegressExpectations, PatternsMatchAnywhereAndBadOnesNameTheLine)
{
    const Expectations e = readExpectations({}, write("flakes.txt", "# flaky on lavapipe\nkappa-\n^seed/glass$\n"),
                                            write("skips.txt", "validation/.*texture\n"));
    EXPECT_TRUE(e.isKnownFlake("extreme/kappa-shadow"));
    EXPECT_TRUE(e.isKnownFlake("seed/glass"));
    EXPECT_FALSE(e.isKnownFlake("seed/glass-area-light"));
    EXPECT_TRUE(e.isSkipped("validation/texture-checker"));
    EXPECT_FALSE(e.isSkipped("extreme/tir"));
    try {
        readNamePatterns(write("bad.txt", "fine\n\n(unclosed\n"), "--skips");
        ADD_FAILURE() << "no error";
    } catch (const InputError& error) {
        EXPECT_NE(
            std::string(error.what()).find((m_dir / "bad.txt").string() + ":3: not a regular expression: '(unclosed'"),
            std::string::npos)
            << error.what();
    }
}

// Patterns are matched in time linear in the name (RE2): the nested stars that
// take a backtracking matcher over 30 s on one name take microseconds, and a
// line of 100,000 characters (a crash of the recursive matcher) is refused.
TEST_F(RegressExpectations, PatternsCannotHangOrCrashTheRun)
{
    const Expectations e = readExpectations({}, write("flakes.txt", "^(.*.*.*.*.*.*.*.*.*.*)*Q$\n"), {});
    const auto start = std::chrono::steady_clock::now();
    for (int i = 0; i < 100; ++i)
        EXPECT_FALSE(e.isKnownFlake(std::string(200, 'a') + "/validation-case-" + std::to_string(i)));
    EXPECT_TRUE(e.isKnownFlake("aQ"));
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(1));
    for (const char* option : {"--flakes", "--skips"}) {
        try {
            readNamePatterns(write("long.txt", "x\n" + std::string(100000, 'a') + "\n"), option);
            ADD_FAILURE() << option << ": a 100,000-byte line was accepted";
        } catch (const InputError& error) {
            const std::string message = error.what();
            EXPECT_NE(message.find((m_dir / "long.txt").string() + ":2: a line of 100000 bytes, more than the 1024"),
                      std::string::npos)
                << message;
            EXPECT_LT(message.size(), 400u) << "the line is echoed cut to 96 bytes";
        }
    }
    // A baseline line as long is refused the same way, echoed cut.
    const std::string error = baselineError(std::string(8 << 20, 'n') + ",Fail\n");
    EXPECT_NE(error.find(":1: a line of 8388613 bytes"), std::string::npos) << error.substr(0, 300);
    EXPECT_LT(error.size(), 400u);
}

TEST_F(RegressExpectations, ADirectoryOrAFifoIsNamedForWhatItIs)
{
    fs::create_directories(m_dir / "folder");
    ASSERT_EQ(mkfifo((m_dir / "pipe").c_str(), 0600), 0);
    for (const auto& [name, what] :
         {std::pair<const char*, const char*>{"folder", "is a directory"}, {"pipe", "is not a regular file"}}) {
        try {
            readBaseline(m_dir / name);
            ADD_FAILURE() << name << " was read";
        } catch (const InputError& error) {
            EXPECT_NE(std::string(error.what()).find(std::string(": ") + what), std::string::npos) << error.what();
        }
    }
}

TEST_F(RegressExpectations, BaselineLineNamingNoCaseIsReported)
{
    Expectations e;
    e.baseline = readBaseline(write("fails.txt", "extreme/tir,Fail\nextreme/tirr,Fail\n"));
    const auto warnings = baselineLinesNamingNoCase(e, {"extreme/tir", "seed/glass"});
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_EQ(warnings[0], (m_dir / "fails.txt").string() + ":2: no case named extreme/tirr in the suite");
}

// The rules of docs/regress.md, "Statuses", one by one.
TEST_F(RegressExpectations, AttemptsBecomeTheCaseStatus)
{
    Expectations e;
    e.baseline = readBaseline(write("fails.txt", "listed-fail,Fail\nlisted-crash,Crash\n"));
    e.flakes = readNamePatterns(write("flakes.txt", "known\n"), "--flakes");
    using S = CaseStatus;
    EXPECT_EQ(caseStatus("new", {S::Pass}, e), S::Pass);
    EXPECT_EQ(caseStatus("new", {S::Fail, S::Fail}, e), S::Fail);
    EXPECT_EQ(caseStatus("new", {S::Crash, S::Fail}, e), S::Crash); // the first failure counts
    EXPECT_EQ(caseStatus("new", {S::Timeout, S::Pass}, e), S::Flake);
    EXPECT_EQ(caseStatus("known-flaky", {S::Fail, S::Pass}, e), S::KnownFlake);
    EXPECT_EQ(caseStatus("known-flaky", {S::Fail, S::Fail}, e), S::Fail); // a listed flake that fails twice fails
    EXPECT_EQ(caseStatus("listed-fail", {S::Fail}, e), S::ExpectedFail);
    EXPECT_EQ(caseStatus("listed-fail", {S::Pass}, e), S::UnexpectedPass);
    EXPECT_EQ(caseStatus("listed-crash", {S::Crash}, e), S::ExpectedFail);
    EXPECT_EQ(caseStatus("listed-crash", {S::Fail, S::Fail}, e), S::Fail); // failing otherwise than listed
    EXPECT_EQ(caseStatus("skipped", {}, e), S::Skip);

    EXPECT_TRUE(needsRetry("new", S::Fail, e));
    EXPECT_TRUE(needsRetry("new", S::Timeout, e));
    EXPECT_FALSE(needsRetry("new", S::Pass, e));
    EXPECT_FALSE(needsRetry("listed-fail", S::Fail, e)); // expected: nothing to learn from a re-run
    EXPECT_TRUE(needsRetry("listed-fail", S::Crash, e));

    for (S s : {S::Fail, S::Crash, S::Timeout, S::UnexpectedPass}) EXPECT_TRUE(failsTheRun(s)) << statusName(s);
    for (S s : {S::Pass, S::Flake, S::KnownFlake, S::ExpectedFail, S::Skip})
        EXPECT_FALSE(failsTheRun(s)) << statusName(s);
    for (S s :
         {S::Pass, S::Fail, S::Crash, S::Timeout, S::Flake, S::Skip, S::ExpectedFail, S::UnexpectedPass, S::KnownFlake})
        EXPECT_EQ(statusNamed(statusName(s)), s);
}

} // namespace
} // namespace vkrt

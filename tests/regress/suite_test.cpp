// Tests of the regression-suite manifest reader: a valid manifest gives the
// expected cases, and every bad one a SceneError at the offending position,
// worded like scene-file errors.
#include "regress/Suite.h"

#include "scene/TomlTraps.h"
#include "util/Error.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>

namespace vkrt {
namespace {

namespace fs = std::filesystem;

/// A folder with a manifest and the scene file its cases name.
class SuiteFile : public ::testing::Test {
protected:
    SuiteFile()
    {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        m_dir = fs::temp_directory_path() / ("vkrt_suite_" + std::string(info->test_suite_name()) + "_" + info->name());
        fs::remove_all(m_dir);
        fs::create_directories(m_dir / "scenes");
        std::ofstream(m_dir / "scenes" / "a.toml") << "# any file will do: the suite reader only checks it exists\n";
    }
    ~SuiteFile() override
    {
        std::error_code ignored;
        fs::remove_all(m_dir, ignored);
    }

    fs::path write(const std::string& text) const
    {
        const fs::path path = m_dir / "suite.toml";
        std::ofstream(path, std::ios::binary) << text;
        return path;
    }

    /// Reads a manifest that must be rejected; returns the error.
    SceneError errorFor(const std::string& text) const
    {
        try {
            readRegressionSuite(write(text));
        } catch (const SceneError& error) {
            EXPECT_EQ(error.where().file, (m_dir / "suite.toml").string());
            return error;
        }
        ADD_FAILURE() << "expected a SceneError for:\n" << text;
        return SceneError({}, "");
    }

    /// Checks the message (without location) and the position of the error for `text`.
    void expectError(const std::string& text, int line, int column, const std::string& message) const
    {
        const SceneError error = errorFor(text);
        EXPECT_EQ(error.message(), message);
        EXPECT_EQ(error.where().line, line) << error.what();
        EXPECT_EQ(error.where().column, column) << error.what();
    }

    fs::path m_dir;
};

/// One complete case, lines 1-7 (8 with `extra`).
std::string caseText(const std::string& name = "a", const std::string& extra = "", const std::string& source = "vkrt")
{
    return "[[case]]\nname = \"" + name +
           "\"\nscene = \"scenes/a.toml\"\nreference = \"refs/a\"\nreference_source = \"" + source +
           "\"\nreference_spp = 4096\nspp = 32\n" + extra;
}

TEST_F(SuiteFile, ValidManifestWithDefaultsAndResolvedPaths)
{
    const RegressionSuite suite =
        readRegressionSuite(write("[suite]\nalpha = 0.05\nmin_pass = 1\nseed = 0\n" +
                                  caseText("a", "width = 32\nheight = 24\nmax_rejected = 3\n") +
                                  caseText("b", "baseline_seconds = 2\nshards = 4\n", "mitsuba")));
    EXPECT_DOUBLE_EQ(suite.alpha, 0.05);
    EXPECT_DOUBLE_EQ(suite.pooledAlpha, 0.001);
    EXPECT_DOUBLE_EQ(suite.minPass, 1.0);
    EXPECT_EQ(suite.seed, 0u);
    ASSERT_EQ(suite.cases.size(), 2u);
    const RegressionCase& a = suite.cases[0];
    EXPECT_EQ(a.name, "a");
    EXPECT_EQ(a.scene, (m_dir / "scenes/a.toml").lexically_normal());
    EXPECT_EQ(a.referenceDir, (m_dir / "refs/a").lexically_normal());
    EXPECT_EQ(a.source, ReferenceSource::Vkrt);
    EXPECT_EQ(a.referenceSpp, 4096u);
    EXPECT_EQ(a.spp, 32u);
    EXPECT_EQ(a.width, 32u);
    EXPECT_EQ(a.height, 24u);
    EXPECT_EQ(a.maxRejected, 3u);
    EXPECT_EQ(a.shards, 1u);
    EXPECT_EQ(suite.cases[1].shards, 4u);
    EXPECT_EQ(suite.cases[1].source, ReferenceSource::Mitsuba);
    EXPECT_DOUBLE_EQ(suite.cases[1].baselineSeconds, 2.0);
    EXPECT_FALSE(suite.cases[1].width.has_value());
}

TEST_F(SuiteFile, UnknownKeysSuggestTheCloseOneWhereTheyStand)
{
    expectError(caseText("a", "sp = 4\n"), 8, 1, "case[0]: unknown key 'sp'; did you mean 'spp'?");
    // Two swapped pairs: two edits with transpositions (plain Levenshtein: four, no hint).
    expectError("[suite]\nmni_psas = 0.5\n" + caseText(), 2, 1,
                "suite: unknown key 'mni_psas'; did you mean 'min_pass'?");
    expectError("[suit]\n" + caseText(), 1, 2, "unknown top-level table 'suit'; did you mean 'suite'?");
    expectError("title = \"x\"\n" + caseText(), 1, 1, "unknown top-level key 'title'");
}

TEST_F(SuiteFile, UnknownKeysAreReportedInFileOrder)
{
    // Alphabetically 'aaa' comes first; the file has 'zzz' first.
    expectError(caseText("a", "zzz = 1\naaa = 2\n"), 8, 1, "case[0]: unknown key 'zzz'");
}

TEST_F(SuiteFile, WrongTypesNameBothTypes)
{
    expectError(caseText("a", "width = \"32\"\n"), 8, 9, "case[0].width: expected an integer, got a string");
    expectError(caseText("a", "height = 24.0\n"), 8, 10, "case[0].height: expected an integer, got a float");
    expectError("[suite]\nalpha = \"0.1\"\n" + caseText(), 2, 9, "suite.alpha: expected a number, got a string");
    expectError("[[case]]\nname = 3\n", 2, 8, "case[0].name: expected a string, got an integer");
    expectError("suite = 1\n" + caseText(), 1, 9, "suite: expected a table, got an integer");
    expectError("[case]\nname = \"a\"\n", 1, 1, "case: expected an array of tables ([[case]]), got a table");
}

TEST_F(SuiteFile, OutOfRangeValuesNameTheRange)
{
    expectError("[suite]\nalpha = 1.5\n" + caseText(), 2, 9, "suite.alpha: must be in (0, 1), got 1.5");
    expectError("[suite]\npooled_alpha = 0\n" + caseText(), 2, 16, "suite.pooled_alpha: must be in (0, 1), got 0");
    expectError("[suite]\nmin_pass = 1.01\n" + caseText(), 2, 12, "suite.min_pass: must be in (0, 1], got 1.01");
    expectError("[suite]\nmax_slowdown = inf\n" + caseText(), 2, 16, "suite.max_slowdown: must be finite, got inf");
    expectError("[suite]\nseed = -1\n" + caseText(), 2, 8, "suite.seed: must be between 0 and 4294967295, got -1");
    expectError(caseText("a", "width = 0\n"), 8, 9, "case[0].width: must be between 1 and 4294967295, got 0");
    expectError(caseText("a", "baseline_seconds = -2\n"), 8, 20, "case[0].baseline_seconds: must be > 0, got -2");
    expectError(caseText("a", "shards = 0\n"), 8, 10, "case[0].shards: must be between 1 and 4294967295, got 0");
    expectError(caseText("a", "shards = 33\n"), 8, 10,
                "case[0].shards: 33 shards of 32 spp would leave some without samples; use at most spp shards");
}

TEST_F(SuiteFile, ReferenceSourceIsAChoice)
{
    const std::string text = "[[case]]\nname = \"a\"\nscene = \"scenes/a.toml\"\nreference = \"r\"\n"
                             "reference_source = \"mitsuab\"\n";
    expectError(text, 5, 20,
                "case[0].reference_source: unknown reference source 'mitsuab'; did you mean 'mitsuba'? "
                "(expected one of: mitsuba, vkrt)");
}

TEST_F(SuiteFile, MissingThingsAreReportedAtTheirTable)
{
    expectError(caseText() + "[[case]]\nname = \"b\"\n", 8, 1, "case[1]: missing required key 'scene'");
    expectError("[suite]\nseed = 2\n", 1, 1, "no [[case]] entries");
    expectError("case = []\n", 1, 8, "case: no [[case]] entries");
    expectError("[[case]]\nname = \"a\"\nscene = \"scenes/none.toml\"\n", 3, 9,
                "case[0].scene: no such file " + (m_dir / "scenes/none.toml").string());
}

TEST_F(SuiteFile, DuplicateCaseNamesPointAtTheSecond)
{
    expectError(caseText("a") + caseText("a"), 9, 8, "case[1].name: duplicate case name 'a' (first used on line 2)");
}

TEST_F(SuiteFile, MissingManifestIsAnInputErrorNamingTheOption)
{
    try {
        readRegressionSuite(m_dir / "nope.toml");
        FAIL() << "a missing manifest was read";
    } catch (const SceneError& error) {
        FAIL() << "expected a plain InputError, got " << error.what();
    } catch (const InputError& error) {
        EXPECT_EQ(std::string(error.what()), "--suite " + (m_dir / "nope.toml").string() + ": no such file");
    }
}

class SuiteFileTomlTrap : public SuiteFile, public ::testing::WithParamInterface<TomlTrap> {};

TEST_P(SuiteFileTomlTrap, IsALocatedSyntaxError)
{
    const std::string& line = GetParam().text;
    for (const std::string& before : {std::string(), caseText()}) {
        const SceneError error = errorFor(before + line + "\n");
        const int expectedLine = before.empty() ? 1 : 8;
        EXPECT_EQ(error.where().line, expectedLine) << error.what();
        EXPECT_GE(error.where().column, 1) << error.what();
        EXPECT_LE(error.where().column, int(line.size()) + 1) << error.what();
        EXPECT_EQ(error.message().rfind("invalid TOML: ", 0), 0u) << error.what();
    }
}

INSTANTIATE_TEST_SUITE_P(TomlTraps, SuiteFileTomlTrap, ::testing::ValuesIn(kTomlTraps),
                         [](const ::testing::TestParamInfo<TomlTrap>& info) { return info.param.name; });

/// The case counts docs/regress.md gives for the default suite: the total, and
/// per row of its table each `pattern` (n), where "prefix/*" counts the cases
/// whose name starts with "prefix/" and a plain name counts that case.
struct DocumentedCounts {
    size_t total = 0;
    std::map<std::string, size_t> perPattern;
};

DocumentedCounts documentedCounts(const fs::path& doc)
{
    std::ifstream file(doc);
    std::stringstream text;
    text << file.rdbuf();
    const std::string all = text.str();
    DocumentedCounts counts;
    std::smatch match;
    if (!std::regex_search(all, match, std::regex("`tests/regress/suite\\.toml`, ([0-9]+) cases"))) return counts;
    counts.total = std::stoul(match[1]);
    // The table follows the sentence; its first column names the cases.
    std::istringstream rest(match.suffix().str());
    std::string line;
    bool inTable = false;
    const std::regex pattern("`([^`]+)` \\(([0-9]+)\\)");
    while (std::getline(rest, line)) {
        if (line.rfind("|", 0) != 0) {
            if (inTable) break;
            continue;
        }
        inTable = true;
        const std::string firstCell = line.substr(1, line.find('|', 1) - 1);
        for (auto it = std::sregex_iterator(firstCell.begin(), firstCell.end(), pattern); it != std::sregex_iterator();
             ++it)
            counts.perPattern[(*it)[1]] = std::stoul((*it)[2]);
    }
    return counts;
}

bool caseMatches(const std::string& name, const std::string& pattern)
{
    if (pattern.size() >= 2 && pattern.ends_with("/*"))
        return name.rfind(pattern.substr(0, pattern.size() - 1), 0) == 0;
    return name == pattern;
}

/// docs/regress.md says how many cases the default suite has and which rows
/// hold them: a case added to the manifest without the doc fails here.
TEST(DefaultSuiteDoc, CountsMatchTheManifest)
{
    const fs::path root = VKRT_TEST_SOURCE_DIR;
    const RegressionSuite suite = readRegressionSuite(root / "tests/regress/suite.toml");
    const DocumentedCounts doc = documentedCounts(root / "docs/regress.md");
    ASSERT_GT(doc.total, 0u) << "docs/regress.md no longer says \"`tests/regress/suite.toml`, N cases\"";
    ASSERT_FALSE(doc.perPattern.empty()) << "docs/regress.md: no `pattern` (n) in the table after the count";
    EXPECT_EQ(doc.total, suite.cases.size()) << "docs/regress.md gives the default suite's case count";
    size_t rowTotal = 0;
    for (const auto& [pattern, count] : doc.perPattern) {
        const size_t actual =
            size_t(std::count_if(suite.cases.begin(), suite.cases.end(),
                                 [&](const RegressionCase& c) { return caseMatches(c.name, pattern); }));
        EXPECT_EQ(count, actual) << "docs/regress.md: `" << pattern << "`";
        rowTotal += count;
    }
    EXPECT_EQ(rowTotal, doc.total) << "docs/regress.md: the table's rows do not add up to the count";
    for (const RegressionCase& c : suite.cases) {
        const bool covered = std::any_of(doc.perPattern.begin(), doc.perPattern.end(),
                                         [&](const auto& entry) { return caseMatches(c.name, entry.first); });
        EXPECT_TRUE(covered) << c.name << " is in no row of docs/regress.md's table";
    }
}

} // namespace
} // namespace vkrt

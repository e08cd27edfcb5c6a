// Tests of the validated-TOML toolkit shared by the scene and suite parsers:
// the bounded edit distance agrees with the textbook table, suggestions stay
// close, and typed readers word their failures with a location.
#include "scene/TomlReader.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <string>
#include <vector>

namespace vkrt {
namespace {

/// Optimal string alignment distance with the full (|a|+1) x (|b|+1) table.
size_t referenceDistance(const std::string& a, const std::string& b)
{
    std::vector<std::vector<size_t>> d(a.size() + 1, std::vector<size_t>(b.size() + 1));
    for (size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
    for (size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
    for (size_t i = 1; i <= a.size(); ++i) {
        for (size_t j = 1; j <= b.size(); ++j) {
            d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
                d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
        }
    }
    return d[a.size()][b.size()];
}

std::string randomWord(std::mt19937& rng, size_t maxLength)
{
    // Three letters make repeats, swaps and near matches common.
    std::uniform_int_distribution<size_t> length(0, maxLength);
    std::uniform_int_distribution<int> letter('a', 'c');
    std::string word(length(rng), ' ');
    for (char& c : word) c = static_cast<char>(letter(rng));
    return word;
}

TEST(TomlReaderEditDistance, KnownPairs)
{
    EXPECT_EQ(boundedEditDistance("lambret", "lambert", 2), 1u);
    EXPECT_EQ(boundedEditDistance("ab", "ba", 2), 1u);
    EXPECT_EQ(boundedEditDistance("", "ab", 2), 2u);
    EXPECT_EQ(boundedEditDistance("fov", "fov", 2), 0u);
    EXPECT_EQ(boundedEditDistance("kitten", "sitting", 2), 3u); // 3 edits: reported as limit + 1
    EXPECT_EQ(boundedEditDistance("kitten", "sitting", 5), 3u);
    EXPECT_EQ(boundedEditDistance("a", "abcd", 2), 3u); // lengths differ by more than the limit
}

TEST(TomlReaderEditDistance, AgreesWithFullTableUpToTheLimit)
{
    std::mt19937 rng(14);
    for (int trial = 0; trial < 20000; ++trial) {
        const std::string a = randomWord(rng, 9), b = randomWord(rng, 9);
        const size_t limit = static_cast<size_t>(trial % 4);
        const size_t expected = std::min(referenceDistance(a, b), limit + 1);
        ASSERT_EQ(boundedEditDistance(a, b, limit), expected) << "'" << a << "' vs '" << b << "', limit " << limit;
    }
}

TEST(TomlReaderEditDistance, LongWordsAreCheap)
{
    // 40,000 x 40,000 cells would be 12.8 GB as a full table.
    const std::string a(40000, 'a');
    std::string b(39999, 'a');
    b += 'b'; // not `std::string&& + "b"`: GCC 14 reports a false -Warray-bounds there at -O2
    EXPECT_EQ(boundedEditDistance(a, b, 2), 1u);
    EXPECT_EQ(boundedEditDistance(a, std::string(40000, 'b'), 2), 3u);
}

TEST(TomlReaderSuggestions, ClosestWithinTwoEditsOrCaseOnly)
{
    const std::vector<std::string_view> keys{"eye", "target", "up", "fov", "width", "height"};
    EXPECT_EQ(closestMatch("fvo", keys), "fov");
    EXPECT_EQ(closestMatch("HEIGHT", keys), "height");
    EXPECT_EQ(closestMatch("zoom", keys), std::nullopt);
    EXPECT_EQ(closestMatch("x", keys), std::nullopt); // 'up' is two edits, but every letter
    EXPECT_EQ(didYouMean("eyes", keys), "; did you mean 'eye'?");
    EXPECT_EQ(didYouMean("zoom", keys), "");
}

TEST(TomlReaderSuggestions, WordsBeyondTheLengthCapGetNone)
{
    const std::string name(129, 'a');
    // .append, not `std::string&& + "b"`: GCC 14 reports a false -Warray-bounds there at -O2.
    const std::string typo = std::string(128, 'a').append("b");
    const std::vector<std::string_view> names{name};
    EXPECT_EQ(closestMatch(typo, names), std::nullopt);
    const std::string shorter(128, 'a'), shorterTypo = std::string(127, 'a').append("b");
    const std::vector<std::string_view> shorterNames{shorter};
    EXPECT_EQ(closestMatch(shorterTypo, shorterNames), std::string_view(shorter));
}

/// Parses `text` as "t.toml" and reads the value of key `v` with `read`; returns the error message with its location.
template <class Read>
std::string readError(const std::string& text, Read read)
{
    const TomlSource source{"t.toml", "."};
    const toml::table root = parseToml(text, source);
    const TableField top(Field(source, root, ""));
    try {
        read(top.require("v"));
    } catch (const SceneError& error) {
        return error.what();
    }
    return "no error";
}

TEST(TomlReaderValues, TypedFailuresNameLocationPathAndBothTypes)
{
    EXPECT_EQ(readError("v = \"1\"\n", readNumber), "t.toml:1:5: v: expected a number, got a string");
    EXPECT_EQ(readError("\nv = 1.5\n", [](const Field& f) { return readInteger(f, 0, 9); }),
              "t.toml:2:5: v: expected an integer, got a float");
    EXPECT_EQ(readError("v = 2\n", readBool), "t.toml:1:5: v: expected a boolean (true or false), got an integer");
    EXPECT_EQ(readError("v = [1, 2]\n", readVector), "t.toml:1:5: v: expected an array of 3 numbers, got 2 element(s)");
    EXPECT_EQ(readError("v = 1979-05-27\n", readString), "t.toml:1:5: v: expected a string, got a date");
}

TEST(TomlReaderValues, RangesAreWrittenAsIntervals)
{
    const auto unitOpen = [](const Field& f) { return readNumberIn(f, {0, 1, true, true}); };
    const auto unitHalfOpen = [](const Field& f) { return readNumberIn(f, {0, 1, true, false}); };
    EXPECT_EQ(readError("v = 1\n", unitOpen), "t.toml:1:5: v: must be in (0, 1), got 1");
    EXPECT_EQ(readError("v = 0\n", unitHalfOpen), "t.toml:1:5: v: must be in (0, 1], got 0");
    EXPECT_EQ(readError("v = 1\n", unitHalfOpen), "no error");
    EXPECT_EQ(readError("v = 0.5\n", unitOpen), "no error");
    EXPECT_EQ(readError("v = nan\n", unitOpen), "t.toml:1:5: v: must be finite, got nan");
    EXPECT_EQ(readError("v = -3\n", [](const Field& f) { return readInteger(f, 1, 7); }),
              "t.toml:1:5: v: must be between 1 and 7, got -3");
}

/// The location and message of parsing `text`, or "parsed".
std::string parseOutcome(const std::string& text)
{
    try {
        parseToml(text, {"t.toml", "."});
    } catch (const SceneError& error) {
        return error.what();
    }
    return "parsed";
}

TEST(TomlReaderUtf8, WellFormedTextOfEveryLengthParses)
{
    // U+00E9, U+20AC, U+1F600 and U+10FFFF: two, three and four bytes.
    EXPECT_EQ(parseOutcome("v = \"\xC3\xA9 \xE2\x82\xAC \xF0\x9F\x98\x80 \xF4\x8F\xBF\xBF\"\n"), "parsed");
    EXPECT_EQ(parseOutcome("\xEF\xBB\xBFv = 1\n"), "parsed"); // a byte-order mark
}

TEST(TomlReaderUtf8, LineEndingBackslashBeforeNonAsciiText)
{
    // Valid TOML on which toml++ 3.3 reaches its __builtin_unreachable while
    // skipping whitespace; the compiled library vkrt links reads it correctly.
    const toml::table root = parseToml("v = \"\"\"a\\  \n  \xC3\xA9\"\"\"\n", {"t.toml", "."});
    EXPECT_EQ(root["v"].value_or(std::string()), "a\xC3\xA9");
}

TEST(TomlReaderUtf8, InvalidBytesAreLocatedExactly)
{
    const std::string prefix = "a = 1\n# \xC3\xA9"; // line 2: '#', ' ', then one two-byte code point
    const auto at4 = [](const std::string& hex) {
        return "t.toml:2:4: invalid TOML: invalid UTF-8 (byte " + hex + "); TOML files must be UTF-8";
    };
    EXPECT_EQ(parseOutcome(prefix + "\xE9\n"), at4("0xE9"));             // Latin-1 'e acute'
    EXPECT_EQ(parseOutcome(prefix + "\x80\n"), at4("0x80"));             // a lone continuation byte
    EXPECT_EQ(parseOutcome(prefix + "\xC0\xAF\n"), at4("0xC0"));         // overlong '/'
    EXPECT_EQ(parseOutcome(prefix + "\xED\xA0\x80\n"), at4("0xED"));     // a UTF-16 surrogate
    EXPECT_EQ(parseOutcome(prefix + "\xF4\x90\x80\x80\n"), at4("0xF4")); // above U+10FFFF
    EXPECT_EQ(parseOutcome(prefix + "\xE2\x82"), at4("0xE2"));           // cut short by the end of the file
}

TEST(TomlReaderTables, UnknownKeysAreReportedInFileOrder)
{
    const TomlSource source{"t.toml", "."};
    // toml::table iterates by name ('aaa' first); the file has 'zzz' first.
    const toml::table root = parseToml("[t]\nok = 1\nzzz = 2\naaa = 3\n", source);
    const TableField table(TableField(Field(source, root, "")).require("t"));
    const std::array<std::string_view, 1> allowed{"ok"};
    try {
        table.rejectUnknownKeys(allowed);
        FAIL() << "unknown keys accepted";
    } catch (const SceneError& error) {
        EXPECT_EQ(std::string(error.what()), "t.toml:3:1: t: unknown key 'zzz'");
    }
}

TEST(TomlReaderTables, EntriesComeInFileOrder)
{
    const TomlSource source{"t.toml", "."};
    const toml::table root = parseToml("[t]\nb = 1\nc = 2\na = 3\n", source);
    const TableField table(TableField(Field(source, root, "")).require("t"));
    std::string order;
    for (const auto& [key, field] : table.entriesInFileOrder()) order += std::string(key) + field.path();
    EXPECT_EQ(order, "bt.bct.cat.a");
}

TEST(TomlReaderTables, ChoicesSuggestAndListTheAlternatives)
{
    enum class Pick { One, Two };
    static constexpr std::array<EnumName<Pick>, 2> picks{{{"one", Pick::One}, {"two", Pick::Two}}};
    const auto readPick = [](const Field& f) { return readChoice(f, "pick", picks).value; };
    EXPECT_EQ(readError("v = \"noe\"\n", readPick),
              "t.toml:1:5: v: unknown pick 'noe'; did you mean 'one'? (expected one of: one, two)");
    EXPECT_EQ(readError("v = \"two\"\n", readPick), "no error");
}

} // namespace
} // namespace vkrt

// Tests of the validated-TOML toolkit shared by the scene and suite parsers:
// the bounded edit distance agrees with the textbook table, suggestions stay
// close, and typed readers word their failures with a location.
#include "scene/TomlReader.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

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

// ------------------------------------------------------------------ bounds (issue 26)

std::string repeated(const std::string& part, int count, const std::string& separator)
{
    std::string out;
    for (int i = 0; i < count; ++i) out += (i ? separator : "") + part;
    return out;
}

const std::string kTooDeep = "invalid TOML: tables and arrays nest more than 128 levels deep here (each part of a "
                             "dotted key or table header is a level); vkrt accepts at most 128";

TEST(TomlReaderNesting, DeepHeadersAndDottedKeysAreRefusedBeforeTomlxxRecurses)
{
    // 50,000 parts overflowed the stack inside toml++; the error is at the 129th part.
    EXPECT_EQ(parseOutcome("[" + repeated("a", 50000, ".") + "]\nx = 1\n"), "t.toml:1:257: " + kTooDeep);
    EXPECT_EQ(parseOutcome("\n" + repeated("a", 50000, ".") + " = 1\n"), "t.toml:2:256: " + kTooDeep);
    EXPECT_EQ(parseOutcome("[[" + repeated("a", 50000, ".") + "]]\n"), "t.toml:1:256: " + kTooDeep);
    EXPECT_EQ(parseOutcome("[" + repeated("a", 128, ".") + "]\nx = 1\n"), "parsed");
    EXPECT_EQ(parseOutcome(repeated("a", 128, ".") + " = 1\n"), "parsed");
}

TEST(TomlReaderNesting, LevelsAddUpAcrossHeadersKeysArraysAndInlineTables)
{
    const std::string header = "[" + repeated("a", 100, ".") + "]\n"; // 100 levels
    EXPECT_EQ(parseOutcome(header + repeated("b", 28, ".") + " = 1\n"), "parsed");
    EXPECT_EQ(parseOutcome(header + repeated("b", 29, ".") + " = 1\n").substr(0, 12), "t.toml:2:56:");
    EXPECT_EQ(parseOutcome(header + "v = " + std::string(27, '[') + "1" + std::string(27, ']') + "\n"), "parsed");
    EXPECT_EQ(parseOutcome(header + "v = " + std::string(28, '[') + "1" + std::string(28, ']') + "\n"),
              "t.toml:2:32: " + kTooDeep);
    // An inline table is its key's value; its dotted keys add their parts: 101 + 9 x 3 = 128 levels.
    const auto inlineChain = [](int n) { return repeated("{x.y.z = ", n, "") + "1" + std::string(n, '}'); };
    EXPECT_EQ(parseOutcome(header + "v = " + inlineChain(9) + "\n"), "parsed");
    EXPECT_NE(parseOutcome(header + "v = " + inlineChain(10) + "\n").find(kTooDeep), std::string::npos);
    // A later line of the same table starts again from the header's depth.
    EXPECT_EQ(parseOutcome(header + "v = [[[1]]]\n" + repeated("b", 26, ".") + " = [2, {c = 3}]\n"), "parsed");
}

TEST(TomlReaderNesting, StringsAndCommentsDoNotCount)
{
    const std::string dots(10000, '.'), brackets(10000, '[');
    EXPECT_EQ(parseOutcome("\"" + dots + "\" = 1\n"), "parsed");
    EXPECT_EQ(parseOutcome("'" + dots + "' = 1\n"), "parsed");
    EXPECT_EQ(parseOutcome("v = \"" + brackets + "\"\n"), "parsed");
    EXPECT_EQ(parseOutcome("v = '''\n" + brackets + "\n" + dots + "'''\n"), "parsed");
    EXPECT_EQ(parseOutcome("v = \"\"\"\\\"\"\"" + brackets + "\"\"\"\"\"\nw = 1\n"),
              "parsed"); // escaped and extra quotes
    EXPECT_EQ(parseOutcome("# " + brackets + dots + "\nv = 1 # " + brackets + "\n"), "parsed");
    EXPECT_EQ(parseOutcome("v = [\n  1, # " + brackets + "\n  2,\n]\n"), "parsed");
    EXPECT_EQ(parseOutcome("v = 1.5e3\nw = 1979-05-27T07:32:00.999\n"), "parsed");
}

TEST(TomlReaderWording, LongValuesAreCutInMessages)
{
    const std::string huge(10 << 20, 'x');
    const std::string quoted = quote(huge);
    EXPECT_EQ(quoted, "'" + std::string(80, 'x') + "...' (10485760 bytes)");
    EXPECT_EQ(quote(std::string(96, 'y')), "'" + std::string(96, 'y') + "'");
    // A cut never splits a UTF-8 sequence: 40 two-byte letters then ASCII.
    std::string accented;
    for (int i = 0; i < 60; ++i) accented += "\xC3\xA9";
    EXPECT_EQ(quote(accented), "'" + accented.substr(0, 80) + "...' (120 bytes)");
}

/// The message of readFileBytes(path), or "read N bytes".
std::string readOutcome(const std::string& path, size_t limit = kMaxTextFileBytes)
{
    try {
        return "read " + std::to_string(readFileBytes(path, "scene file", limit).size()) + " bytes";
    } catch (const InputError& error) {
        return error.what();
    }
}

TEST(TomlReaderFiles, EndlessAndOversizedFilesStopAtTheLimit)
{
    EXPECT_EQ(readOutcome("/dev/zero"), "cannot read scene file '/dev/zero': it is longer than that (read stopped "
                                        "there); vkrt reads scene files of at most 64 MiB");
    EXPECT_EQ(readOutcome("/dev/null"), "read 0 bytes");
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "vkrt-toml-reader-files";
    std::filesystem::create_directories(dir);
    const std::string sparse = (dir / "sparse.toml").string();
    {
        std::ofstream(sparse) << "v = 1\n";
    }
    std::filesystem::resize_file(sparse, (size_t(64) << 20) + 1); // refused by its size, without reading it
    EXPECT_EQ(readOutcome(sparse), "cannot read scene file '" + sparse +
                                       "': it is 67108865 bytes; vkrt reads scene files of at most 64 MiB");
    std::filesystem::resize_file(sparse, 6);
    EXPECT_EQ(readOutcome(sparse), "read 6 bytes");
    EXPECT_EQ(readOutcome(dir.string()), "cannot read scene file '" + dir.string() + "': Is a directory");
}

TEST(TomlReaderFiles, APipeWithoutWriterIsRefusedAtOnce)
{
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "vkrt-toml-reader-fifo";
    std::filesystem::create_directories(dir);
    const std::string fifo = (dir / "scene.toml").string();
    std::filesystem::remove(fifo);
    ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
    const auto started = std::chrono::steady_clock::now();
    EXPECT_EQ(readOutcome(fifo), "cannot read scene file '" + fifo + "': it is a pipe, and nothing was writing to it");
    EXPECT_LT(std::chrono::steady_clock::now() - started, std::chrono::seconds(5));
    // What was written to the pipe is read to its end. A reader held open keeps
    // the pipe and its bytes alive after the writer has gone, with no thread timing.
    const int keeper = open(fifo.c_str(), O_RDONLY | O_NONBLOCK);
    ASSERT_GE(keeper, 0);
    const int writer = open(fifo.c_str(), O_WRONLY);
    ASSERT_GE(writer, 0);
    ASSERT_EQ(write(writer, "v = 1\n", 6), 6);
    close(writer);
    EXPECT_EQ(readOutcome(fifo), "read 6 bytes");
    close(keeper);
}

} // namespace
} // namespace vkrt

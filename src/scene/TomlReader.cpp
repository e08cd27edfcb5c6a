#include "scene/TomlReader.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace vkrt {
namespace {

bool isBareKey(std::string_view key)
{
    const auto bare = [](unsigned char c) { return std::isalnum(c) || c == '_' || c == '-'; };
    return !key.empty() && std::all_of(key.begin(), key.end(), bare);
}

/// Keys that TOML needs quoted (material names may contain anything) are
/// quoted here too, so the printed path stays unambiguous.
std::string childPath(std::string_view parent, std::string_view key)
{
    const std::string name = isBareKey(key) ? std::string(key) : "\"" + std::string(key) + "\"";
    return parent.empty() ? name : std::string(parent) + "." + name;
}

bool isBefore(const toml::source_position& a, const toml::source_position& b)
{
    return std::pair(a.line, a.column) < std::pair(b.line, b.column);
}

[[noreturn]] void failAt(const SourceLocation& where, std::string_view path, const std::string& message)
{
    throw SceneError(where, path.empty() ? message : std::string(path) + ": " + message);
}

/// The unknown key that comes first in the file, so errors are reported in reading order.
const toml::key* firstUnknownKey(const toml::table& table, KeyList allowed)
{
    const toml::key* first = nullptr;
    for (auto&& [key, value] : table) {
        if (contains(allowed, key.str())) continue;
        if (!first || isBefore(key.source().begin, first->source().begin)) first = &key;
    }
    return first;
}

const toml::table& asTable(const Field& field)
{
    if (!field.node().is_table()) field.fail("expected a table, got " + describeType(field.node()));
    return *field.node().as_table();
}

// ------------------------------------------------------------- suggestions

/// A suggestion is offered for at most this many edits.
constexpr size_t maxSuggestionDistance = 2;
/// Longer words get no suggestion: nobody retypes a name that long, and the
/// bound keeps a hostile file (a 40,000-character name) from costing time.
constexpr size_t maxSuggestedLength = 128;

/// One row of the edit-distance table restricted to the band |i - j| <= limit,
/// computed from the two rows above it. Returns the smallest value in the band.
size_t fillBandRow(std::string_view a, std::string_view b, size_t i, size_t limit, const std::vector<size_t>& above2,
                   const std::vector<size_t>& above, std::vector<size_t>& row)
{
    const size_t beyond = limit + 1;
    const size_t first = i > limit ? i - limit : 1;
    const size_t last = std::min(b.size(), i + limit);
    // Cells just outside the band are read by this row and the next; they stand for "too far".
    row[0] = std::min(i, beyond);
    if (first > 1) row[first - 1] = beyond;
    if (last + 1 <= b.size()) row[last + 1] = beyond;
    size_t smallest = row[0];
    for (size_t j = first; j <= last; ++j) {
        const size_t substitution = above[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
        size_t cell = std::min({above[j] + 1, row[j - 1] + 1, substitution});
        if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) cell = std::min(cell, above2[j - 2] + 1);
        row[j] = std::min(cell, beyond);
        smallest = std::min(smallest, row[j]);
    }
    return smallest;
}

// ------------------------------------------------------------- documents

/// Length of the well-formed UTF-8 sequence starting at `at` (Unicode table
/// 3-7: no overlong forms, no surrogates, nothing above U+10FFFF), or 0.
size_t utf8SequenceLength(std::string_view text, size_t at)
{
    const auto byte = [&](size_t i) { return at + i < text.size() ? static_cast<unsigned char>(text[at + i]) : 0u; };
    const auto inRange = [](unsigned value, unsigned low, unsigned high) { return value >= low && value <= high; };
    const unsigned lead = byte(0);
    if (lead < 0x80) return 1;
    const bool tail1 = inRange(byte(1), 0x80, 0xBF), tail2 = inRange(byte(2), 0x80, 0xBF);
    const bool tail3 = inRange(byte(3), 0x80, 0xBF);
    if (inRange(lead, 0xC2, 0xDF)) return tail1 ? 2 : 0;
    if (lead == 0xE0) return inRange(byte(1), 0xA0, 0xBF) && tail2 ? 3 : 0;
    if (lead == 0xED) return inRange(byte(1), 0x80, 0x9F) && tail2 ? 3 : 0;
    if (inRange(lead, 0xE1, 0xEF)) return tail1 && tail2 ? 3 : 0;
    if (lead == 0xF0) return inRange(byte(1), 0x90, 0xBF) && tail2 && tail3 ? 4 : 0;
    if (lead == 0xF4) return inRange(byte(1), 0x80, 0x8F) && tail2 && tail3 ? 4 : 0;
    if (inRange(lead, 0xF1, 0xF3)) return tail1 && tail2 && tail3 ? 4 : 0;
    return 0;
}

/// TOML documents are UTF-8. toml++ 3.3 places an invalid byte's error at the
/// end of the previous line, so vkrt finds the byte itself (columns count code
/// points, as toml++'s do).
void checkUtf8(std::string_view text, const TomlSource& source)
{
    int line = 1, column = 1;
    for (size_t at = 0; at < text.size(); ++column) {
        const size_t length = utf8SequenceLength(text, at);
        if (length == 0) {
            char hex[8];
            std::snprintf(hex, sizeof hex, "0x%02X", static_cast<unsigned char>(text[at]));
            throw SceneError({source.file, line, column},
                             "invalid TOML: invalid UTF-8 (byte " + std::string(hex) + "); TOML files must be UTF-8");
        }
        if (text[at] == '\n') ++line, column = 0;
        at += length;
    }
}

/// How deeply a scene may nest tables and arrays. toml++ bounds bracket
/// nesting (TOML_MAX_NESTED_VALUES, 256) but not dotted keys and headers, and
/// it recurses once per level when it builds and when it destroys the tables:
/// a 50,000-part header (`[a.a.a...]`) overflowed the stack. Scene files need
/// fewer than 10 levels.
constexpr int kMaxTomlNesting = 128;

/// Finds the first place where a TOML document nests deeper than
/// kMaxTomlNesting, before toml++ sees it. It follows only what sets depth
/// (headers, dotted keys, arrays, inline tables, and the strings and comments
/// that may hide their characters); for a malformed document it may give up
/// early, and toml++ then reports the syntax error.
class TomlNestingScan {
public:
    TomlNestingScan(std::string_view text, const TomlSource& source) : m_text(text), m_source(source) {}

    void run()
    {
        startKey(0);
        while (m_at < m_text.size()) m_expectKey ? keyCharacter() : valueCharacter();
    }

private:
    struct Container {
        bool inlineTable;
        int depth; ///< of the array or table itself
    };

    char peek(size_t ahead = 0) const { return m_at + ahead < m_text.size() ? m_text[m_at + ahead] : '\0'; }

    void advance()
    {
        if (m_text[m_at] == '\n') {
            ++m_line;
            m_column = 1;
        } else if ((static_cast<unsigned char>(m_text[m_at]) & 0xC0) != 0x80) {
            ++m_column; // columns count code points, as toml++'s do
        }
        ++m_at;
    }

    void check(int depth) const
    {
        if (depth <= kMaxTomlNesting) return;
        throw SceneError({m_source.file, m_line, m_column},
                         "invalid TOML: tables and arrays nest more than " + std::to_string(kMaxTomlNesting) +
                             " levels deep here (each part of a dotted key or table header is a level); vkrt "
                             "accepts at most " +
                             std::to_string(kMaxTomlNesting));
    }

    void startKey(int base)
    {
        m_expectKey = true;
        m_keyBase = base;
        m_keyParts = 1;
    }

    void skipLine()
    {
        while (m_at < m_text.size() && peek() != '\n') advance();
    }

    /// A string starting here (basic, literal, or either multi-line form).
    void skipString()
    {
        const char quoteChar = peek();
        const bool multiLine = peek(1) == quoteChar && peek(2) == quoteChar;
        for (int i = 0; i < (multiLine ? 3 : 1); ++i) advance();
        while (m_at < m_text.size()) {
            if (quoteChar == '"' && peek() == '\\' && m_at + 1 < m_text.size()) {
                advance();
                advance();
                continue;
            }
            if (!multiLine && peek() == '\n') return; // unterminated: toml++ says so
            if (peek() == quoteChar && (!multiLine || (peek(1) == quoteChar && peek(2) == quoteChar))) {
                for (int i = 0; i < (multiLine ? 3 : 1); ++i) advance();
                // A multi-line string may end in up to two more quotes of its own.
                for (int i = 0; multiLine && i < 2 && peek() == quoteChar; ++i) advance();
                return;
            }
            advance();
        }
    }

    void keyCharacter()
    {
        const char c = peek();
        if (c == '"' || c == '\'') return skipString();
        if (c == '#') return skipLine();
        if (c == '[' && m_open.empty() && m_keyParts == 1) return header();
        if (c == '.') {
            ++m_keyParts;
            check(m_keyBase + m_keyParts);
        } else if (c == '=') {
            m_valueDepth = m_keyBase + m_keyParts;
            m_expectKey = false;
        } else if (c == '}' && !m_open.empty()) { // an empty inline table
            m_open.pop_back();
            m_expectKey = false;
        }
        advance();
    }

    /// `[a.b.c]` or `[[a.b.c]]`: later keys are relative to that table.
    void header()
    {
        const bool arrayOfTables = peek(1) == '[';
        advance();
        if (arrayOfTables) advance();
        int parts = 1;
        while (m_at < m_text.size() && peek() != ']' && peek() != '\n') {
            if (peek() == '"' || peek() == '\'') {
                skipString();
                continue;
            }
            if (peek() == '.') check(++parts + (arrayOfTables ? 1 : 0));
            advance();
        }
        m_tableDepth = parts + (arrayOfTables ? 1 : 0);
        skipLine(); // the closing brackets and any comment
        startKey(m_tableDepth);
    }

    void valueCharacter()
    {
        const char c = peek();
        if (c == '"' || c == '\'') return skipString();
        if (c == '#') return skipLine();
        if (c == '[' || c == '{') {
            m_open.push_back({c == '{', m_valueDepth});
            check(m_valueDepth + 1);
            advance();
            if (c == '{') return startKey(m_open.back().depth);
            m_valueDepth = m_open.back().depth + 1;
            return;
        }
        if ((c == ']' || c == '}') && !m_open.empty()) {
            m_open.pop_back();
            if (!m_open.empty() && !m_open.back().inlineTable) m_valueDepth = m_open.back().depth + 1;
        } else if (c == ',' && !m_open.empty()) {
            if (m_open.back().inlineTable) {
                advance();
                return startKey(m_open.back().depth);
            }
            m_valueDepth = m_open.back().depth + 1;
        } else if (c == '\n' && m_open.empty()) {
            advance();
            return startKey(m_tableDepth);
        }
        advance();
    }

    std::string_view m_text;
    const TomlSource& m_source;
    size_t m_at = 0;
    int m_line = 1, m_column = 1;
    bool m_expectKey = true;
    int m_keyBase = 0, m_keyParts = 1;
    int m_tableDepth = 0, m_valueDepth = 0;
    std::vector<Container> m_open; ///< arrays and inline tables not yet closed
};

[[noreturn]] void failToRead(std::string_view what, const std::string& path, int error)
{
    throw InputError("cannot read " + std::string(what) + " '" + path + "': " + std::strerror(error));
}

} // namespace

// ------------------------------------------------------------------ wording

std::string formatNumber(double value)
{
    char text[64];
    const auto result = std::to_chars(text, text + sizeof text, value);
    return std::string(text, result.ptr);
}

/// Messages echo at most this many bytes of a value: a 10 MB string in a scene
/// file must not become a 10 MB error message.
constexpr size_t kMaxQuotedBytes = 96;

std::string quote(std::string_view text)
{
    if (text.size() <= kMaxQuotedBytes) return "'" + std::string(text) + "'";
    size_t cut = kMaxQuotedBytes - 16;
    while (cut > 0 && (static_cast<unsigned char>(text[cut]) & 0xC0) == 0x80) --cut; // not inside a UTF-8 sequence
    return "'" + std::string(text.substr(0, cut)) + "...' (" + std::to_string(text.size()) + " bytes)";
}

std::string joinList(KeyList words)
{
    std::string out;
    for (std::string_view word : words) {
        if (!out.empty()) out += ", ";
        out += word;
    }
    return out;
}

bool contains(KeyList keys, std::string_view key) { return std::find(keys.begin(), keys.end(), key) != keys.end(); }

std::string lowercase(std::string_view text)
{
    std::string out(text);
    for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return out;
}

std::string describeType(const toml::node& node)
{
    switch (node.type()) {
    case toml::node_type::table: return "a table";
    case toml::node_type::array: return "an array";
    case toml::node_type::string: return "a string";
    case toml::node_type::integer: return "an integer";
    case toml::node_type::floating_point: return "a float";
    case toml::node_type::boolean: return "a boolean";
    case toml::node_type::date: return "a date";
    case toml::node_type::time: return "a time";
    case toml::node_type::date_time: return "a date-time";
    case toml::node_type::none: break;
    }
    return "nothing";
}

// -------------------------------------------------------------- suggestions

/// Swapped letters ("lambret") are the most common typo in names, hence OSA
/// rather than plain Levenshtein. Only cells within `limit` of the diagonal can
/// stay within `limit`, so the rest of each row is never computed.
size_t boundedEditDistance(std::string_view a, std::string_view b, size_t limit)
{
    const size_t beyond = limit + 1;
    if (std::max(a.size(), b.size()) - std::min(a.size(), b.size()) > limit) return beyond;
    std::vector<size_t> above2(b.size() + 1, beyond), above(b.size() + 1, beyond), row(b.size() + 1, beyond);
    for (size_t j = 0; j <= std::min(b.size(), limit); ++j) above[j] = j;
    for (size_t i = 1; i <= a.size(); ++i) {
        if (fillBandRow(a, b, i, limit, above2, above, row) > limit) return beyond;
        std::swap(above2, above);
        std::swap(above, row);
    }
    return above[b.size()];
}

std::optional<std::string_view> closestMatch(std::string_view word, KeyList candidates)
{
    if (word.size() > maxSuggestedLength) return std::nullopt;
    const std::string lowerWord = lowercase(word);
    std::optional<std::string_view> best;
    size_t bestDistance = maxSuggestionDistance + 1;
    for (std::string_view candidate : candidates) {
        const size_t distance = candidate.size() == word.size() && lowercase(candidate) == lowerWord
                                    ? 0
                                    : boundedEditDistance(word, candidate, maxSuggestionDistance);
        // A candidate reachable only by rewriting every character ('x' -> 'up')
        // is noise for short keys, not a hint.
        if (distance >= std::max(word.size(), candidate.size())) continue;
        if (distance < bestDistance) {
            best = candidate;
            bestDistance = distance;
        }
    }
    return best;
}

std::string didYouMean(std::string_view word, KeyList candidates)
{
    const auto match = closestMatch(word, candidates);
    return match ? "; did you mean " + quote(*match) + "?" : "";
}

// ----------------------------------------------------------- located values

SourceLocation locate(const TomlSource& source, const toml::source_position& position)
{
    return {source.file, static_cast<int>(position.line), static_cast<int>(position.column)};
}

void Field::fail(const std::string& message) const { failAt(location(), m_path, message); }

Field Field::element(size_t index, const toml::node& node) const
{
    return {*m_source, node, m_path + "[" + std::to_string(index) + "]"};
}

TableField::TableField(const Field& field) : m_field(field), m_table(&asTable(field)) {}

std::optional<Field> TableField::find(std::string_view key) const
{
    const toml::node* node = m_table->get(key);
    if (!node) return std::nullopt;
    return Field(m_field.context(), *node, childPath(m_field.path(), key));
}

Field TableField::require(std::string_view key) const
{
    if (auto field = find(key)) return *field;
    if (m_field.path().empty()) m_field.fail("missing required table [" + std::string(key) + "]");
    m_field.fail("missing required key " + quote(key));
}

void TableField::rejectUnknownKeys(KeyList allowed, KeyList otherKindsKeys, std::string_view kind) const
{
    const toml::key* key = firstUnknownKey(*m_table, allowed);
    if (!key) return;
    const std::string message = contains(otherKindsKeys, key->str())
                                    ? "key " + quote(key->str()) + " is not used by " + std::string(kind)
                                    : unknownKeyMessage(*key, allowed);
    failAt(locate(m_field.context(), key->source().begin), m_field.path(), message);
}

std::vector<std::pair<std::string_view, Field>> TableField::entriesInFileOrder() const
{
    std::vector<std::pair<std::string_view, Field>> entries;
    for (auto&& [key, value] : *m_table) entries.emplace_back(key.str(), *find(key.str()));
    std::stable_sort(entries.begin(), entries.end(), [](const auto& a, const auto& b) {
        return isBefore(a.second.node().source().begin, b.second.node().source().begin);
    });
    return entries;
}

std::string TableField::unknownKeyMessage(const toml::key& key, KeyList allowed) const
{
    std::string noun = "key";
    if (m_field.path().empty()) noun = (*m_table)[key.str()].is_table() ? "top-level table" : "top-level key";
    return "unknown " + noun + " " + quote(key.str()) + didYouMean(key.str(), allowed);
}

// ------------------------------------------------------------------ documents

toml::table parseToml(std::string_view text, const TomlSource& source)
{
    checkUtf8(text, source);
    TomlNestingScan(text, source).run();
    try {
        return toml::parse(text, std::string_view(source.file));
    } catch (const toml::parse_error& error) {
        throw SceneError(locate(source, error.source().begin), "invalid TOML: " + std::string(error.description()));
    }
}

/// A file descriptor closed when it goes out of scope.
class FileDescriptor {
public:
    explicit FileDescriptor(int fd) : m_fd(fd) {}
    FileDescriptor(const FileDescriptor&) = delete;
    FileDescriptor& operator=(const FileDescriptor&) = delete;
    ~FileDescriptor()
    {
        if (m_fd >= 0) close(m_fd);
    }
    int get() const { return m_fd; }

private:
    int m_fd;
};

std::string mebibytes(size_t bytes) { return std::to_string(bytes >> 20) + " MiB"; }

/// Reads with POSIX calls, which say why (errno) a read failed. Opening does
/// not wait: a FIFO nobody writes to would block open() for ever. Reads stop
/// one byte past the limit, so /dev/zero or an endless pipe costs at most that.
std::string readFileBytes(const std::string& path, std::string_view what, size_t maxBytes)
{
    const FileDescriptor file(open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC));
    if (file.get() < 0) failToRead(what, path, errno);
    struct stat status {};
    if (fstat(file.get(), &status) != 0) failToRead(what, path, errno);
    if (S_ISDIR(status.st_mode)) failToRead(what, path, EISDIR);
    const auto tooLarge = [&](const std::string& size) {
        throw InputError("cannot read " + std::string(what) + " '" + path + "': it is " + size + "; vkrt reads " +
                         std::string(what) + "s of at most " + mebibytes(maxBytes));
    };
    if (S_ISREG(status.st_mode) && static_cast<uint64_t>(status.st_size) > maxBytes)
        tooLarge(std::to_string(status.st_size) + " bytes");
    // Back to blocking reads: a pipe whose writer is slow is read to its end.
    const int flags = fcntl(file.get(), F_GETFL);
    if (flags < 0 || fcntl(file.get(), F_SETFL, flags & ~O_NONBLOCK) != 0) failToRead(what, path, errno);
    std::string bytes;
    char buffer[1 << 16];
    while (bytes.size() <= maxBytes) {
        const ssize_t count = read(file.get(), buffer, sizeof buffer);
        if (count < 0 && errno == EINTR) continue;
        if (count < 0) failToRead(what, path, errno);
        if (count == 0) break;
        bytes.append(buffer, static_cast<size_t>(count));
    }
    if (bytes.size() > maxBytes) tooLarge("longer than that (read stopped there)");
    if (bytes.empty() && S_ISFIFO(status.st_mode))
        throw InputError("cannot read " + std::string(what) + " '" + path +
                         "': it is a pipe, and nothing was writing to it");
    return bytes;
}

// ------------------------------------------------------------ scalar values

double readNumber(const Field& field)
{
    const toml::node& node = field.node();
    if (!node.is_number()) field.fail("expected a number, got " + describeType(node));
    const double value =
        node.is_integer() ? static_cast<double>(node.as_integer()->get()) : node.as_floating_point()->get();
    // TOML allows nan and inf literals; nothing vkrt reads can use them.
    if (!std::isfinite(value)) field.fail("must be finite, got " + formatNumber(value));
    return value;
}

double readPositive(const Field& field)
{
    const double value = readNumber(field);
    if (!(value > 0)) field.fail("must be > 0, got " + formatNumber(value));
    return value;
}

double readNonNegative(const Field& field)
{
    const double value = readNumber(field);
    if (value < 0) field.fail("must be >= 0, got " + formatNumber(value));
    return value;
}

double readNumberIn(const Field& field, const NumberRange& range)
{
    const double value = readNumber(field);
    const bool aboveMin = range.minOpen ? value > range.min : value >= range.min;
    const bool belowMax = range.maxOpen ? value < range.max : value <= range.max;
    if (aboveMin && belowMax) return value;
    field.fail("must be in " + std::string(range.minOpen ? "(" : "[") + formatNumber(range.min) + ", " +
               formatNumber(range.max) + (range.maxOpen ? ")" : "]") + ", got " + formatNumber(value));
}

int64_t readInteger(const Field& field, int64_t min, int64_t max)
{
    if (!field.node().is_integer()) field.fail("expected an integer, got " + describeType(field.node()));
    const int64_t value = field.node().as_integer()->get();
    if (value < min || value > max)
        field.fail("must be between " + std::to_string(min) + " and " + std::to_string(max) + ", got " +
                   std::to_string(value));
    return value;
}

std::string readString(const Field& field)
{
    if (!field.node().is_string()) field.fail("expected a string, got " + describeType(field.node()));
    return field.node().as_string()->get();
}

bool readBool(const Field& field)
{
    if (!field.node().is_boolean()) field.fail("expected a boolean (true or false), got " + describeType(field.node()));
    return field.node().as_boolean()->get();
}

std::filesystem::path readPath(const Field& field)
{
    const std::filesystem::path given = readString(field);
    return given.is_absolute() ? given : field.context().baseDir / given;
}

glm::dvec3 readVector(const Field& field)
{
    const auto c = readTriple(field, "numbers", readNumber);
    return {c[0], c[1], c[2]};
}

} // namespace vkrt

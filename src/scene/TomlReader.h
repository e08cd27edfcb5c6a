#pragma once
// Validated reading of hand-written TOML files (scene files, regression-suite
// manifests): every value is read through a Field that knows its file position
// and full dotted path, so each complaint reads
// "file:line:column: path: expected ..., got ..." and misspelt keys or names
// get a "did you mean".
#include "util/Error.h"

#include <glm/vec3.hpp>
#include <toml++/toml.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

// toml++ 3.3 (Debian 12) trips its own debug assertions, and reaches one
// __builtin_unreachable, on some invalid documents ("[.", "v=[}", a non-ASCII
// letter outside a string, ...). The compiled library that distributions ship is built
// with NDEBUG and reports those documents as parse errors; the header-only
// build compiled here without NDEBUG would abort instead. So vkrt links the
// compiled library (pkg-config's tomlplusplus sets TOML_HEADER_ONLY=0), and a
// header-only build is accepted only with assertions off.
#if TOML_HEADER_ONLY && !defined(NDEBUG)
#error "vkrt needs the compiled toml++ library (TOML_HEADER_ONLY=0), or NDEBUG with the header-only build"
#endif

namespace vkrt {

using KeyList = std::span<const std::string_view>;

// ------------------------------------------------------------------ wording

/// Shortest text that reads back as the same double, so messages echo what the user wrote.
std::string formatNumber(double value);
std::string quote(std::string_view text);
std::string joinList(KeyList words);
std::string lowercase(std::string_view text);
bool contains(KeyList keys, std::string_view key);
/// "a string", "an integer", ...: what a node is, for "expected X, got Y".
std::string describeType(const toml::node& node);

// -------------------------------------------------------------- suggestions

/// Optimal-string-alignment distance (Levenshtein plus adjacent transposition)
/// when it is at most `limit`, otherwise limit + 1. Costs O(|a| * limit) time
/// and O(|b|) memory.
size_t boundedEditDistance(std::string_view a, std::string_view b, size_t limit);

/// The closest candidate within two edits, or equal ignoring case; none for a
/// word too long to be a misspelt name.
std::optional<std::string_view> closestMatch(std::string_view word, KeyList candidates);

/// "; did you mean 'x'?" or "".
std::string didYouMean(std::string_view word, KeyList candidates);

// ----------------------------------------------------------- located values

/// The document being read: its name for messages, and the folder relative paths in it are resolved against.
struct TomlSource {
    std::string file;
    std::filesystem::path baseDir;
};

SourceLocation locate(const TomlSource& source, const toml::source_position& position);

/// A TOML value together with what is needed to complain about it.
class Field {
public:
    Field(const TomlSource& source, const toml::node& node, std::string path)
        : m_source(&source),
          m_node(&node),
          m_path(std::move(path))
    {
    }
    const TomlSource& context() const { return *m_source; }
    const toml::node& node() const { return *m_node; }
    const std::string& path() const { return m_path; }
    SourceLocation location() const { return locate(*m_source, m_node->source().begin); }
    [[noreturn]] void fail(const std::string& message) const;
    Field element(size_t index, const toml::node& node) const;

private:
    const TomlSource* m_source;
    const toml::node* m_node;
    std::string m_path;
};

/// A Field known to be a table, with key-level checks.
class TableField {
public:
    /// Fails unless `field` is a table.
    explicit TableField(const Field& field);

    const Field& field() const { return m_field; }
    std::optional<Field> find(std::string_view key) const;
    /// The value of `key`, or a failure located at this table.
    Field require(std::string_view key) const;

    /// Rejects the first key (in file order) outside `allowed`. Keys in
    /// `otherKindsKeys` are valid for a different `type`/`shape`, which
    /// deserves a more precise message than "unknown".
    void rejectUnknownKeys(KeyList allowed, KeyList otherKindsKeys = {}, std::string_view kind = {}) const;

    /// Entries in the order they appear in the file (toml::table sorts by name).
    std::vector<std::pair<std::string_view, Field>> entriesInFileOrder() const;

private:
    std::string unknownKeyMessage(const toml::key& key, KeyList allowed) const;

    Field m_field;
    const toml::table* m_table;
};

/// Parses a whole document; syntax errors become a SceneError at their position.
toml::table parseToml(std::string_view text, const TomlSource& source);

/// The longest scene or suite file vkrt reads (docs/robustness.md): far above
/// any hand-written file (meshes and images are separate files), and small
/// enough that /dev/zero or an endless pipe given as a scene costs little.
constexpr size_t kMaxTextFileBytes = size_t(64) << 20;

/// The bytes of a file of at most maxBytes, which may be a pipe or a device;
/// InputError "cannot read <what> 'path': <reason>" when it cannot be read,
/// is a directory, is longer, or is a pipe nobody writes to.
std::string readFileBytes(const std::string& path, std::string_view what, size_t maxBytes = kMaxTextFileBytes);

// ------------------------------------------------------------ scalar values

/// A finite number (integers are accepted for floats).
double readNumber(const Field& field);
double readPositive(const Field& field);
double readNonNegative(const Field& field);

/// An interval of the real line; an open end excludes its bound.
struct NumberRange {
    double min, max;
    bool minOpen = false, maxOpen = false;
};
/// A finite number in `range`; failures print the range as "(0, 1]".
double readNumberIn(const Field& field, const NumberRange& range);

int64_t readInteger(const Field& field, int64_t min, int64_t max);
std::string readString(const Field& field);
bool readBool(const Field& field);

/// A string naming a file, resolved against the document's folder unless absolute.
std::filesystem::path readPath(const Field& field);

/// A name for one value of an enum, for readChoice.
template <class E>
struct EnumName {
    std::string_view name;
    E value;
};

/// Looks a string up among `choices` (anything with a `name`), suggesting the
/// closest one on failure. Returns a copy: the entries are small, and a
/// reference into `choices` would be flagged by GCC 14's -Wdangling-reference.
template <class Choice, size_t N>
Choice readChoice(const Field& field, std::string_view noun, const std::array<Choice, N>& choices)
{
    const std::string text = readString(field);
    std::array<std::string_view, N> names;
    for (size_t i = 0; i < N; ++i) {
        if (choices[i].name == text) return choices[i];
        names[i] = choices[i].name;
    }
    field.fail("unknown " + std::string(noun) + " " + quote(text) + didYouMean(text, names) +
               " (expected one of: " + joinList(names) + ")");
}

/// `read` of `key` when the table has it, otherwise `fallback`.
template <class T, class Read>
T readOr(const TableField& table, std::string_view key, T fallback, Read read)
{
    const std::optional<Field> field = table.find(key);
    return field ? static_cast<T>(read(*field)) : fallback;
}

// ------------------------------------------------------------ arrays

/// Reads an array of exactly three elements with `read`; `what` names them ("numbers").
template <class Read>
auto readTriple(const Field& field, std::string_view what, Read read)
{
    const toml::array* array = field.node().as_array();
    // Appended, not `"..." + std::string(what) + "..."`: GCC 14 reports a false
    // -Warray-bounds in the inlined `std::string&& + "..."` at -O2.
    std::string expected = "expected an array of 3 ";
    expected.append(what).append(", got ");
    if (!array) field.fail(expected + describeType(field.node()));
    if (array->size() != 3) field.fail(expected + std::to_string(array->size()) + " element(s)");
    std::array<decltype(read(field)), 3> out;
    for (size_t i = 0; i < 3; ++i) out[i] = read(field.element(i, *array->get(i)));
    return out;
}

/// An array of three finite numbers.
glm::dvec3 readVector(const Field& field);

/// Calls `read` for every table of a [[name]] array, in file order.
template <class Read>
void forEachTable(const Field& field, Read read)
{
    const toml::array* array = field.node().as_array();
    if (!array) field.fail("expected an array of tables ([[" + field.path() + "]]), got " + describeType(field.node()));
    for (size_t i = 0; i < array->size(); ++i) read(TableField(field.element(i, *array->get(i))));
}

} // namespace vkrt

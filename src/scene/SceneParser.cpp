// Scene-file reader: TOML text -> toml++ tree -> validated Scene.
//
// Every check reports the exact position of the offending value (or of the
// enclosing table when something is missing) together with the value's full
// dotted path, because scene files are written by hand and an error that only
// says "bad radius" is useless in a file with a hundred spheres.
#include "scene/SceneParser.h"

#include "util/Hash.h"

#include <toml++/toml.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <utility>
#include <vector>

namespace vkrt {
namespace {

namespace fs = std::filesystem;
using Keys = std::span<const std::string_view>;

// ----------------------------------------------------------------- wording

/// Shortest text that reads back as the same double, so messages echo what the user wrote.
std::string formatNumber(double value)
{
    char text[64];
    const auto result = std::to_chars(text, text + sizeof text, value);
    return std::string(text, result.ptr);
}

std::string quote(std::string_view text) { return "'" + std::string(text) + "'"; }

std::string joinList(Keys words)
{
    std::string out;
    for (std::string_view word : words) {
        if (!out.empty()) out += ", ";
        out += word;
    }
    return out;
}

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

std::string elementPath(std::string_view parent, size_t index)
{
    return std::string(parent) + "[" + std::to_string(index) + "]";
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

// ------------------------------------------------------------- suggestions

std::string lowercase(std::string_view text)
{
    std::string out(text);
    for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return out;
}

/// Optimal-string-alignment distance: Levenshtein plus adjacent transposition,
/// because swapped letters ("lambret") are the most common typo in names.
size_t editDistance(std::string_view a, std::string_view b)
{
    std::vector<std::vector<size_t>> d(a.size() + 1, std::vector<size_t>(b.size() + 1));
    for (size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
    for (size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
    for (size_t i = 1; i <= a.size(); ++i) {
        for (size_t j = 1; j <= b.size(); ++j) {
            const size_t substitution = d[i - 1][j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
            d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, substitution});
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
                d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
        }
    }
    return d[a.size()][b.size()];
}

/// The closest candidate within edit distance 2 (or equal ignoring case). A
/// candidate reachable only by rewriting every character ('x' -> 'up') is not
/// offered: for short keys that would be noise, not a hint.
std::optional<std::string_view> closestMatch(std::string_view word, Keys candidates)
{
    constexpr size_t maxDistance = 2;
    std::optional<std::string_view> best;
    size_t bestDistance = maxDistance + 1;
    for (std::string_view candidate : candidates) {
        const size_t distance = lowercase(candidate) == lowercase(word) ? 0 : editDistance(word, candidate);
        if (distance >= std::max(word.size(), candidate.size())) continue;
        if (distance < bestDistance) {
            best = candidate;
            bestDistance = distance;
        }
    }
    return best;
}

std::string didYouMean(std::string_view word, Keys candidates)
{
    const auto match = closestMatch(word, candidates);
    return match ? "; did you mean " + quote(*match) + "?" : "";
}

// --------------------------------------------------------- located values

struct Context {
    std::string file; ///< as given by the caller, for messages
    fs::path baseDir; ///< relative asset paths are resolved against it
};

SourceLocation locate(const Context& context, const toml::source_position& position)
{
    return {context.file, static_cast<int>(position.line), static_cast<int>(position.column)};
}

bool isBefore(const toml::source_position& a, const toml::source_position& b)
{
    return std::pair(a.line, a.column) < std::pair(b.line, b.column);
}

[[noreturn]] void failAt(const SourceLocation& where, std::string_view path, const std::string& message)
{
    throw SceneError(where, path.empty() ? message : std::string(path) + ": " + message);
}

/// A TOML value together with what is needed to complain about it.
class Field {
public:
    Field(const Context& context, const toml::node& node, std::string path)
        : m_context(&context), m_node(&node), m_path(std::move(path))
    {
    }
    const Context& context() const { return *m_context; }
    const toml::node& node() const { return *m_node; }
    const std::string& path() const { return m_path; }
    SourceLocation location() const { return locate(*m_context, m_node->source().begin); }
    [[noreturn]] void fail(const std::string& message) const { failAt(location(), m_path, message); }
    Field element(size_t index, const toml::node& node) const { return {*m_context, node, elementPath(m_path, index)}; }

private:
    const Context* m_context;
    const toml::node* m_node;
    std::string m_path;
};

const toml::table& asTable(const Field& field)
{
    if (!field.node().is_table()) field.fail("expected a table, got " + describeType(field.node()));
    return *field.node().as_table();
}

bool contains(Keys keys, std::string_view key) { return std::find(keys.begin(), keys.end(), key) != keys.end(); }

/// The unknown key that comes first in the file, so errors are reported in reading order.
const toml::key* firstUnknownKey(const toml::table& table, Keys allowed)
{
    const toml::key* first = nullptr;
    for (auto&& [key, value] : table) {
        if (contains(allowed, key.str())) continue;
        if (!first || isBefore(key.source().begin, first->source().begin)) first = &key;
    }
    return first;
}

/// A Field known to be a table, with key-level checks.
class TableField {
public:
    explicit TableField(const Field& field) : m_field(field), m_table(&asTable(field)) {}

    const Field& field() const { return m_field; }

    std::optional<Field> find(std::string_view key) const
    {
        const toml::node* node = m_table->get(key);
        if (!node) return std::nullopt;
        return Field(m_field.context(), *node, childPath(m_field.path(), key));
    }

    Field require(std::string_view key) const
    {
        if (auto field = find(key)) return *field;
        if (m_field.path().empty()) m_field.fail("missing required table [" + std::string(key) + "]");
        m_field.fail("missing required key " + quote(key));
    }

    /// Rejects keys outside `allowed`. Keys in `otherKindsKeys` are valid for a
    /// different `type`/`shape`, which deserves a more precise message than "unknown".
    void rejectUnknownKeys(Keys allowed, Keys otherKindsKeys = {}, std::string_view kind = {}) const
    {
        const toml::key* key = firstUnknownKey(*m_table, allowed);
        if (!key) return;
        const std::string message = contains(otherKindsKeys, key->str())
                                        ? "key " + quote(key->str()) + " is not used by " + std::string(kind)
                                        : unknownKeyMessage(*key, allowed);
        failAt(locate(m_field.context(), key->source().begin), m_field.path(), message);
    }

    /// Entries in the order they appear in the file (toml::table sorts by name).
    std::vector<std::pair<std::string_view, Field>> entriesInFileOrder() const
    {
        std::vector<std::pair<std::string_view, Field>> entries;
        for (auto&& [key, value] : *m_table) entries.emplace_back(key.str(), *find(key.str()));
        std::stable_sort(entries.begin(), entries.end(), [](const auto& a, const auto& b) {
            return isBefore(a.second.node().source().begin, b.second.node().source().begin);
        });
        return entries;
    }

private:
    std::string unknownKeyMessage(const toml::key& key, Keys allowed) const
    {
        std::string noun = "key";
        if (m_field.path().empty()) noun = (*m_table)[key.str()].is_table() ? "top-level table" : "top-level key";
        return "unknown " + noun + " " + quote(key.str()) + didYouMean(key.str(), allowed);
    }

    Field m_field;
    const toml::table* m_table;
};

// ------------------------------------------------------------ scalar values

double readNumber(const Field& field)
{
    const toml::node& node = field.node();
    if (!node.is_number()) field.fail("expected a number, got " + describeType(node));
    const double value =
        node.is_integer() ? static_cast<double>(node.as_integer()->get()) : node.as_floating_point()->get();
    // TOML allows nan and inf literals; nothing in a scene can use them.
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

double readIor(const Field& field)
{
    const double value = readNumber(field);
    if (value < 1) field.fail("must be >= 1, got " + formatNumber(value));
    if (value > SceneLimits::maxIor)
        field.fail("must be <= " + formatNumber(SceneLimits::maxIor) + ", got " + formatNumber(value));
    return value;
}

double readFov(const Field& field)
{
    const double value = readNumber(field);
    if (!(value > 0 && value < 180)) field.fail("must be strictly between 0 and 180 degrees, got " + formatNumber(value));
    return value;
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

/// Looks a string up among `choices` (anything with a `name`), suggesting the closest one on failure.
template <class Choice, size_t N>
const Choice& readChoice(const Field& field, std::string_view noun, const std::array<Choice, N>& choices)
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

template <class E>
struct EnumName {
    std::string_view name;
    E value;
};

template <class T, class Read>
T readOr(const TableField& table, std::string_view key, T fallback, Read read)
{
    const std::optional<Field> field = table.find(key);
    return field ? static_cast<T>(read(*field)) : fallback;
}

// ---------------------------------------------------------- vectors, colours

/// Reads an array of exactly three elements with `read`.
template <class Read>
auto readTriple(const Field& field, std::string_view what, Read read)
{
    const toml::array* array = field.node().as_array();
    const std::string expected = "expected an array of 3 " + std::string(what) + ", got ";
    if (!array) field.fail(expected + describeType(field.node()));
    if (array->size() != 3) field.fail(expected + std::to_string(array->size()) + " element(s)");
    std::array<decltype(read(field)), 3> out;
    for (size_t i = 0; i < 3; ++i) out[i] = read(field.element(i, *array->get(i)));
    return out;
}

glm::dvec3 readVector(const Field& field)
{
    const auto c = readTriple(field, "numbers", readNumber);
    return {c[0], c[1], c[2]};
}

std::array<glm::dvec3, 3> readVertices(const Field& field) { return readTriple(field, "points", readVector); }

enum class ColorRange { Unit, NonNegative };

double checkChannel(const Field& field, double value, ColorRange range)
{
    if (range == ColorRange::Unit && !(value >= 0 && value <= 1))
        field.fail("must be in [0, 1], got " + formatNumber(value));
    if (value < 0) field.fail("must be >= 0, got " + formatNumber(value));
    return value;
}

/// A colour is three channels or one number meaning grey.
Color readColor(const Field& field, ColorRange range)
{
    const auto channel = [range](const Field& f) { return checkChannel(f, readNumber(f), range); };
    if (field.node().is_number()) return Color(channel(field));
    if (!field.node().is_array())
        field.fail("expected a colour (a number or an array of 3 numbers), got " + describeType(field.node()));
    const auto c = readTriple(field, "numbers", channel);
    return {c[0], c[1], c[2]};
}

Color readUnitColor(const Field& field) { return readColor(field, ColorRange::Unit); }
Color readRadiance(const Field& field) { return readColor(field, ColorRange::NonNegative); }

// ------------------------------------------------------------------ geometry

bool isFinite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

/// Scaling by the largest component first lets legal extreme vectors (1e300 or
/// 1e-300) normalize without overflow or underflow; nullopt for the zero vector.
std::optional<glm::dvec3> normalized(const glm::dvec3& v)
{
    const double largest = std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)});
    if (largest == 0) return std::nullopt;
    return glm::normalize(v / largest);
}

/// to - from, halved when the full difference of two finite points overflows
/// (only its direction is used).
glm::dvec3 difference(const glm::dvec3& from, const glm::dvec3& to)
{
    const glm::dvec3 d = to - from;
    return isFinite(d) ? d : to * 0.5 - from * 0.5;
}

// -------------------------------------------------------------------- render

constexpr std::array<std::string_view, 2> renderKeys{"integrator", "max_depth"};
constexpr std::array<EnumName<Integrator>, 2> integrators{{{"whitted", Integrator::Whitted}, {"path", Integrator::Path}}};

Integrator readIntegrator(const Field& field) { return readChoice(field, "integrator", integrators).value; }
int readMaxDepth(const Field& field) { return static_cast<int>(readInteger(field, 1, SceneLimits::maxDepth)); }

RenderSettings readRender(const TableField& table)
{
    table.rejectUnknownKeys(renderKeys);
    RenderSettings render;
    render.integrator = readOr(table, "integrator", render.integrator, readIntegrator);
    render.maxDepth = readOr(table, "max_depth", render.maxDepth, readMaxDepth);
    return render;
}

// -------------------------------------------------------------------- camera

constexpr std::array<std::string_view, 6> cameraKeys{"eye", "target", "up", "fov", "width", "height"};

/// sin of the smallest accepted angle between up and the view direction; below
/// it the camera's right vector is numerically meaningless.
constexpr double parallelTolerance = 1e-6;

glm::dvec3 readTarget(const Field& field, const glm::dvec3& eye)
{
    const glm::dvec3 target = readVector(field);
    if (target == eye) field.fail("must differ from camera.eye (the view direction would be undefined)");
    return target;
}

glm::dvec3 readUp(const TableField& camera, const glm::dvec3& viewDirection)
{
    const std::optional<Field> field = camera.find("up");
    const glm::dvec3 up = field ? readVector(*field) : glm::dvec3(0, 1, 0);
    const std::optional<glm::dvec3> unitUp = normalized(up);
    if (!unitUp) field->fail("must not be zero-length"); // the default is not, so field exists
    if (glm::length(glm::cross(*unitUp, viewDirection)) >= parallelTolerance) return up;
    if (field) field->fail("must not be parallel to the view direction (target - eye)");
    camera.field().fail("the default up [0, 1, 0] is parallel to the view direction (target - eye); set 'up'");
}

uint32_t readImageSide(const Field& field)
{
    return static_cast<uint32_t>(readInteger(field, 1, SceneLimits::maxImageSide));
}

void readResolution(const TableField& table, Camera& camera)
{
    camera.width = readOr(table, "width", camera.width, readImageSide);
    camera.height = readOr(table, "height", camera.height, readImageSide);
    const uint64_t pixels = uint64_t{camera.width} * camera.height;
    if (pixels <= SceneLimits::maxImagePixels) return;
    const Field blamed = table.find("height").value_or(table.find("width").value_or(table.field()));
    blamed.fail("width * height = " + std::to_string(pixels) + " pixels exceeds the limit of " +
                std::to_string(SceneLimits::maxImagePixels));
}

Camera readCamera(const TableField& table)
{
    table.rejectUnknownKeys(cameraKeys);
    Camera camera;
    camera.eye = readVector(table.require("eye"));
    camera.target = readTarget(table.require("target"), camera.eye);
    camera.up = readUp(table, *normalized(difference(camera.eye, camera.target)));
    camera.fovY = readFov(table.require("fov"));
    readResolution(table, camera);
    return camera;
}

// ----------------------------------------------------------------- materials

constexpr std::array<std::string_view, 2> lambertKeys{"type", "albedo"};
constexpr std::array<std::string_view, 4> phongKeys{"type", "diffuse", "specular", "shininess"};
constexpr std::array<std::string_view, 4> mirrorKeys{"type", "reflectance", "fresnel", "ior"};
constexpr std::array<std::string_view, 5> glossyKeys{"type", "reflectance", "exponent", "fresnel", "ior"};
constexpr std::array<std::string_view, 4> dielectricKeys{"type", "ior", "absorption", "fresnel"};

constexpr std::array<EnumName<FresnelMode>, 2> reflectorFresnelModes{
    {{"none", FresnelMode::None}, {"schlick", FresnelMode::Schlick}}};
constexpr std::array<EnumName<FresnelMode>, 2> dielectricFresnelModes{
    {{"schlick", FresnelMode::Schlick}, {"exact", FresnelMode::Exact}}};

FresnelMode readReflectorFresnel(const Field& field)
{
    return readChoice(field, "fresnel mode", reflectorFresnelModes).value;
}

FresnelMode readDielectricFresnel(const Field& field)
{
    return readChoice(field, "fresnel mode", dielectricFresnelModes).value;
}

void readLambert(const TableField& table, Material& material)
{
    material.diffuse = readOr(table, "albedo", Color(0.8), readUnitColor);
}

void readPhong(const TableField& table, Material& material)
{
    material.diffuse = readOr(table, "diffuse", Color(0.8), readUnitColor);
    material.specular = readOr(table, "specular", Color(0.0), readUnitColor);
    material.exponent = readOr(table, "shininess", 32.0, readNonNegative);
}

/// Mirror and glossy share an optional Schlick term whose R0 comes from `ior`.
void readReflectorFresnelTerm(const TableField& table, Material& material)
{
    material.fresnel = readOr(table, "fresnel", FresnelMode::None, readReflectorFresnel);
    material.ior = readOr(table, "ior", 1.5, readIor);
}

void readMirror(const TableField& table, Material& material)
{
    material.specular = readOr(table, "reflectance", Color(1.0), readUnitColor);
    readReflectorFresnelTerm(table, material);
}

void readGlossy(const TableField& table, Material& material)
{
    material.specular = readOr(table, "reflectance", Color(1.0), readUnitColor);
    material.exponent = readOr(table, "exponent", 100.0, readNonNegative);
    readReflectorFresnelTerm(table, material);
}

void readDielectric(const TableField& table, Material& material)
{
    material.ior = readOr(table, "ior", 1.5, readIor);
    material.absorption = readOr(table, "absorption", Color(0.0), readRadiance);
    material.fresnel = readOr(table, "fresnel", FresnelMode::Default, readDielectricFresnel);
}

struct MaterialKind {
    std::string_view name;
    MaterialType type;
    Keys keys;
    void (*read)(const TableField&, Material&);
};

// The registry (shared/Kinds.h) names each kind's key list `nameKeys` and its reader `readType`.
#define VKRT_MATERIAL_KIND_ENTRY(KIND, Type, name, value, delta) MaterialKind{#name, MaterialType::Type, name##Keys, read##Type},
const std::array<MaterialKind, kMaterialKindCount> materialKinds{{VKRT_MATERIAL_KINDS(VKRT_MATERIAL_KIND_ENTRY)}};
#undef VKRT_MATERIAL_KIND_ENTRY

/// Every key some kind of the table accepts: a key of another kind gets a
/// more precise message than "unknown".
template <class Kind, size_t N>
std::vector<std::string_view> keysOfEveryKind(const std::array<Kind, N>& kinds)
{
    std::vector<std::string_view> keys;
    for (const Kind& kind : kinds)
        for (std::string_view key : kind.keys)
            if (!contains(keys, key)) keys.push_back(key);
    return keys;
}

const std::vector<std::string_view> allMaterialKeys = keysOfEveryKind(materialKinds);

Material readMaterial(std::string_view name, const TableField& table)
{
    // A copy: GCC 14 cannot tell that the reference would not dangle.
    const MaterialKind kind = readChoice(table.require("type"), "material type", materialKinds);
    table.rejectUnknownKeys(kind.keys, allMaterialKeys, "material type " + quote(kind.name));
    Material material;
    material.name = name;
    material.type = kind.type;
    material.where = table.field().location();
    kind.read(table, material);
    return material;
}

std::vector<Material> readMaterials(const TableField& table)
{
    std::vector<Material> materials;
    for (const auto& [name, field] : table.entriesInFileOrder()) materials.push_back(readMaterial(name, TableField(field)));
    return materials;
}

/// Resolves the material names used by objects to indices into Scene::materials.
class MaterialIndex {
public:
    explicit MaterialIndex(const std::vector<Material>& materials)
    {
        for (size_t i = 0; i < materials.size(); ++i) {
            m_index.emplace(materials[i].name, static_cast<uint32_t>(i));
            m_names.push_back(materials[i].name);
        }
    }

    uint32_t resolve(const Field& field) const
    {
        const std::string name = readString(field);
        const auto found = m_index.find(name);
        if (found == m_index.end()) field.fail(unknownMessage(name));
        return found->second;
    }

private:
    std::string unknownMessage(const std::string& name) const
    {
        std::vector<std::string_view> names(m_names.begin(), m_names.end());
        const std::string message = "unknown material " + quote(name);
        if (names.empty()) return message + " (no materials are defined; add a [materials." + name + "] table)";
        const std::string suggestion = didYouMean(name, names);
        // Listing a handful of names helps when nothing is close; a long list would bury the message.
        if (suggestion.empty() && names.size() <= 10) return message + " (defined: " + joinList(names) + ")";
        return message + suggestion;
    }

    std::map<std::string, uint32_t, std::less<>> m_index;
    std::vector<std::string> m_names;
};

// ------------------------------------------------------------------- objects

constexpr std::array<std::string_view, 4> sphereKeys{"shape", "material", "center", "radius"};
constexpr std::array<std::string_view, 4> boxKeys{"shape", "material", "min", "max"};
constexpr std::array<std::string_view, 3> triangleKeys{"shape", "material", "vertices"};
constexpr std::array<std::string_view, 4> planeKeys{"shape", "material", "point", "normal"};

void readSphere(const TableField& table, uint32_t material, Scene& scene)
{
    scene.spheres.push_back({readVector(table.require("center")), readPositive(table.require("radius")), material});
}

void checkBoxExtent(const Field& maxField, const glm::dvec3& min, const glm::dvec3& max)
{
    static constexpr char axes[] = "xyz";
    for (int axis = 0; axis < 3; ++axis) {
        if (min[axis] < max[axis]) continue;
        maxField.fail("must be greater than min in every component, but " + std::string(1, axes[axis]) +
                      ": min = " + formatNumber(min[axis]) + " >= max = " + formatNumber(max[axis]));
    }
}

void readBox(const TableField& table, uint32_t material, Scene& scene)
{
    const glm::dvec3 min = readVector(table.require("min"));
    const Field maxField = table.require("max");
    const glm::dvec3 max = readVector(maxField);
    checkBoxExtent(maxField, min, max);
    scene.boxes.push_back({min, max, material});
}

void readTriangle(const TableField& table, uint32_t material, Scene& scene)
{
    // Degenerate triangles are accepted on purpose: meshes exported by tools
    // contain them, and the renderer handles them.
    scene.triangles.push_back({readVertices(table.require("vertices")), material});
}

void readPlane(const TableField& table, uint32_t material, Scene& scene)
{
    const glm::dvec3 point = readVector(table.require("point"));
    const Field normalField = table.require("normal");
    const std::optional<glm::dvec3> normal = normalized(readVector(normalField));
    if (!normal) normalField.fail("must not be zero-length");
    scene.planes.push_back({point, *normal, material});
}

struct ShapeReader {
    std::string_view name;
    Keys keys;
    void (*read)(const TableField&, uint32_t, Scene&);
};

#define VKRT_SHAPE_KIND_ENTRY(KIND, Type, name, value, field, array, ARRAY, capacity) \
    ShapeReader{#name, field##Keys, read##Type},
const std::array<ShapeReader, kShapeKindCount> shapeKinds{{VKRT_SHAPE_KINDS(VKRT_SHAPE_KIND_ENTRY)}};
#undef VKRT_SHAPE_KIND_ENTRY
const std::vector<std::string_view> allShapeKeys = keysOfEveryKind(shapeKinds);

void readObject(const TableField& table, const MaterialIndex& materials, Scene& scene)
{
    const ShapeReader kind = readChoice(table.require("shape"), "shape", shapeKinds);
    table.rejectUnknownKeys(kind.keys, allShapeKeys, "shape " + quote(kind.name));
    kind.read(table, materials.resolve(table.require("material")), scene);
}

/// Calls `read` for every table of a [[name]] array.
template <class Read>
void forEachTable(const Field& field, Read read)
{
    const toml::array* array = field.node().as_array();
    if (!array) field.fail("expected an array of tables ([[" + field.path() + "]]), got " + describeType(field.node()));
    for (size_t i = 0; i < array->size(); ++i) read(TableField(field.element(i, *array->get(i))));
}

// -------------------------------------------------------------------- lights

constexpr std::array<std::string_view, 3> pointLightKeys{"type", "position", "intensity"};
constexpr std::array<std::string_view, 4> triangleLightKeys{"type", "vertices", "radiance", "two_sided"};

void readPointLight(const TableField& table, Scene& scene)
{
    scene.pointLights.push_back({readVector(table.require("position")), readRadiance(table.require("intensity"))});
}

void readTriangleLight(const TableField& table, Scene& scene)
{
    TriangleLight light;
    light.vertices = readVertices(table.require("vertices"));
    light.radiance = readRadiance(table.require("radiance"));
    light.twoSided = readOr(table, "two_sided", false, readBool);
    scene.triangleLights.push_back(light);
}

struct LightReader {
    std::string_view name;
    Keys keys;
    void (*read)(const TableField&, Scene&);
};

#define VKRT_LIGHT_KIND_ENTRY(KIND, Type, name, value, field, array, ARRAY, capacity) \
    LightReader{#name, field##Keys, read##Type},
const std::array<LightReader, kLightKindCount> lightKinds{{VKRT_LIGHT_KINDS(VKRT_LIGHT_KIND_ENTRY)}};
#undef VKRT_LIGHT_KIND_ENTRY
const std::vector<std::string_view> allLightKeys = keysOfEveryKind(lightKinds);

void readLight(const TableField& table, Scene& scene)
{
    const LightReader kind = readChoice(table.require("type"), "light type", lightKinds);
    table.rejectUnknownKeys(kind.keys, allLightKeys, "light type " + quote(kind.name));
    kind.read(table, scene);
}

// ---------------------------------------------------------------- background

constexpr std::array<std::string_view, 2> backgroundKeys{"color", "cubemap"};
/// Vulkan cube face order, matching Cubemap::facePaths.
constexpr std::array<std::string_view, 6> faceKeys{"px", "nx", "py", "ny", "pz", "nz"};

void checkImageExtension(const Field& field, const fs::path& path)
{
    const std::string extension = lowercase(path.extension().string());
    if (extension != ".exr" && extension != ".png")
        field.fail("cubemap faces must be .exr or .png files, got " + quote(path.string()));
}

void checkRegularFile(const Field& field, const fs::path& path)
{
    std::error_code error;
    const fs::file_status status = fs::status(path, error);
    if (!fs::exists(status)) field.fail("file " + quote(path.string()) + " does not exist");
    if (!fs::is_regular_file(status)) field.fail(quote(path.string()) + " is not a regular file");
}

std::string readFacePath(const Field& field)
{
    const fs::path given = readString(field);
    const fs::path path = given.is_absolute() ? given : field.context().baseDir / given;
    checkImageExtension(field, path);
    checkRegularFile(field, path);
    return path.string();
}

Cubemap readCubemap(const TableField& table)
{
    table.rejectUnknownKeys(faceKeys);
    Cubemap cubemap;
    cubemap.where = table.field().location();
    for (size_t i = 0; i < faceKeys.size(); ++i) cubemap.facePaths[i] = readFacePath(table.require(faceKeys[i]));
    return cubemap;
}

Background readBackground(const TableField& table)
{
    table.rejectUnknownKeys(backgroundKeys);
    Background background;
    background.color = readOr(table, "color", Color(0.0), readRadiance);
    const std::optional<Field> cubemap = table.find("cubemap");
    if (!cubemap) return background;
    if (const auto color = table.find("color"))
        cubemap->fail("cannot be combined with background.color (line " + std::to_string(color->location().line) +
                      "); use one or the other");
    background.cubemap = readCubemap(TableField(*cubemap));
    return background;
}

// --------------------------------------------------------------------- scene

constexpr std::array<std::string_view, 6> topLevelKeys{"render", "camera", "materials", "objects", "lights", "background"};

Scene readScene(const TableField& top)
{
    top.rejectUnknownKeys(topLevelKeys);
    Scene scene;
    if (const auto render = top.find("render")) scene.render = readRender(TableField(*render));
    scene.camera = readCamera(TableField(top.require("camera")));
    if (const auto materials = top.find("materials")) scene.materials = readMaterials(TableField(*materials));
    const MaterialIndex materialIndex(scene.materials);
    const auto object = [&](const TableField& table) { readObject(table, materialIndex, scene); };
    if (const auto objects = top.find("objects")) forEachTable(*objects, object);
    const auto light = [&](const TableField& table) { readLight(table, scene); };
    if (const auto lights = top.find("lights")) forEachTable(*lights, light);
    if (const auto background = top.find("background")) scene.background = readBackground(TableField(*background));
    return scene;
}

toml::table parseToml(std::string_view text, const Context& context)
{
    try {
        return toml::parse(text, std::string_view(context.file));
    } catch (const toml::parse_error& error) {
        throw SceneError(locate(context, error.source().begin), "invalid TOML: " + std::string(error.description()));
    }
}

struct FileCloser {
    void operator()(std::FILE* file) const { std::fclose(file); }
};

[[noreturn]] void failToRead(const std::string& path, int error)
{
    throw InputError("cannot read scene file '" + path + "': " + std::strerror(error));
}

/// Uses stdio rather than iostreams because only stdio reliably reports why (errno) a read failed.
std::string readFileBytes(const std::string& path)
{
    errno = 0;
    const std::unique_ptr<std::FILE, FileCloser> file(std::fopen(path.c_str(), "rb"));
    if (!file) failToRead(path, errno);
    std::string bytes;
    char buffer[1 << 16];
    size_t count = 0;
    while ((count = std::fread(buffer, 1, sizeof buffer, file.get())) > 0) bytes.append(buffer, count);
    if (std::ferror(file.get())) failToRead(path, errno);
    return bytes;
}

} // namespace

Scene parseSceneString(std::string_view text, const std::string& path)
{
    const Context context{path, fs::path(path).parent_path()};
    const toml::table root = parseToml(text, context);
    Scene scene = readScene(TableField(Field(context, root, "")));
    scene.path = path;
    scene.fileHash = fnv1a64(text);
    return scene;
}

Scene parseSceneFile(const std::string& path) { return parseSceneString(readFileBytes(path), path); }

} // namespace vkrt

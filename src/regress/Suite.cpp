// Regression-suite manifest reader. Manifests are written by hand like scene
// files, so they are read with the same located, typed checks
// (scene/TomlReader.h): every error names file:line:column and the dotted path.
#include "regress/Suite.h"

#include "scene/TomlReader.h"
#include "util/Error.h"

#include <array>
#include <cctype>
#include <cstdint>
#include <cstdio>
#include <map>
#include <string_view>
#include <utility>

namespace fs = std::filesystem;

namespace vkrt {

namespace {

constexpr std::array<std::string_view, 2> topLevelKeys{"suite", "case"};
constexpr std::array<std::string_view, 5> suiteKeys{"alpha", "pooled_alpha", "min_pass", "max_slowdown", "seed"};
constexpr std::array<std::string_view, 11> caseKeys{"name",  "scene", "reference", "reference_source", "reference_spp",
                                                    "spp",   "width", "height",    "baseline_seconds", "max_rejected",
                                                    "shards"};

constexpr std::array<EnumName<ReferenceSource>, 2> referenceSources{
    {{"mitsuba", ReferenceSource::Mitsuba}, {"vkrt", ReferenceSource::Vkrt}}};

/// A significance level: 0 and 1 would make the test meaningless.
double readAlpha(const Field& field) { return readNumberIn(field, {0, 1, true, true}); }
/// A fraction of passing values: 1 (all must pass) is allowed.
double readPassFraction(const Field& field) { return readNumberIn(field, {0, 1, true, false}); }

uint32_t readUint32(const Field& field, int64_t min)
{
    return static_cast<uint32_t>(readInteger(field, min, UINT32_MAX));
}
uint32_t readCount(const Field& field) { return readUint32(field, 1); }
uint32_t readSeed(const Field& field) { return readUint32(field, 0); }
uint64_t readTolerance(const Field& field) { return readUint32(field, 0); }
std::optional<uint32_t> readSide(const Field& field) { return readCount(field); }

fs::path readScenePath(const Field& field)
{
    const fs::path scene = readPath(field).lexically_normal();
    if (!fs::exists(scene)) field.fail("no such file " + scene.string());
    return scene;
}

fs::path readFolder(const Field& field) { return readPath(field).lexically_normal(); }

void readSuiteSettings(const TableField& table, RegressionSuite& suite)
{
    table.rejectUnknownKeys(suiteKeys);
    suite.alpha = readOr(table, "alpha", suite.alpha, readAlpha);
    suite.pooledAlpha = readOr(table, "pooled_alpha", suite.pooledAlpha, readAlpha);
    suite.minPass = readOr(table, "min_pass", suite.minPass, readPassFraction);
    suite.maxSlowdown = readOr(table, "max_slowdown", suite.maxSlowdown, readPositive);
    suite.seed = readOr(table, "seed", suite.seed, readSeed);
}

/// A case name: what a child process is started with (--run-case), --filter
/// matches, and every report (CSV, JUnit XML, the baseline files) writes
/// unquoted. So it is 1 to kMaxCaseNameBytes letters, digits and `._/+-`
/// (deqp's case names and paths need no more), never a character a report
/// would have to escape.
std::string readCaseName(const Field& field)
{
    const std::string name = readString(field);
    if (name.empty()) field.fail("a case name cannot be empty");
    if (name.size() > kMaxCaseNameBytes)
        field.fail("a case name is at most " + std::to_string(kMaxCaseNameBytes) + " bytes, this one " +
                   std::to_string(name.size()));
    for (const char c : name) {
        if (!isCaseNameCharacter(c)) {
            char code[8];
            std::snprintf(code, sizeof code, "0x%02X", unsigned(static_cast<unsigned char>(c)));
            field.fail("a case name holds only letters, digits and . _ / + -, not " +
                       (std::isprint(static_cast<unsigned char>(c)) ? quote(std::string(1, c)) : std::string(code)));
        }
    }
    return name;
}

RegressionCase readCase(const TableField& table)
{
    table.rejectUnknownKeys(caseKeys);
    RegressionCase c;
    c.name = readCaseName(table.require("name"));
    c.scene = readScenePath(table.require("scene"));
    c.referenceDir = readFolder(table.require("reference"));
    c.source = readChoice(table.require("reference_source"), "reference source", referenceSources).value;
    c.referenceSpp = readCount(table.require("reference_spp"));
    c.spp = readCount(table.require("spp"));
    c.width = readOr(table, "width", c.width, readSide);
    c.height = readOr(table, "height", c.height, readSide);
    c.baselineSeconds = readOr(table, "baseline_seconds", c.baselineSeconds, readPositive);
    c.maxRejected = readOr(table, "max_rejected", c.maxRejected, readTolerance);
    c.shards = readOr(table, "shards", c.shards, readCount);
    if (c.shards > c.spp)
        table.require("shards").fail(std::to_string(c.shards) + " shards of " + std::to_string(c.spp) +
                                     " spp would leave some without samples; use at most spp shards");
    return c;
}

/// Case names are what --filter and the report use, so two cases may not share one.
class CaseNames {
public:
    void add(const TableField& table, const std::string& name)
    {
        const Field field = table.require("name");
        const auto [first, inserted] = m_seen.emplace(name, field.location().line);
        if (!inserted)
            field.fail("duplicate case name " + quote(name) + " (first used on line " + std::to_string(first->second) +
                       ")");
    }

private:
    std::map<std::string, int> m_seen;
};

std::vector<RegressionCase> readCases(const TableField& top)
{
    const std::optional<Field> cases = top.find("case");
    if (!cases) top.field().fail("no [[case]] entries");
    if (cases->node().is_array() && cases->node().as_array()->empty()) cases->fail("no [[case]] entries");
    std::vector<RegressionCase> out;
    CaseNames names;
    forEachTable(*cases, [&](const TableField& table) {
        out.push_back(readCase(table));
        names.add(table, out.back().name);
    });
    return out;
}

} // namespace

bool isCaseNameCharacter(char c)
{
    const auto u = static_cast<unsigned char>(c);
    return std::isalnum(u) || c == '.' || c == '_' || c == '/' || c == '+' || c == '-';
}

RegressionSuite readRegressionSuite(const fs::path& path)
{
    if (!fs::exists(path)) throw InputError("--suite " + path.string() + ": no such file");
    const TomlSource source{path.string(), path.parent_path()};
    const toml::table root = parseToml(readFileBytes(source.file, "suite file"), source);
    const TableField top(Field(source, root, ""));
    top.rejectUnknownKeys(topLevelKeys);
    RegressionSuite suite;
    suite.path = path;
    if (const auto settings = top.find("suite")) readSuiteSettings(TableField(*settings), suite);
    suite.cases = readCases(top);
    return suite;
}

} // namespace vkrt

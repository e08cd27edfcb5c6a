#include "regress/Suite.h"

#include "util/Error.h"

#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <set>
#include <vector>

namespace fs = std::filesystem;

namespace vkrt {

namespace {

SourceLocation locate(const fs::path& file, const toml::node& node)
{
    return {file.string(), int(node.source().begin.line), int(node.source().begin.column)};
}

/// Levenshtein distance, for "did you mean".
size_t editDistance(const std::string& a, const std::string& b)
{
    std::vector<size_t> row(b.size() + 1);
    for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (size_t i = 1; i <= a.size(); ++i) {
        size_t diagonal = row[0];
        row[0] = i;
        for (size_t j = 1; j <= b.size(); ++j) {
            size_t above = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
            diagonal = above;
        }
    }
    return row[b.size()];
}

std::string didYouMean(const std::string& key, const std::set<std::string>& allowed)
{
    std::string best;
    size_t bestDistance = 3; // offer only keys within two edits
    for (const std::string& candidate : allowed) {
        size_t d = editDistance(key, candidate);
        if (d < bestDistance && d < std::max(key.size(), candidate.size())) best = candidate, bestDistance = d;
    }
    return best.empty() ? "" : "; did you mean '" + best + "'?";
}

void rejectUnknownKeys(const fs::path& file, const toml::table& table, const std::set<std::string>& allowed,
                       const std::string& where)
{
    for (const auto& [key, value] : table) {
        std::string name(key.str());
        if (!allowed.count(name))
            throw SceneError(locate(file, value), where + ": unknown key '" + name + "'" + didYouMean(name, allowed));
    }
}

template <typename T> T require(const fs::path& file, const toml::table& table, const char* key, const std::string& where)
{
    const toml::node* node = table.get(key);
    if (!node) throw SceneError(locate(file, table), where + ": missing required key '" + key + "'");
    if constexpr (std::is_same_v<T, std::string>) {
        if (auto v = node->value<std::string>()) return *v;
        throw SceneError(locate(file, *node), where + "." + key + ": expected a string");
    } else {
        if (auto v = node->value<T>()) return *v;
        throw SceneError(locate(file, *node), where + "." + key + ": expected a number");
    }
}

template <typename T>
std::optional<T> optional(const fs::path& file, const toml::table& table, const char* key, const std::string& where)
{
    if (!table.get(key)) return std::nullopt;
    return require<T>(file, table, key, where);
}

double positive(const fs::path& file, const toml::table& table, const char* key, const std::string& where, double value)
{
    if (!(value > 0.0) || !std::isfinite(value))
        throw SceneError(locate(file, *table.get(key)), where + "." + key + ": must be a positive number");
    return value;
}

/// A probability: in (0, 1), or (0, 1] when `closed`.
double probability(const fs::path& file, const toml::table& table, const char* key, const std::string& where,
                   double value, bool closed)
{
    if (!(value > 0.0) || value > 1.0 || (!closed && value == 1.0))
        throw SceneError(locate(file, *table.get(key)),
                         where + "." + key + ": must be in (0, 1" + (closed ? "]" : ")") + ", got " + std::to_string(value));
    return value;
}

/// An integer in [minimum, 2^32 - 1].
uint32_t count32(const fs::path& file, const toml::table& table, const char* key, const std::string& where, int64_t value,
                 int64_t minimum = 1)
{
    if (value < minimum || value > int64_t(UINT32_MAX))
        throw SceneError(locate(file, *table.get(key)),
                         where + "." + key + ": must be an integer in [" + std::to_string(minimum) + ", 4294967295]");
    return uint32_t(value);
}

RegressionCase readCase(const fs::path& file, const toml::table& t, size_t index)
{
    std::string where = "case[" + std::to_string(index) + "]";
    rejectUnknownKeys(file, t,
                      {"name", "scene", "reference", "reference_source", "reference_spp", "spp", "width", "height",
                       "baseline_seconds", "max_rejected"},
                      where);
    RegressionCase c;
    fs::path dir = file.parent_path();
    c.name = require<std::string>(file, t, "name", where);
    c.scene = (dir / require<std::string>(file, t, "scene", where)).lexically_normal();
    c.referenceDir = (dir / require<std::string>(file, t, "reference", where)).lexically_normal();
    std::string source = require<std::string>(file, t, "reference_source", where);
    if (source != "mitsuba" && source != "vkrt")
        throw SceneError(locate(file, *t.get("reference_source")),
                         where + ".reference_source: expected \"mitsuba\" or \"vkrt\", got \"" + source + "\"");
    c.source = source == "mitsuba" ? ReferenceSource::Mitsuba : ReferenceSource::Vkrt;
    c.referenceSpp = count32(file, t, "reference_spp", where, require<int64_t>(file, t, "reference_spp", where));
    c.spp = count32(file, t, "spp", where, require<int64_t>(file, t, "spp", where));
    if (auto w = optional<int64_t>(file, t, "width", where)) c.width = count32(file, t, "width", where, *w);
    if (auto h = optional<int64_t>(file, t, "height", where)) c.height = count32(file, t, "height", where, *h);
    if (auto b = optional<double>(file, t, "baseline_seconds", where)) c.baselineSeconds = positive(file, t, "baseline_seconds", where, *b);
    if (auto m = optional<int64_t>(file, t, "max_rejected", where)) c.maxRejected = count32(file, t, "max_rejected", where, *m, 0);
    if (!fs::exists(c.scene))
        throw SceneError(locate(file, *t.get("scene")), where + ".scene: no such file " + c.scene.string());
    return c;
}

} // namespace

RegressionSuite readRegressionSuite(const fs::path& path)
{
    if (!fs::exists(path)) throw InputError("--suite " + path.string() + ": no such file");
    toml::table root;
    try {
        root = toml::parse_file(path.string());
    } catch (const toml::parse_error& e) {
        throw SceneError({path.string(), int(e.source().begin.line), int(e.source().begin.column)},
                         std::string("invalid TOML: ") + std::string(e.description()));
    }
    rejectUnknownKeys(path, root, {"suite", "case"}, "suite file");
    RegressionSuite suite;
    suite.path = path;
    if (const toml::table* s = root["suite"].as_table()) {
        rejectUnknownKeys(path, *s, {"alpha", "pooled_alpha", "min_pass", "max_slowdown", "seed"}, "suite");
        if (auto v = optional<double>(path, *s, "alpha", "suite")) suite.alpha = probability(path, *s, "alpha", "suite", *v, false);
        if (auto v = optional<double>(path, *s, "pooled_alpha", "suite"))
            suite.pooledAlpha = probability(path, *s, "pooled_alpha", "suite", *v, false);
        if (auto v = optional<double>(path, *s, "min_pass", "suite")) suite.minPass = probability(path, *s, "min_pass", "suite", *v, true);
        if (auto v = optional<double>(path, *s, "max_slowdown", "suite"))
            suite.maxSlowdown = positive(path, *s, "max_slowdown", "suite", *v);
        if (auto v = optional<int64_t>(path, *s, "seed", "suite")) suite.seed = count32(path, *s, "seed", "suite", *v, 0);
    }
    const toml::array* cases = root["case"].as_array();
    if (!cases || cases->empty()) throw SceneError({path.string(), 1, 1}, "suite file: no [[case]] entries");
    std::set<std::string> names;
    for (size_t i = 0; i < cases->size(); ++i) {
        const toml::table* t = (*cases)[i].as_table();
        if (!t) throw SceneError(locate(path, (*cases)[i]), "case[" + std::to_string(i) + "]: expected a table");
        RegressionCase c = readCase(path, *t, i);
        if (!names.insert(c.name).second)
            throw SceneError(locate(path, *t->get("name")), "case[" + std::to_string(i) + "].name: duplicate '" + c.name + "'");
        suite.cases.push_back(std::move(c));
    }
    return suite;
}

} // namespace vkrt
